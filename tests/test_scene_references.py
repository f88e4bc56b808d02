"""The built-in scenes give the stored results to the last bit (tools/scene_references.py).

A change meant to keep results (a restructuring, a faster kernel) must pass these as they
are; a change meant to change them records new references with
``python tools/scene_references.py --write`` and says why in its commit. The default plate
runs in the fast suite, the other scenes with ``-m slow``.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
import scene_references  # noqa: E402


def _check(name):
    import json
    stored = json.loads(scene_references.REFERENCE_FILE.read_text())[name]
    found = scene_references.reference_fingerprint(name)
    assert not scene_references.differences(stored, found), scene_references.differences(stored, found)


def test_default_plate_equals_its_reference_to_the_last_bit():
    _check("plate")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["plate4x", "disk", "disintegration"])
def test_scene_equals_its_reference_to_the_last_bit(name):
    _check(name)
