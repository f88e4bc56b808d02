"""Compare the built-in scenes' results with stored references, to the last bit.

A change that must not change results (a restructuring, a faster kernel) is checked with

    python tools/scene_references.py --check            # all four scenes
    python tools/scene_references.py --check plate      # one

and a change that is meant to change them records new references with ``--write``
(commit the JSON with the change and say why in its message).  Each reference holds,
per scene, the accepted steps (load, increment, split vertices, fragments, crack length)
and the final state: split vertices, fragments, crack length, the final displacement and
mesh as SHA-256 of their bytes.  Floats are stored as ``float.hex`` so that "equal" means
equal to the last bit.  tests/test_scene_references.py runs the same comparison.

The last bits of the displacement depend on the BLAS kernels OpenBLAS picks for the CPU
(numpy's and scipy's OpenBLAS: its AVX-512 kernels sum in another order than its AVX2
ones; the crack pattern, the loads and the mesh are the same).  The scenes therefore run in
a child process with ``OPENBLAS_CORETYPE`` set to :data:`OPENBLAS_REFERENCE_CORE` on x86-64,
the kernels the references were written with, so that any x86-64 machine with AVX2
compares to the last bit (docs/design.md, "Determinism").
"""
import argparse
import hashlib
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np

#: the OpenBLAS kernels of the stored references (x86-64 machines with AVX2)
OPENBLAS_REFERENCE_CORE = "Haswell"

REFERENCE_FILE = Path(__file__).resolve().parent.parent / "tests" / "data" / "scene_references.json"

#: scene name -> (scene function name, its parameters)
SCENES = {
    "plate": ("plate", {}),
    "plate4x": ("plate", {"maxh": 0.017}),
    "disk": ("disk", {}),
    "disintegration": ("disintegration", {}),
}


def _sha(array):
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()


def scene_fingerprint(name):
    """Run one scene (no files) and return its fingerprint as a JSON-able dict."""
    import ngfracture as nf
    function, params = SCENES[name]
    scene = getattr(nf.scenes, function)(**params)
    result = nf.Simulation(scene, nf.StepControl()).run()
    state, summary = result.state, result.summary
    steps = [{"x": float(h["x"]).hex(), "dx": float(h["dx"]).hex(), "split_vertices": h["split_vertices"],
              "fragments": h["fragments"], "crack_length": float(h["crack_length"]).hex()}
             for h in state.history]
    return {"reason": result.reason, "n_steps": summary["n_steps"],
            "n_split_vertices": summary["n_split_vertices"], "n_fragments": summary["n_fragments"],
            "crack_length": float(summary["crack_length"]).hex(),
            "displacement_sha256": _sha(state.u), "points_sha256": _sha(state.arrays.points),
            "triangles_sha256": _sha(state.arrays.triangles), "steps": steps}


def reference_fingerprint(name):
    """:func:`scene_fingerprint` in a child process with the references' BLAS kernels."""
    env = dict(os.environ)
    if platform.machine().lower() in ("x86_64", "amd64"):
        env["OPENBLAS_CORETYPE"] = OPENBLAS_REFERENCE_CORE
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)   # the ngfracture this process imports
    done = subprocess.run([sys.executable, __file__, "--fingerprint", name], env=env, capture_output=True,
                          text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"scene {name} failed in its child process:\n{done.stderr}")
    return json.loads(done.stdout)


def differences(reference, found):
    """The keys (and steps) where two fingerprints differ; empty when equal."""
    diffs = [k for k in reference if k != "steps" and reference[k] != found.get(k)]
    ref_steps, new_steps = reference["steps"], found["steps"]
    if len(ref_steps) != len(new_steps):
        diffs.append(f"steps: {len(ref_steps)} in the reference, {len(new_steps)} now")
    for i, (a, b) in enumerate(zip(ref_steps, new_steps)):
        keys = [k for k in a if a[k] != b.get(k)]
        if keys:
            diffs.append(f"step {i + 1}: {keys}")
            break
    return diffs


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true", help="compare with the stored references")
    mode.add_argument("--write", action="store_true", help="store new references")
    mode.add_argument("--fingerprint", action="store_true", help=argparse.SUPPRESS)  # the child process
    parser.add_argument("scenes", nargs="*", help=f"some of {', '.join(SCENES)} (default: all)")
    args = parser.parse_args(argv)
    unknown = sorted(set(args.scenes) - set(SCENES))
    if unknown:
        parser.error(f"unknown scene(s) {unknown}; the scenes are {list(SCENES)}")
    if args.fingerprint:
        print(json.dumps(scene_fingerprint(args.scenes[0])))
        return 0
    stored = json.loads(REFERENCE_FILE.read_text()) if REFERENCE_FILE.exists() else {}
    failed = False
    for name in args.scenes or list(SCENES):
        found = reference_fingerprint(name)
        if args.write:
            stored[name] = found
            print(f"{name}: written ({found['n_steps']} steps, {found['n_split_vertices']} splits, "
                  f"{found['n_fragments']} fragments)")
            continue
        diffs = differences(stored[name], found) if name in stored else ["no reference stored"]
        print(f"{name}: {'equal to the last bit' if not diffs else 'DIFFERENT: ' + '; '.join(diffs)}")
        failed |= bool(diffs)
    if args.write:
        REFERENCE_FILE.parent.mkdir(parents=True, exist_ok=True)
        REFERENCE_FILE.write_text(json.dumps(stored, indent=1, sort_keys=True) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
