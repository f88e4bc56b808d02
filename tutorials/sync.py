"""Keep the tutorial notebooks and their percent-format scripts in step.

Each tutorial exists twice: ``NN_name.py`` (jupytext "percent" format, the file
to review and edit) and ``NN_name.ipynb`` (what users open in Jupyter), stored
without outputs.  ``python tutorials/sync.py`` rewrites every notebook from its
script; ``tests/test_tutorials.py`` checks that they agree cell by cell.

The percent format: a line ``# %%`` starts a code cell, ``# %% [markdown]`` a
markdown cell whose lines are comments (``# text``); a leading ``# ---`` block is
the jupytext header and is skipped.
"""
import sys
from pathlib import Path

import nbformat

HERE = Path(__file__).resolve().parent

KERNELSPEC = {"display_name": "Python 3", "language": "python", "name": "python3"}


def parse_percent(text):
    """Split a percent-format script into cells.

    Parameters
    ----------
    text : str
        The script.

    Returns
    -------
    list of (str, str)
        ``(cell_type, source)`` pairs, ``cell_type`` "code" or "markdown", with
        leading and trailing blank lines of each cell removed.
    """
    lines = text.splitlines()
    if lines and lines[0] == "# ---":
        end = lines.index("# ---", 1)
        lines = lines[end + 1:]
    cells = []
    kind, body = None, []

    def flush():
        if kind is not None:
            while body and not body[0].strip():
                body.pop(0)
            while body and not body[-1].strip():
                body.pop()
            cells.append((kind, "\n".join(body)))

    for line in lines:
        if line.startswith("# %%"):
            flush()
            kind = "markdown" if "[markdown]" in line else "code"
            body = []
        elif kind == "markdown":
            body.append(line[2:] if line.startswith("# ") else line.lstrip("#"))
        elif kind is not None:
            body.append(line)
    flush()
    return cells


def notebook_from_script(path):
    """A notebook (no outputs) with the cells of a percent-format script.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.py`` script.

    Returns
    -------
    nbformat.NotebookNode
    """
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = dict(KERNELSPEC)
    nb.metadata["language_info"] = {"name": "python"}
    for kind, source in parse_percent(Path(path).read_text(encoding="utf-8")):
        if kind == "code":
            nb.cells.append(nbformat.v4.new_code_cell(source))
        else:
            nb.cells.append(nbformat.v4.new_markdown_cell(source))
    for i, cell in enumerate(nb.cells):
        cell["id"] = f"cell-{i}"  # deterministic ids: no churn in git diffs
    return nb


def scripts():
    """The tutorial scripts in this folder, in order (``NN_*.py``)."""
    return sorted(HERE.glob("[0-9][0-9]_*.py"))


def main():
    """Rewrite every tutorial notebook from its script."""
    for script in scripts():
        nb = notebook_from_script(script)
        nbformat.validate(nb)
        target = script.with_suffix(".ipynb")
        nbformat.write(nb, target)
        print(f"wrote {target.name} ({len(nb.cells)} cells)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
