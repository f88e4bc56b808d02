"""The tutorials run, and each notebook is its percent script.

Every notebook in tutorials/ is executed headless with nbclient in a Jupyter
kernel of this interpreter (kernel "python3": jupyter_client resolves it to the
running Python when ipykernel is installed here); a cell that raises, including
the notebooks' own asserts, fails the test.  Runnable as a script:
``python tests/test_tutorials.py``.
"""
import importlib.util
import os
import sys
import time
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parent.parent
TUTORIALS = ROOT / "tutorials"
NOTEBOOKS = sorted(TUTORIALS.glob("[0-9][0-9]_*.ipynb"))
TIMEOUT = 900  # seconds per cell; the run of tutorial 8 (a 3D fragmentation, 27 steps) takes about 3 minutes of CPU


def _sync_module():
    spec = importlib.util.spec_from_file_location("tutorials_sync", TUTORIALS / "sync.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _absolute_pythonpath(monkeypatch):
    """The kernel runs in tutorials/: make a relative PYTHONPATH (``PYTHONPATH=.``) absolute."""
    entries = [e for e in os.environ.get("PYTHONPATH", "").split(os.pathsep) if e]
    if entries:
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(os.path.abspath(e) for e in entries))


def execute(nb, cwd):
    """Execute a notebook in place in a fresh kernel; return the wall time in seconds."""
    client = NotebookClient(nb, timeout=TIMEOUT, kernel_name="python3",
                            resources={"metadata": {"path": str(cwd)}})
    t0 = time.perf_counter()
    client.execute()
    return time.perf_counter() - t0


def test_there_are_tutorials():
    assert len(NOTEBOOKS) >= 2
    assert [nb.stem for nb in NOTEBOOKS] == [s.stem for s in _sync_module().scripts()]


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[nb.stem for nb in NOTEBOOKS])
def test_notebook_matches_script_and_has_no_outputs(notebook):
    stored = nbformat.read(notebook, as_version=4)
    expected = _sync_module().notebook_from_script(notebook.with_suffix(".py"))
    assert [(c.cell_type, c.source) for c in stored.cells] == \
        [(c.cell_type, c.source) for c in expected.cells], \
        f"{notebook.name} differs from its script; run python tutorials/sync.py"
    for cell in stored.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, \
                f"{notebook.name} is committed with outputs"


def test_kernel_is_this_interpreter(monkeypatch, tmp_path):
    _absolute_pythonpath(monkeypatch)
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell("import sys; print(sys.prefix)"))
    execute(nb, tmp_path)
    assert nb.cells[0].outputs[0]["text"].strip() == sys.prefix


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[nb.stem for nb in NOTEBOOKS])
def test_notebook_runs(notebook, monkeypatch):
    _absolute_pythonpath(monkeypatch)
    nb = nbformat.read(notebook, as_version=4)
    seconds = execute(nb, TUTORIALS)  # raises CellExecutionError on a failing cell
    print(f"{notebook.name}: {seconds:.1f} s")
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    # the figures reach the reader (a forced non-interactive backend would swallow them)
    assert any("image/png" in o.get("data", {}) for o in outputs)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-v", "-s"]))
