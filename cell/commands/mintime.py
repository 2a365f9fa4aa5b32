"""``cell mintime SCENARIO --out STEM``: the minimum-time R II and R IV (Shin & McKay 1983).

Writes STEM.csv (one row per grid point of each regime: regime, s, the joint
angles, ṡ and the velocity-limit curve) and STEM.json (each regime's time and
switching points, and the limits used), both whole or not at all.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from cell.commands import scenario_arguments

HELP = "minimum-time motion along the path (Shin & McKay)"
DESCRIPTION = ("Phase-plane minimum-time parameterisation of R II and R IV; writes STEM.csv "
               "and STEM.json.")
COLUMNS = ["regime", "s", "theta1_rad", "theta2_rad", "theta3_rad", "theta4_rad", "theta5_rad",
           "sdot", "sdot_limit"]


def frame(results: dict[str, Any]) -> Any:
    import pandas as pd

    parts = []
    for r, res in results.items():
        p = res.profile
        data = {"regime": r, "s": p.s}
        data.update({f"theta{j + 1}_rad": res.q[:, j] for j in range(5)})
        data.update({"sdot": p.sdot, "sdot_limit": p.sdot_limit})
        parts.append(pd.DataFrame(data, columns=COLUMNS))
    return pd.concat(parts, ignore_index=True)


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True, help="output stem: STEM.csv and STEM.json")


def stem(out: str) -> Path:
    path = Path(out)
    return path.with_suffix("") if path.suffix in (".csv", ".json") else path


def main(args: argparse.Namespace) -> int:
    import numpy as np

    from cell.assembly import geometry_of, motors_of, planner_bounds, step_table
    from cell.errors import CellError, NoMotionError
    from cell.mintime.regimes import plan_regimes, summary
    from cell.output import write_csv, write_text
    from cell.overrides import parse_sets
    from cell.scenario import load_scenario

    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    step_table(scenario)  # reach and motor checks, naming their keys
    bounds = planner_bounds(scenario)
    try:
        results = plan_regimes(geometry_of(scenario), motors_of(scenario), bounds)
    except NoMotionError as exc:
        raise CellError(f"{scenario.source}: mintime: {exc}") from None
    table = frame(results)
    doc = json.dumps(summary(results, bounds), indent=2, allow_nan=False) + "\n"
    base = stem(args.out)
    csv_path, json_path = base.parent / (base.name + ".csv"), base.parent / (base.name + ".json")
    write_csv(table.replace([np.inf], np.nan), csv_path)
    write_text(doc, json_path)
    times = ", ".join(f"{r} {res.profile.time_s:.4f} s" for r, res in results.items())
    print(f"wrote {csv_path} and {json_path}: {times}")
    return 0
