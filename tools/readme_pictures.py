"""Make the README's pictures with the code they show: run scenes, copy their final.png.

Usage: python tools/readme_pictures.py [--scenes plate disk] [--out out/readme]

Writes docs/<scene>.png (the final state of ``ngfracture run <scene>`` at its default
resolution) and prints each run's summary line. Run it from the repository root with
the package installed (or built in place and on PYTHONPATH).
"""
import argparse
import shutil
import sys
from pathlib import Path

from ngfracture import scenes
from ngfracture import Simulation

ROOT = Path(__file__).resolve().parent.parent


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", default=["plate", "disk"], choices=sorted(scenes.SCENES))
    p.add_argument("--out", default="out/readme", help="where the runs write (replaced)")
    args = p.parse_args(argv)
    docs = ROOT / "docs"
    docs.mkdir(exist_ok=True)
    for name in args.scenes:
        result = Simulation(scenes.SCENES[name](), out=Path(args.out) / name, force=True).run()
        s = result.summary
        print(f"{name}: {result.reason}, {s['n_steps']} steps, {s['n_split_vertices']} split vertices, "
              f"{s['n_fragments']} fragments, {s['timings']['wall']:.1f} s")
        if "final" not in s.get("pictures", {}):
            print(f"{name}: no picture ({s.get('pictures')})", file=sys.stderr)
            return 1
        shutil.copyfile(Path(args.out) / name / "final.png", docs / f"{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
