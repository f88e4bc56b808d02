"""Files written atomically: a reader sees the old file or the new one, never half of one.

Every file ngfracture writes (time series, checkpoints, summaries, pictures, JSON of the
command line and the benchmarks) goes through :func:`write_file`: the content is made in a
temporary file ``.tmp_ngf_*`` in the target's folder, flushed and fsync'ed, renamed over
the target (or hard-linked, when an existing target must be refused without a race), and
the folder is fsync'ed. A run killed at any moment leaves at most a ``.tmp_ngf_*`` file,
which the run's ``--force`` and ``--resume`` remove.
"""
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["TEMPORARY_PREFIX", "write_file", "write_bytes", "write_json", "jsonable", "fsync_folder"]

#: the name prefix of the temporary files (what a killed write leaves behind)
TEMPORARY_PREFIX = ".tmp_ngf_"


def fsync_folder(folder):
    """Flush a folder's entries (a rename into it) to the disk.

    Parameters
    ----------
    folder : str or pathlib.Path
    """
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_file(path, produce, force=False, sync=True):
    """Make a file atomically: ``produce(temporary_path)`` writes it, then it is renamed.

    Parameters
    ----------
    path : str or pathlib.Path
        The target; its folder must exist.
    produce : callable(pathlib.Path)
        Writes the whole content to the path it is given (a temporary file in the
        target's folder, with the target's suffix).
    force : bool
        Replace an existing target; without it an existing target is an error (also one
        that appears while the content is made).
    sync : bool
        fsync the file and the folder (False for files that a later synced write in the
        same folder covers, such as the steps of a time series before their collection).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and not ``force``.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=TEMPORARY_PREFIX, suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        produce(Path(tmp))
        if sync:
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        if force:
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)      # fails if path exists: no race with another writer
            except FileExistsError:
                raise FileExistsError(f"{path} exists; pass force=True to overwrite it") from None
            os.unlink(tmp)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    if sync:
        fsync_folder(path.parent)
    return path


def write_bytes(path, data, force=False, sync=True):
    """Write bytes atomically (:func:`write_file`).

    Parameters
    ----------
    path : str or pathlib.Path
    data : bytes
    force, sync : bool
        As for :func:`write_file`.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and not ``force``.
    """
    return write_file(path, lambda tmp: tmp.write_bytes(data), force, sync)


def jsonable(obj, where="data"):
    """``obj`` with numpy scalars and arrays and paths turned into what JSON holds.

    Parameters
    ----------
    obj : object
        Numbers, strings, bools, None, lists, tuples, dicts, numpy scalars and arrays, paths.
    where : str
        Its name in error messages (keys are appended: ``data['x'][2]``).

    Returns
    -------
    object
        Plain Python values.

    Raises
    ------
    ValueError
        A NaN or infinite number, named by its key path.
    TypeError
        A value or key JSON cannot hold, named by its key path.
    """
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if isinstance(k, np.generic):
                k = k.item()
            if not isinstance(k, (str, int, float, bool)) and k is not None:
                raise TypeError(f"{where}[{k!r}]: a {type(k).__name__} is not a JSON key")
            out[k] = jsonable(v, f"{where}[{k!r}]")
        return out
    if isinstance(obj, (list, tuple)):
        return [jsonable(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist(), where)
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, float) and not math.isfinite(obj):
        raise ValueError(f"{where} is {obj!r}, which JSON cannot hold")
    if obj is None or isinstance(obj, (str, int, float, bool)):
        return obj
    raise TypeError(f"{where} is a {type(obj).__name__}, which JSON cannot hold")


def write_json(path, data, force=False, make_folder=False):
    """Write a dict (or list) as indented JSON atomically, numpy values converted.

    Parameters
    ----------
    path : str or pathlib.Path
    data : dict or list
        See :func:`jsonable`.
    force : bool
        Overwrite an existing file.
    make_folder : bool
        Create missing parent folders.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and not ``force`` (also when it appears while writing).
    ValueError, TypeError
        From :func:`jsonable`, before anything is written; ``data`` not a dict or list.
    """
    if not isinstance(data, (dict, list)):
        raise TypeError(f"write_json: data must be a dict or a list, got {type(data).__name__}")
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"{path} exists; pass force=True to overwrite it")
    text = json.dumps(jsonable(data, path.name), indent=2, allow_nan=False) + "\n"
    if make_folder:
        path.parent.mkdir(parents=True, exist_ok=True)
    return write_bytes(path, text.encode(), force)
