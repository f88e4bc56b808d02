"""The overlap check of every written step of a 3D run (ngfracture.output.overlap3d)."""
import json
from pathlib import Path

from ngfracture.output.overlap3d import vtu_overlap_volume

#: overlap accepted between fragments, relative to the body's volume (as run/invariants.py's OVERLAP_TOL)
TOL = 1e-10


def check_run_overlap(folder, tol=TOL):
    """Measure the overlap of every step_NNNNNN.vtu of a finished run folder, assert each at
    most ``tol`` of the body's volume, and return {file name: Overlap3d}."""
    folder = Path(folder)
    n = json.loads((folder / "summary.json").read_text())["n_steps"]
    names = sorted(p.name for p in folder.glob("step_*.vtu"))
    assert names == [f"step_{k:06d}.vtu" for k in range(n + 1)], names
    out = {}
    for name in names:
        ov = vtu_overlap_volume(folder / name)
        assert ov.volume <= tol * ov.body_volume, (name, ov.volume, ov.body_volume, ov.pairs[:5])
        out[name] = ov
    return out


def check_step_overlap(folder, step, tol=TOL):
    """Assert the overlap of the written ``step_NNNNNN.vtu`` of ``step`` at most ``tol`` of the
    body's volume (a run's ``on_step``: a long run stops at its first violation)."""
    name = f"step_{step:06d}.vtu"
    ov = vtu_overlap_volume(Path(folder) / name)
    assert ov.volume <= tol * ov.body_volume, (name, ov.volume / ov.body_volume, ov.pairs[:5])
    return ov
