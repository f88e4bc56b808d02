"""The files of a run in its output folder: which are ours, and writing them.

A run's folder holds the VTK time series, checkpoints, ``summary.json`` and pictures.
Existing results are refused unless the run replaces them (``force``: only the files
named by :data:`OWN_PATTERNS` are removed) or continues them (``resume``: the steps after
the newest checkpoint are removed, the time series goes on). Bad input is refused before
the folder is touched (:func:`check_folder`).
"""
import time
from pathlib import Path

from . import checkpoint
from ..output.atomic import TEMPORARY_PREFIX, write_json
from ..output.curves import plot_force_displacement, write_force_displacement_csv
from ..output.timeseries import TimeSeriesWriter
from .state import json_round_trip, load_state, save_state

__all__ = ["OWN_PATTERNS", "check_folder", "read_resumable", "RunFiles"]

#: the files a run writes (what ``force`` removes); temporary files of a killed write too
OWN_PATTERNS = ("step_*.vtu", "cracks_*.vtp", "results.pvd", "cracks.pvd", "checkpoint_*.npz",
                "summary.json", "final.png", "step_*.png", "fragment_sizes.png", "force_displacement.csv",
                "force_displacement.png", TEMPORARY_PREFIX + "*")


def check_folder(out, force=False, resume=False, option_names=("force", "resume")):
    """Refuse an output folder before any work; returns the files of ours in it.

    Parameters
    ----------
    out : path
        The output folder (need not exist).
    force, resume : bool
        Replace earlier results, or continue from the newest checkpoint.
    option_names : (str, str)
        How the refusal names the two options (the CLI passes "--force", "--resume").

    Returns
    -------
    list of pathlib.Path
        The files in ``out`` that ngfracture writes (what ``force`` removes).

    Raises
    ------
    FileExistsError
        ``out`` is not a folder, or holds results and neither force nor resume is given.
    checkpoint.CheckpointError
        ``resume`` and ``out`` has no checkpoint.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"output folder {out} exists and is not a folder")
    own = sorted({p for pat in OWN_PATTERNS for p in out.glob(pat)}) if out.exists() else []
    if resume and not checkpoint.list_checkpoints(out):
        raise checkpoint.CheckpointError(f"{out}: no checkpoint to resume from")
    if own and not (force or resume):
        raise FileExistsError(f"output folder {out} already holds results ({own[0].name}, ...); "
                              f"use {option_names[0]} to replace them or {option_names[1]} to continue")
    return own


def read_resumable(out, identity):
    """The newest checkpoint's state, if it belongs to this run.

    Parameters
    ----------
    out : path
        The output folder.
    identity : dict
        ``scene``, ``parameters`` and ``control`` (the options that decide the load path)
        of the run that resumes.

    Returns
    -------
    state : State
    run : dict
        The checkpoint's run metadata (area_initial, timings, ...).

    Raises
    ------
    checkpoint.CheckpointError
        A damaged or foreign checkpoint, or one of another scene, parameters or options.
    """
    state, run = load_state(out)
    if run.get("scene") != identity["scene"] or run.get("parameters") != json_round_trip(identity["parameters"]):
        raise checkpoint.CheckpointError(
            f"{out}: the checkpoint is of scene {run.get('scene')!r} with parameters "
            f"{run.get('parameters')!r}, not {identity['scene']!r} with {identity['parameters']!r}")
    saved, now = run.get("control"), json_round_trip(identity["control"])
    if saved is not None and saved != now:
        name = next(k for k in sorted(set(saved) | set(now)) if saved.get(k) != now.get(k))
        raise checkpoint.CheckpointError(
            f"{out}: the checkpoint was written with {name} = {saved.get(name)!r}, this run has "
            f"{now.get(name)!r}; resume with the options of the interrupted run (only max_steps may differ)")
    return state, run


class RunFiles:
    """The files of one run: time series, checkpoints, pictures, summary.

    Made by :meth:`create` or :meth:`resume` when the run starts.

    Parameters
    ----------
    folder : pathlib.Path
    writer : TimeSeriesWriter
    pictures : {"final", "every", "none"}
    """

    def __init__(self, folder, writer, pictures):
        self.folder, self.writer, self.pictures = Path(folder), writer, pictures

    @classmethod
    def create(cls, out, pictures):
        """Start a run's files in ``out``: earlier files of ours are removed.

        Parameters
        ----------
        out : path
        pictures : {"final", "every", "none"}

        Returns
        -------
        RunFiles
        """
        out = Path(out)
        own = check_folder(out, force=True)
        out.mkdir(parents=True, exist_ok=True)
        for p in own:
            p.unlink()
        return cls(out, TimeSeriesWriter(out), pictures)

    @classmethod
    def resume(cls, out, last_step, pictures):
        """Continue a run's files after step ``last_step`` (later steps' files are removed).

        Parameters
        ----------
        out : path
        last_step : int
            The step of the checkpoint resumed from.
        pictures : {"final", "every", "none"}

        Returns
        -------
        RunFiles
        """
        out = Path(out)
        writer = TimeSeriesWriter(out, resume=True, last_step=last_step)   # also removes killed writes
        for p in out.glob("step_*.png"):   # pictures of steps after the checkpoint
            if int(p.stem.split("_")[1]) > last_step:
                p.unlink()
        for p in out.glob(TEMPORARY_PREFIX + "*"):   # a checkpoint write that was killed
            p.unlink()
        return cls(out, writer, pictures)

    def write_step(self, state, prob, stats, timings):
        """The time series entry of an accepted state (and its picture with ``pictures="every"``).

        Parameters
        ----------
        state : State
        prob : ElasticProblem
            The problem on the state.
        stats : FragmentStatistics
        timings : Timings
        """
        with timings.timed("output"):
            self.writer.write(state.step, state.x, prob.mesh, prob.u, stats.fragment)
            if self.pictures == "every":
                from ..output.pictures import picture_scale, render_png
                render_png(prob.mesh, prob.u, stats.fragment, self.folder / f"step_{state.step:06d}.png",
                           scale=picture_scale(state.arrays.points, state.u))

    def write_checkpoint(self, state, run, timings):
        """A checkpoint of an accepted state.

        Parameters
        ----------
        state : State
        run : dict
            The run's metadata (see :func:`ngfracture.run.state.save_state`).
        timings : Timings
        """
        with timings.timed("output"):
            save_state(self.folder, state, run)

    def write_final(self, state, prob, stats, summary, timings):
        """The final pictures and ``summary.json`` (whose timings and pictures it completes).

        Parameters
        ----------
        state : State
        prob : ElasticProblem
        stats : FragmentStatistics
        summary : dict
            Changed in place: ``pictures`` and the output and wall times.
        timings : Timings
        """
        from ..output.pictures import final_pictures, picture_scale
        t0 = time.perf_counter()
        pictures = {}
        if self.pictures != "none":     # ours: a resumed run redraws them
            pictures = final_pictures(self.folder, prob.mesh, prob.u, stats,
                                      picture_scale(state.arrays.points, state.u))
        if state.history:
            write_force_displacement_csv(self.folder / "force_displacement.csv", state.history)
            if self.pictures != "none" and plot_force_displacement(
                    self.folder / "force_displacement.png", state.history, summary.get("load_description", "")):
                pictures["force_displacement"] = "force_displacement.png"
        seconds = time.perf_counter() - t0
        timings.add("output", seconds)
        summary["timings"]["output"] = round(timings["output"], 6)
        summary["timings"]["wall"] = round(summary["timings"]["wall"] + seconds, 6)   # the pictures too
        summary["pictures"] = pictures
        write_json(self.folder / "summary.json", summary, force=True)
