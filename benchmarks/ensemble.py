"""Benchmark of ensembles on dask.distributed: parallel efficiency and scheduling overhead.

The same ensemble (N samples of a coarse random-strength plate, default 8 at maxh 0.12,
no contact rows) runs on a LocalCluster of 1 and of K single-threaded worker processes
(default K = 2), each into a fresh temporary folder. Reported per worker count:

  wall              seconds from the first submission to the last sample's result
  cluster_start     seconds to start the LocalCluster (once per ensemble)
  report            seconds of the statistics and pictures (once per ensemble)
  task_sum          sum over samples of the task's seconds in its worker (scene, run, summary)
  run_sum           sum over samples of Simulation's own wall time
  efficiency        wall(1) / (K wall(K)): parallel efficiency against the 1-worker run of
                    the same process (1 for K = 1)
  overhead_per_sample   (K wall - task_sum) / N: seconds per sample that a worker was not
                    running a task (dispatch, result transfer, and idle workers at the end
                    when the samples' lengths do not divide evenly)
  overhead_share    overhead_per_sample / mean task seconds
  task_share        1 - run_sum / task_sum: the part of a task outside Simulation.run
                    (imports, meshing, reading the summary)
  busy_share        task_sum / (K wall): the share of the workers' time spent in tasks
  slowdown          mean task seconds / mean task seconds with 1 worker: how much slower a
                    sample runs next to others (cores shared with other processes)
  cpu_seconds       CPU seconds of all tasks; cpu_efficiency = cpu_seconds(1) / cpu_seconds(K):
                    1 when K workers do the same work as one (the efficiency on dedicated
                    cores, where a task's CPU seconds are its wall seconds)
  cpu_share         CPU seconds of the tasks over their wall seconds: below 1 when a
                    worker's core was shared with other processes
  load_before, load_after   os.getloadavg() (1 minute): the machine is shared

The two ensembles must be equal (timings aside); ``same_result`` says whether they are.

Usage: python benchmarks/ensemble.py [--samples 8] [--maxh 0.12] [--workers 2] [--json FILE [--force]]
"""
import argparse
import functools
import os
import sys
import tempfile

import benchmark_json
from ngfracture import scenes
from ngfracture.studies.ensemble import Ensemble, comparable_report


def measure(workers, samples, maxh, steps):
    """One ensemble on a LocalCluster of ``workers`` processes: its report and the figures."""
    factory = functools.partial(scenes.plate, maxh=maxh, weibull_m=8)
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="ngfracture_ensemble_") as out:
        report = Ensemble(factory, list(range(samples)), out=out, workers=workers, contact="never",
                          control={"max_steps": steps}, progress=False).run()
    ex = report["execution"]
    wall = ex["samples_seconds"]
    tasks = [s["timings"]["task"] for s in report["samples"]]
    runs = [s["timings"]["run"] for s in report["samples"]]
    overhead = (workers * wall - sum(tasks)) / samples
    return report, {"workers": workers, "samples": samples, "wall": wall, "cluster_start": ex["cluster_start_seconds"],
                    "report": ex["report_seconds"], "busy_share": sum(tasks) / (workers * wall),
                    "cpu_share": sum(s["timings"]["task_cpu"] for s in report["samples"]) / sum(tasks),
                    "cpu_seconds": sum(s["timings"]["task_cpu"] for s in report["samples"]),
                    "task_sum": sum(tasks), "run_sum": sum(runs), "overhead_per_sample": overhead,
                    "overhead_share": overhead / (sum(tasks) / samples), "task_share": 1 - sum(runs) / sum(tasks),
                    "steps": [s["steps"] for s in report["samples"]],
                    "load_before": load_before, "load_after": os.getloadavg()[0]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=8)
    parser.add_argument("--maxh", type=float, default=0.12)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--steps", type=int, default=200, help="at most this many steps per sample")
    benchmark_json.add_options(parser)
    args = parser.parse_args(argv)
    if args.samples < 1 or args.workers < 2 or args.maxh <= 0:
        parser.error("need --samples >= 1, --workers >= 2, --maxh > 0")
    benchmark_json.refuse_existing(parser, args)
    one_report, one = measure(1, args.samples, args.maxh, args.steps)
    many_report, many = measure(args.workers, args.samples, args.maxh, args.steps)
    one["efficiency"] = 1.0
    many["efficiency"] = one["wall"] / (args.workers * many["wall"])
    many["slowdown"] = many["task_sum"] / one["task_sum"]
    many["cpu_efficiency"] = one["cpu_seconds"] / many["cpu_seconds"]
    result = {"scene": "plate", "maxh": args.maxh, "weibull_m": 8, "contact": "never", "cpu_count": os.cpu_count(),
              "cases": [one, many], "same_result": comparable_report(one_report) == comparable_report(many_report)}
    benchmark_json.write(args, result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
