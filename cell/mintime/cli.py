"""``cell mintime SCENARIO --out FILE``: the minimum-time R II and R IV.

Writes FILE.csv (one row per grid point of each regime: regime, s, the joint
angles, ṡ and the velocity-limit curve) and FILE.json (each regime's time and
switching points, and the limits used), both whole or not at all.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from .regimes import plan_regimes, summary

COLUMNS = ["regime", "s", "theta1_rad", "theta2_rad", "theta3_rad", "theta4_rad", "theta5_rad",
           "sdot", "sdot_limit"]


def frame(results: dict) -> pd.DataFrame:
    parts = []
    for r, res in results.items():
        p = res.profile
        data = {"regime": r, "s": p.s}
        data.update({f"theta{j + 1}_rad": res.q[:, j] for j in range(5)})
        data.update({"sdot": p.sdot, "sdot_limit": p.sdot_limit})
        parts.append(pd.DataFrame(data, columns=COLUMNS))
    return pd.concat(parts, ignore_index=True)


def stem(out: str) -> Path:
    path = Path(out)
    return path.with_suffix("") if path.suffix in (".csv", ".json") else path


def cmd_mintime(args: argparse.Namespace) -> int:
    from cell.cli import parse_sets
    from cell.output import write_csv, write_text
    from cell.scenario import load_scenario

    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    results = plan_regimes(scenario)
    table = frame(results)
    doc = json.dumps(summary(results, scenario), indent=2, allow_nan=False) + "\n"
    base = stem(args.out)
    csv_path, json_path = base.parent / (base.name + ".csv"), base.parent / (base.name + ".json")
    write_csv(table.replace([np.inf], np.nan), csv_path)
    write_text(doc, json_path)
    times = ", ".join(f"{r} {res.profile.time_s:.4f} s" for r, res in results.items())
    print(f"wrote {csv_path} and {json_path}: {times}")
    return 0
