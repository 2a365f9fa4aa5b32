"""``cell mintime SCENARIO --out DIR``: the minimum-time R II and R IV (Shin & McKay 1983).

Writes DIR/profile.csv (one row per grid point of each regime: regime, s, the
time from the regime's start, the joint angles, ṡ and the velocity-limit curve)
and DIR/summary.json (each regime's time and switching points, and the limits
used) as one set: both appear together or neither does.  docs/usage.md
("Minimum-time motion") describes every column and key.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from cell.cli.common import scenario_arguments, scenario_of

HELP = "minimum-time motion along the path (Shin & McKay)"
DESCRIPTION = ("Phase-plane minimum-time parameterisation of R II and R IV; writes "
               "DIR/profile.csv and DIR/summary.json.")
COLUMNS = ["regime", "s", "t_s", "theta1_rad", "theta2_rad", "theta3_rad", "theta4_rad",
           "theta5_rad", "sdot", "sdot_limit"]
#: The files of ``cell mintime``, written as one set.
FILES = ("profile.csv", "summary.json")


def frame(results: dict[str, Any]) -> Any:
    import pandas as pd

    from cell.arm.mintime.planner import elapsed_s

    parts = []
    for r, res in results.items():
        p = res.profile
        data = {"regime": r, "s": p.s, "t_s": elapsed_s(p.s, p.sdot)}
        data.update({f"theta{j + 1}_rad": res.q[:, j] for j in range(5)})
        data.update({"sdot": p.sdot, "sdot_limit": p.sdot_limit})
        parts.append(pd.DataFrame(data, columns=COLUMNS))
    return pd.concat(parts, ignore_index=True)


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True, metavar="DIR",
                   help="directory for profile.csv and summary.json")


def check_out(out: str) -> None:
    """Refuse, before any work, an ``--out`` that cannot take the set (or names a file the old way)."""
    from cell.plumbing.errors import CellError
    from cell.plumbing.output.atomic import OutputDir

    if Path(out).suffix.lower() in (".csv", ".json") and not Path(out).is_dir():
        raise CellError(f"{out}: --out names a directory (it gets {' and '.join(FILES)}); "
                        f"drop the {Path(out).suffix}")
    OutputDir.check(out, FILES)


def main(args: argparse.Namespace) -> int:
    import numpy as np

    from cell.arm.mintime.regimes import plan_regimes, summary
    from cell.plumbing.errors import InfeasibleError, NoMotionError, ScenarioError
    from cell.plumbing.output.atomic import OutputDir
    from cell.scenario.schema import MAX_TIME_S, inert_settings
    from cell.sim.physics_checks import planner_error, step_table
    from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

    check_out(args.out)  # before any work
    scenario = scenario_of(args)
    step_table(scenario)  # reach and motor checks, naming their keys
    for line in inert_settings(scenario):
        print(f"cell: warning: {line}", file=sys.stderr)
    bounds = planner_bounds(scenario)
    rates = "robot.motors.max_rate_no_load_rad_s"
    try:
        results = plan_regimes(geometry_of(scenario), motors_of(scenario), bounds)
    except NoMotionError as exc:
        raise planner_error(scenario, exc, "mintime") from None
    except InfeasibleError as exc:  # the drives cannot turn at the motors' rates (dynamics file)
        raise ScenarioError(scenario.source, rates, scenario.get(rates),
                            f"{exc} (drives of {scenario.mintime.dynamics_file})") from None
    slowest = max(results, key=lambda r: results[r].profile.time_s)
    if not results[slowest].profile.time_s <= MAX_TIME_S:  # the schema's bound on any time
        key = "mintime.rate_fraction" if scenario.mintime.rate_fraction < 1 else rates
        value = scenario.get(key)
        raise ScenarioError(scenario.source, key, value,
                            f"{slowest} would take {results[slowest].profile.time_s:.4g} s, more "
                            f"than {MAX_TIME_S:g} s")
    table = frame(results)
    doc = json.dumps(summary(results, bounds), indent=2, allow_nan=False) + "\n"
    with OutputDir(args.out, FILES) as out:
        out.write_csv("profile.csv", table.replace([np.inf], np.nan))
        out.write_text("summary.json", doc)
    from cell.reporting.planner_report import planner_line

    print(planner_line(scenario))
    times = ", ".join(f"{r} {res.profile.time_s:.4f} s" for r, res in results.items())
    print(f"wrote {out.target}/profile.csv and summary.json: {times}")
    return 0
