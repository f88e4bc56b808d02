"""Ensembles of runs: one scene, many seeds, run on dask.distributed.

Each sample is an ordinary :class:`~ngfracture.run.simulation.Simulation` run in
``DIR/sample_NNNN/`` with its checkpoints and summary.json. The samples are independent
tasks of a ``dask.distributed`` client: by default a ``LocalCluster`` of single-threaded
worker processes, or any cluster the caller connects to (``dask-jobqueue``, SSH,
Kubernetes), so the same code runs on a laptop and on a cluster.

A sample task is idempotent: a finished sample (valid summary.json of the same scene
parameters) is read, not rerun; an interrupted one (a checkpoint) resumes from its
checkpoint, which continues bit for bit as the uninterrupted run; anything else starts
cleanly. So when a worker dies, dask's rescheduling of its task elsewhere gives the
result of an uninterrupted run, and a rerun of the whole ensemble skips what is done.
Every sample runs with one NGSolve thread and one BLAS thread, so its result does not
depend on the worker that ran it.

``DIR/ensemble.json`` holds per sample its seed, reason, steps, split vertices,
fragments, crack length, peak load and wall time, and the statistics of
:mod:`ngfracture.studies.statistics`. The peak load is the largest ``2 W / x`` over the accepted
steps (W the elastic energy, x the load parameter): by Clapeyron's theorem the
generalised force conjugate to x of a linear elastic body under one prescribed
displacement parameter (contact without gap keeps the problem homogeneous of degree one
in x); St Venant-Kirchhoff at strains ~1e-4 departs from it by that order.
"""
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Ensemble", "SceneFactory", "run_sample", "sample_record", "sample_directory"]

FORMAT = "ngfracture-ensemble"


def sample_directory(out, index):
    """The folder of sample ``index``: ``out/sample_NNNN``.

    Parameters
    ----------
    out : path
    index : int

    Returns
    -------
    pathlib.Path
    """
    return Path(out) / f"sample_{int(index):04d}"


def peak_load(history):
    """Largest 2 W / x over the accepted steps (see the module docstring), and its x.

    Parameters
    ----------
    history : list of dict
        summary.json's history (x, elastic_energy per step).

    Returns
    -------
    (float, float)
        Peak load and the load parameter where it occurs; (0, 0) without steps.
    """
    best, at = 0.0, 0.0
    for h in history:
        if h["x"] > 0 and 2 * h["elastic_energy"] / h["x"] > best:
            best, at = 2 * h["elastic_energy"] / h["x"], h["x"]
    return best, at


def comparable_report(report):
    """An ensemble report without what may differ between equal ensembles.

    The run times of the samples and the execution block (workers, scheduler, which samples
    were run, resumed or skipped) depend on where and when the samples ran; everything else
    depends only on the scene, the seeds and the options.

    Parameters
    ----------
    report : dict
        The content of ensemble.json.

    Returns
    -------
    dict
        A copy (as from a JSON round trip) without ``execution`` and the samples' ``timings``.
    """
    report = json.loads(json.dumps(report))
    report.pop("execution")
    for s in report["samples"]:
        s.pop("timings")
    return report


def sample_record(summary, index, seed):
    """The ensemble's line for one sample, from its summary.json.

    Parameters
    ----------
    summary : dict
    index, seed : int

    Returns
    -------
    dict
    """
    load, at = peak_load(summary["history"])
    return {"index": index, "seed": seed, "reason": summary["reason"],
            "ok": summary["reason"] in ("load_max", "max_steps", "broken"),
            "steps": summary["n_steps"], "split_vertices": summary["n_split_vertices"],
            "fragments": summary["n_fragments"],
            **{k: summary[k] for k in ("crack_length", "crack_area") if k in summary},
            "peak_load": load, "load_at_peak": at,
            "peak_energy": max((h["elastic_energy"] for h in summary["history"]), default=0.0),
            **{k: summary[k] for k in ("fragment_areas", "fragment_volumes") if k in summary},
            "timings": {"run": summary["timings"]["wall"]}}


def _finished_summary(directory, parameters):
    """summary.json of a finished sample of these parameters, else None."""
    path = Path(directory) / "summary.json"
    try:
        summary = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if summary.get("parameters") != parameters or "history" not in summary:
        return None
    return summary


def run_sample(scene_factory, seed, index, out, options):
    """One sample, in a worker: finished -> read; checkpoint -> resume; else a fresh run.

    Parameters
    ----------
    scene_factory : callable(seed=int) -> Scene
    seed, index : int
    out : path
        The ensemble's folder.
    options : dict
        control (StepControl settings), contact, pictures, checkpoint_every.

    Returns
    -------
    dict
        :func:`sample_record` plus ``timings.task`` and ``timings.task_cpu`` (wall and CPU
        seconds of the whole task) and ``status`` (run, resumed or skipped).
    """
    t0, cpu0 = time.perf_counter(), time.process_time()
    import ngsolve
    ngsolve.SetNumThreads(1)        # one thread per worker process: results do not depend on it
    from ..run import checkpoint
    from ..run.simulation import Simulation, StepControl
    from ..run.state import json_round_trip
    scene = scene_factory(seed=seed)
    directory = sample_directory(out, index)
    summary = _finished_summary(directory, json_round_trip(scene.parameters))
    status = "skipped"
    if summary is None:
        resume = directory.exists() and bool(checkpoint.list_checkpoints(directory))
        control = StepControl(**{**scene.control, **options.get("control", {})})
        sim = Simulation(scene, control=control, out=directory, resume=resume, force=not resume,
                         pictures=options.get("pictures", "none"),
                         checkpoint_every=options.get("checkpoint_every", 1),
                         contact=options.get("contact", "auto"))
        summary = sim.run().summary
        status = "resumed" if resume else "run"
    record = sample_record(summary, index, seed)
    record["timings"]["task"] = time.perf_counter() - t0
    record["timings"]["task_cpu"] = time.process_time() - cpu0    # below "task": the core was shared
    record["status"] = status
    return record


class SceneFactory:
    """A scene by its source and parameters, loaded where it is called (in the worker).

    Parameters
    ----------
    spec : str
        As for :func:`ngfracture.run.scene_source.load_scene_function`: a built-in name, a
        file path (made absolute here: the workers must see the same file) or
        ``package.module:function``.
    parameters : dict
        Keyword arguments of the scene function, without the seed.
    """

    def __init__(self, spec, parameters):
        if spec.endswith(".py") or os.sep in spec:
            spec = os.path.abspath(spec)
        self.spec, self.parameters = spec, dict(parameters)

    def __call__(self, seed):
        """The scene of one seed.

        Parameters
        ----------
        seed : int

        Returns
        -------
        Scene
        """
        from ..run.scene_source import load_scene_function
        return load_scene_function(self.spec)(**self.parameters, seed=seed)

    def __repr__(self):
        return f"SceneFactory({self.spec!r}, {self.parameters!r})"


def _check_seeds(seeds):
    seeds = list(seeds)
    if not seeds:
        raise ValueError("Ensemble: no seeds (need at least one sample)")
    for s in seeds:
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 0:
            raise ValueError(f"Ensemble: seeds must be integers >= 0, got {s!r}")
    if len(set(seeds)) != len(seeds):
        raise ValueError("Ensemble: the seeds repeat; every sample needs its own")
    return [int(s) for s in seeds]


def _base_parameters(parameters):
    """The scene parameters without the per-sample ones (seed and the field's numbers)."""
    return {k: v for k, v in parameters.items() if k != "seed" and not k.startswith("strength_")}


@dataclass
class Ensemble:
    """Many seeds of one scene, each an ordinary run, on a dask.distributed client.

    Parameters
    ----------
    scene_factory : callable(seed=int) -> Scene
        Builds the scene of a seed, in the worker (pickled with cloudpickle: a module
        function, a ``functools.partial`` of one, or a closure).
    seeds : list of int
        One sample per seed (distinct, >= 0); sample i runs in ``out/sample_{i:04d}``.
    out : path
        The ensemble's folder.
    control : dict
        StepControl settings for every sample (on top of the scene's).
    contact : {"auto", "never"}
    pictures : {"none", "final", "every"}
        Pictures of every sample (default none: the ensemble draws its own).
    checkpoint_every : int
    workers : int
        Worker processes of the LocalCluster that :meth:`run` starts without a client.
    progress : bool or callable(done, total)
        A text progress bar over samples on stderr (True), none (False), or a callback.
    bootstrap_seed : int
        Seed of the bootstrap of the statistics.
    replicates : int
        Bootstrap replicates.

    Raises
    ------
    ValueError
        Bad seeds, workers, options; a factory that takes no seed or ignores it (checked
        by building the first sample's scene here, before any file is touched).
    FileExistsError
        ``out`` holds an ensemble of another scene, seeds or options.
    """
    scene_factory: object
    seeds: list
    out: object
    control: dict = field(default_factory=dict)
    contact: str = "auto"
    pictures: str = "none"
    checkpoint_every: int = 1
    workers: int = 2
    progress: object = True
    bootstrap_seed: int = 0
    replicates: int = 1000

    def __post_init__(self):
        self.seeds = _check_seeds(self.seeds)
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1:
            raise ValueError(f"Ensemble: workers must be an integer >= 1, got {self.workers!r}")
        if self.pictures not in ("none", "final", "every"):
            raise ValueError(f"Ensemble: pictures must be 'none', 'final' or 'every', got {self.pictures!r}")
        if self.contact not in ("auto", "never"):
            raise ValueError(f"Ensemble: contact must be 'auto' or 'never', got {self.contact!r}")
        if not callable(self.scene_factory):
            raise ValueError("Ensemble: scene_factory must be callable(seed=...) -> Scene")
        self.out = Path(self.out)
        if self.out.exists() and not self.out.is_dir():
            raise FileExistsError(f"Ensemble: {self.out} exists and is not a folder")
        self.request = self._request()
        saved = self._saved_request()
        if saved is not None and saved != self.request:
            key = next(k for k in sorted(set(saved) | set(self.request)) if saved.get(k) != self.request.get(k))
            raise FileExistsError(f"Ensemble: {self.out} holds an ensemble with another {key} "
                                  f"({saved.get(key)!r}, this one {self.request.get(key)!r}); use another folder")

    def _request(self):
        """What defines the ensemble: scene, its base parameters, seeds, options (checked once here)."""
        from ..run.simulation import Scene, StepControl
        from ..run.state import json_round_trip
        try:
            scene = self.scene_factory(seed=self.seeds[0])
        except TypeError as err:
            if "seed" in str(err):
                raise ValueError(f"Ensemble: the scene factory takes no seed parameter ({err}); "
                                 f"an ensemble needs a scene with a random strength") from None
            raise
        if not isinstance(scene, Scene):
            raise ValueError(f"Ensemble: the scene factory returned a {type(scene).__name__}, not a Scene")
        scene.validate()
        StepControl(**{**scene.control, **self.control}).validate(scene.dx)
        if scene.parameters.get("seed") != self.seeds[0]:
            raise ValueError(f"Ensemble: scene {scene.name!r} does not record seed {self.seeds[0]} in its "
                             f"parameters (it has seed = {scene.parameters.get('seed')!r}): its samples would "
                             f"not differ")
        options = {"control": self.control, "contact": self.contact, "pictures": self.pictures,
                   "checkpoint_every": self.checkpoint_every}
        return json_round_trip({"format": FORMAT, "scene": scene.name, "parameters": _base_parameters(scene.parameters),
                         "seeds": self.seeds, "options": options})

    def _saved_request(self):
        path = self.out / "ensemble_request.json"
        if not path.exists():
            return None
        try:
            return json.loads(path.read_text())
        except ValueError:
            raise FileExistsError(f"Ensemble: {path} is not readable JSON; use another folder") from None

    def run(self, client=None):
        """Run (or finish) every sample and write ensemble.json and the pictures.

        Parameters
        ----------
        client : distributed.Client, optional
            Where the samples run; None: a LocalCluster of ``workers`` single-threaded
            worker processes, closed at the end.

        Returns
        -------
        dict
            The content of ensemble.json.
        """
        from distributed import Client, LocalCluster, as_completed
        from ..output.atomic import write_json
        t0 = time.perf_counter()
        cluster = None
        if client is None:
            import logging
            cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster)
        try:
            t_started = time.perf_counter()
            self.out.mkdir(parents=True, exist_ok=True)
            write_json(self.out / "ensemble_request.json", self.request, force=True)
            options = self.request["options"]
            futures = [client.submit(run_sample, self.scene_factory, seed, i, str(self.out), options,
                                     key=f"ngfracture-sample-{self.out.resolve()}-{i}-{seed}", pure=False)
                       for i, seed in enumerate(self.seeds)]
            records = {}
            self._show(0, len(futures))
            for future in as_completed(futures):
                i = futures.index(future)
                try:
                    records[i] = future.result()
                except Exception as err:          # a sample that raised, or a worker killed too often
                    records[i] = {"index": i, "seed": self.seeds[i], "reason": "error", "ok": False,
                                  "message": f"{type(err).__name__}: {err}", "timings": {}, "status": "error"}
                self._show(len(records), len(futures))
            t_samples = time.perf_counter()
            workers = len(client.scheduler_info().get("workers", {}))
            scheduler = client.scheduler.address
        finally:
            if cluster is not None:
                client.close()
                cluster.close()
        samples = [records[i] for i in range(len(self.seeds))]
        report = self._report(samples)
        report["execution"] = {"workers": workers, "scheduler": None if cluster is not None else scheduler,
                               "status": {status: [s["index"] for s in samples if s["status"] == status]
                                          for status in ("run", "resumed", "skipped", "error")},
                               "cluster_start_seconds": t_started - t0,
                               "samples_seconds": t_samples - t_started,
                               "wall_seconds": time.perf_counter() - t0}
        for s in samples:
            s.pop("status")
        from .statistics import plot_ensemble
        report["pictures"] = plot_ensemble(report, self.out)
        report["execution"]["report_seconds"] = time.perf_counter() - t_samples
        report["execution"]["wall_seconds"] = time.perf_counter() - t0
        write_json(self.out / "ensemble.json", report, force=True)
        return report

    def _show(self, done, total):
        if callable(self.progress):
            self.progress(done, total)
        elif self.progress:
            width = 30
            bar = "#" * (width * done // total) + "-" * (width - width * done // total)
            sys.stderr.write(f"\r[{bar}] {done}/{total} samples")
            if done == total:
                sys.stderr.write("\n")
            sys.stderr.flush()

    def _report(self, samples):
        from .statistics import fit_fragment_sizes, fragment_size_statistics, summary_with_interval
        done = [s for s in samples if s["ok"]]
        areas = [s["fragment_volumes"] if "fragment_volumes" in s else s["fragment_areas"] for s in done]   # 3D: volumes
        pooled = np.concatenate([np.asarray(a, dtype=float) for a in areas]) if areas else np.zeros(0)
        return {"format": FORMAT, "scene": self.request["scene"], "parameters": self.request["parameters"],
                "seeds": self.seeds, "options": self.request["options"],
                "finished": len(done), "not_finished": [s["index"] for s in samples if not s["ok"]],
                "samples": samples,
                "fragment_sizes": fragment_size_statistics(areas, seed=self.bootstrap_seed,
                                                           replicates=self.replicates),
                "fit": fit_fragment_sizes(pooled),
                "fragment_counts": summary_with_interval([s["fragments"] for s in done], seed=self.bootstrap_seed,
                                                         replicates=self.replicates),
                "peak_load": summary_with_interval([s["peak_load"] for s in done], seed=self.bootstrap_seed,
                                                   replicates=self.replicates)}
