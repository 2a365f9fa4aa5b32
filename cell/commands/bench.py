"""``cell bench [--out FILE]``: the speed figures of this machine (``make bench``)."""

from __future__ import annotations

import argparse
import json
import platform
from typing import Any

HELP = "measure simulation and planner speed"
DESCRIPTION = "Benchmarks; writes a JSON of the figures (make bench)."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="reports/bench.json", help="JSON file to write")


def main(args: argparse.Namespace) -> int:
    from cell.bench import TARGET_PARTS_PER_S, benchmarks
    from cell.bench_planner import benchmarks as planner_benchmarks
    from cell.output import check_file, write_text

    check_file(args.out)  # before any work
    results: dict[str, Any] = benchmarks()
    results.update(planner_benchmarks())
    results["machine"] = f"{platform.machine()} {platform.python_implementation()} " \
                         f"{platform.python_version()}"
    for key, value in results.items():
        shown = f"{value:,.0f}" if isinstance(value, float) and value >= 100 else \
            (f"{value:.3f}" if isinstance(value, float) else str(value))
        print(f"{key:<28} {shown}")
    for key in ("parts_per_s_adaptive", "parts_per_s_non_adaptive"):
        if results[key] < TARGET_PARTS_PER_S:
            print(f"note: {key} is below the target of {TARGET_PARTS_PER_S:,} parts/s")
    write_text(json.dumps(results, indent=2, sort_keys=True) + "\n", args.out)
    print(f"wrote {args.out}")
    return 0
