"""The benchmarks' common outputs: ``--json FILE``, ``--force`` and plots.

Every benchmark writes its result as JSON, to stdout or, with ``--json FILE``, atomically
to FILE (``ngfracture.output.atomic.write_json``). An existing FILE (or plot) is refused before
any measurement unless ``--force``: a benchmark can run for hours, and a finished result is
not overwritten by mistake.
"""
import json
import os
import sys

from ngfracture.output.atomic import write_file, write_json


def add_options(parser, force_help="overwrite an existing --json file"):
    """Add ``--json FILE`` and ``--force`` to an argparse parser."""
    parser.add_argument("--json", metavar="FILE", help="write the JSON here (atomically) instead of "
                        "stdout; refused if FILE exists, unless --force")
    parser.add_argument("--force", action="store_true", help=force_help)


def refuse_existing(parser, args, *more_paths):
    """Exit with a usage error (status 2) if an output file exists and ``--force`` is not given."""
    for path in (args.json, *more_paths):
        if path is not None and os.path.exists(path) and not args.force:
            parser.error(f"{path} exists; pass --force to overwrite it")


def save_figure(fig, path):
    """Save a matplotlib figure as PNG at ``path`` atomically (a temporary file, then a rename)
    and close it."""
    import matplotlib.pyplot as plt
    write_file(path, lambda tmp: fig.savefig(tmp, dpi=120, format="png"), force=True)
    plt.close(fig)


def write(args, result):
    """Write ``result`` to ``args.json`` (atomically) or to stdout."""
    if args.json:
        write_json(args.json, result, force=args.force, make_folder=True)
    else:
        json.dump(result, sys.stdout, indent=1)
        print()
