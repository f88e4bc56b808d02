"""Checkpoints: the full state of a run, written atomically and verified on reading.

A checkpoint is one ``.npz`` file holding named numpy arrays plus a JSON header
(format name and version, ngfracture version, user metadata) and a SHA-256 digest
of everything else.  Writing goes through :func:`ngfracture.output.atomic.write_file`
(a temporary file in the same folder, fsync, rename, fsync of the folder); a run killed at
any moment leaves either the old or the new file, never half of one.  The newest ``keep`` checkpoints are kept.

Reading refuses, with a message naming the file, anything truncated, altered
(digest mismatch), foreign (not an ngfracture checkpoint) or of another format
version; ``latest`` names the previous valid checkpoint in that message.
"""
import hashlib
import json
import re
import zipfile
from pathlib import Path

import numpy as np

from ..output.atomic import write_file

FORMAT = "ngfracture-checkpoint"
FORMAT_VERSION = 1
PATTERN = re.compile(r"^checkpoint_(\d{6})\.npz$")


class CheckpointError(RuntimeError):
    """A checkpoint that cannot be trusted (truncated, altered, foreign or of another version)."""


def _digest(arrays, header_bytes):
    h = hashlib.sha256()
    h.update(header_bytes)
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def path_for(folder, step):
    """The file name of the checkpoint of a step.

    Parameters
    ----------
    folder : str or pathlib.Path
        The checkpoint folder.
    step : int
        Step number (six digits in the name).

    Returns
    -------
    pathlib.Path
        ``folder / "checkpoint_NNNNNN.npz"``.
    """
    return Path(folder) / f"checkpoint_{int(step):06d}.npz"


def write(folder, step, arrays, meta, keep=2):
    """Write a checkpoint atomically and keep the newest ``keep`` of them.

    Parameters
    ----------
    folder : path
        Output folder (must exist).
    step : int
        Step number, part of the file name.
    arrays : dict of str -> numpy.ndarray
        The state to store, by name.
    meta : dict
        JSON-serialisable metadata.
    keep : int
        How many checkpoints to keep (>= 1).

    Returns
    -------
    pathlib.Path
        The written file.
    """
    from .. import __version__
    folder = Path(folder)
    header = {"format": FORMAT, "format_version": FORMAT_VERSION, "ngfracture": __version__,
              "step": int(step), "meta": meta}
    header_bytes = json.dumps(header, sort_keys=True).encode()
    payload = {f"a_{k}": np.asarray(v) for k, v in arrays.items()}
    payload["header"] = np.frombuffer(header_bytes, dtype=np.uint8)
    payload["digest"] = np.frombuffer(_digest(payload, b"").encode(), dtype=np.uint8)
    target = path_for(folder, step)
    write_file(target, lambda tmp: np.savez(tmp, **payload), force=True)
    for old in list_checkpoints(folder)[:-keep]:
        old.unlink()
    return target


def read(path):
    """Read and verify one checkpoint.

    Parameters
    ----------
    path : str or pathlib.Path
        The checkpoint file.

    Returns
    -------
    arrays : dict of str -> numpy.ndarray
        The arrays given to :func:`write`.
    header : dict
        Format, format version, ngfracture version, step and user ``meta``.

    Raises
    ------
    CheckpointError
        If the file is truncated, altered, foreign or of another format version.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            payload = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError) as err:
        raise CheckpointError(f"{path}: not a readable checkpoint (truncated or foreign): {err}") from None
    if "header" not in payload or "digest" not in payload:
        raise CheckpointError(f"{path}: not an ngfracture checkpoint (no header)")
    stored = bytes(payload.pop("digest")).decode(errors="replace")
    if _digest(payload, b"") != stored:
        raise CheckpointError(f"{path}: contents do not match the stored digest (corrupted)")
    try:
        header = json.loads(bytes(payload.pop("header")).decode())
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise CheckpointError(f"{path}: unreadable header") from None
    if header.get("format") != FORMAT:
        raise CheckpointError(f"{path}: not an ngfracture checkpoint (format {header.get('format')!r})")
    if header.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(f"{path}: checkpoint format version {header.get('format_version')!r}, "
                              f"this ngfracture reads version {FORMAT_VERSION}")
    arrays = {k[2:]: v for k, v in payload.items() if k.startswith("a_")}
    return arrays, header


def list_checkpoints(folder):
    """Complete checkpoint files in a folder, oldest first (temporary files ignored).

    Parameters
    ----------
    folder : str or pathlib.Path
        The checkpoint folder; a missing folder has none.

    Returns
    -------
    list of pathlib.Path
        Files named ``checkpoint_NNNNNN.npz``, by increasing step (not verified).
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in folder.iterdir() if (m := PATTERN.match(p.name))]
    return [p for _, p in sorted(found)]


def latest(folder):
    """Read the newest checkpoint of a folder.

    Parameters
    ----------
    folder : str or pathlib.Path
        The checkpoint folder.

    Returns
    -------
    arrays : dict of str -> numpy.ndarray
    header : dict
        As for :func:`read`.

    Raises
    ------
    CheckpointError
        If there is none, or the newest one is damaged (the message names the
        previous valid one, which can be resumed by removing the damaged file).
    """
    files = list_checkpoints(folder)
    if not files:
        raise CheckpointError(f"{folder}: no checkpoint to resume from")
    try:
        return read(files[-1])
    except CheckpointError as err:
        previous = None
        for p in reversed(files[:-1]):
            try:
                read(p)
                previous = p
                break
            except CheckpointError:
                continue
        hint = (f"; the previous valid checkpoint is {previous} (remove the damaged file to resume from it)"
                if previous else "; no valid checkpoint is left")
        raise CheckpointError(str(err) + hint) from None
