"""Checkpoints are atomic, verified, and refuse damaged or foreign files."""
import json

import numpy as np
import pytest

from ngfracture.run import checkpoint as ck


def state(seed=0):
    rng = np.random.default_rng(seed)
    return {"u": rng.standard_normal(100), "triangles": rng.integers(0, 50, (40, 3))}


def test_roundtrip_is_exact_and_only_two_are_kept(tmp_path):
    for step in range(5):
        ck.write(tmp_path, step, state(step), {"step": step, "dx": 0.5 ** step})
    files = ck.list_checkpoints(tmp_path)
    assert [f.name for f in files] == ["checkpoint_000003.npz", "checkpoint_000004.npz"]
    arrays, header = ck.latest(tmp_path)
    for k, v in state(4).items():
        assert np.array_equal(arrays[k], v) and arrays[k].dtype == v.dtype
    assert header["meta"] == {"step": 4, "dx": 0.5 ** 4}


def test_interrupted_write_leaves_the_last_complete_checkpoint(tmp_path):
    ck.write(tmp_path, 1, state(1), {})
    # a run killed during a write leaves only a temporary file behind
    (tmp_path / ".checkpoint_abc.tmp").write_bytes(b"PK\x03\x04 half a zip")
    arrays, header = ck.latest(tmp_path)
    assert header["step"] == 1 and np.array_equal(arrays["u"], state(1)["u"])


def test_truncated_checkpoint_is_refused_and_previous_named(tmp_path):
    ck.write(tmp_path, 1, state(1), {})
    newest = ck.write(tmp_path, 2, state(2), {})
    data = newest.read_bytes()
    newest.write_bytes(data[: len(data) // 2])
    with pytest.raises(ck.CheckpointError, match="checkpoint_000002.*previous valid checkpoint is .*checkpoint_000001"):
        ck.latest(tmp_path)


def test_bit_flip_is_detected(tmp_path):
    path = ck.write(tmp_path, 1, {"u": np.zeros(1000)}, {})
    data = bytearray(path.read_bytes())
    # flip one bit inside the stored array data (zeros), away from zip headers
    pos = data.find(bytes(64)) + 32
    data[pos] ^= 0x10
    path.write_bytes(bytes(data))
    with pytest.raises(ck.CheckpointError, match="corrupted|not a readable"):
        ck.read(path)


def test_foreign_and_other_version_files_are_refused(tmp_path):
    foreign = tmp_path / "checkpoint_000001.npz"
    np.savez(foreign, u=np.zeros(3))
    with pytest.raises(ck.CheckpointError, match="not an ngfracture checkpoint"):
        ck.read(foreign)
    path = ck.write(tmp_path, 2, state(), {})
    arrays, header = ck.read(path)
    header["format_version"] = 99
    hb = json.dumps(header, sort_keys=True).encode()
    payload = {f"a_{k}": v for k, v in arrays.items()}
    payload["header"] = np.frombuffer(hb, dtype=np.uint8)
    payload["digest"] = np.frombuffer(ck._digest(payload, b"").encode(), dtype=np.uint8)
    np.savez(path, **payload)
    with pytest.raises(ck.CheckpointError, match="format version 99"):
        ck.read(path)


def test_empty_folder_has_nothing_to_resume(tmp_path):
    with pytest.raises(ck.CheckpointError, match="no checkpoint"):
        ck.latest(tmp_path)
