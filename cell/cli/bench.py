"""``cell bench [--out FILE]``: the speed figures of this machine (``make bench``)."""

from __future__ import annotations

import argparse
import json
import platform
from typing import Any

HELP = "measure simulation and planner speed"
DESCRIPTION = ("Benchmarks: simulation speed and its share of SimPy's own, a cold start, the "
               "Table 7.1 sweep, peak memory of a long run, the planner; writes a JSON of the "
               "figures (make bench).")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="reports/bench.json", help="JSON file to write")


def main(args: argparse.Namespace) -> int:
    from cell.bench.planner_speed import benchmarks as planner_benchmarks
    from cell.bench.throughput import benchmarks, verdicts
    from cell.plumbing.output.atomic import check_file, write_text

    check_file(args.out)  # before any work
    results: dict[str, Any] = benchmarks()
    results.update(planner_benchmarks())
    results["machine"] = f"{platform.machine()} {platform.python_implementation()} " \
                         f"{platform.python_version()}"
    for key, value in sorted(results.items()):
        shown = f"{value:,.0f}" if isinstance(value, float) and value >= 100 else \
            (f"{value:.4g}" if isinstance(value, float) else str(value))
        print(f"{key:<36} {shown}")
    print()
    print(f"{'target':<40} {'value':>12}  {'wanted':<12} met")
    for name, value, wanted, met in verdicts(results):
        print(f"{name:<40} {value:>12}  {wanted:<12} {'yes' if met else 'NO'}")
    write_text(json.dumps(results, indent=2, sort_keys=True) + "\n", args.out)
    print(f"wrote {args.out}")
    return 0
