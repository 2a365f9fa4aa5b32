"""``cell sensitivity STUDY --out DIR [--workers N]``."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path
from typing import Any

from cell.cli.common import check_workers, workers_argument

HELP = "which keys the measures depend on: Morris screening, then Sobol indices (SALib)"
DESCRIPTION = ("Screen a study file's keys over their ranges with Morris's elementary effects, "
               "then compute Sobol indices (first order and total, 95 % intervals) of the keys "
               "that matter, per measure and policy, on common random numbers; write "
               "morris.csv, sobol.csv, points.csv, sensitivity.png and report.md into DIR, "
               "as a unit.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("study", help="study YAML file, or a built-in one by name (assumptions)")
    p.add_argument("--out", required=True, help="directory for the results")
    workers_argument(p, default="1")  # args.workers or 1, below


def main(args: argparse.Namespace) -> int:
    from cell.experiments.study import load_study
    from cell.plumbing.errors import ScenarioError
    from cell.plumbing.output.atomic import OutputDir
    from cell.reporting.sensitivity_report import FILES
    from cell.scenario import catalog

    OutputDir.check(args.out, FILES)
    check_workers(args.workers)
    source = catalog.resolve(args.study)
    study = load_study(source)
    for p in study.params:
        if p.is_choice:
            raise ScenarioError(source, f"vary.{p.key}", list(p.choices), "sensitivity needs a "
                                "range [low, high]; list policies under 'policies'")
    if not study.settings.measures:
        raise ScenarioError(source, "measures", [], "name the measures to analyse")
    sizes = _sizes(study, source)
    frames = run(study, args.workers or 1, sizes)
    write(study, args.out, frames, sizes, f"cell sensitivity {shlex.quote(catalog.shown(source))} --out ...")
    print(f"wrote {args.out}: " + ", ".join(FILES))
    return 0


def _sizes(study: Any, source: Path) -> dict[str, int]:
    """The designs' sizes, each within MAX_POINTS points (one rule for Morris and Sobol)."""
    from cell.experiments.study import MAX_POINTS
    from cell.plumbing.errors import ScenarioError

    m, s = study.settings.morris, study.settings.sobol
    if s.samples & (s.samples - 1):
        raise ScenarioError(source, "sobol.samples", s.samples, "must be a power of 2 (Sobol sequence)")
    keys = min(s.keys or len(study.params), len(study.params))
    for key, count, points in (("morris.trajectories", m.trajectories, len(study.params) + 1),
                               ("sobol.samples", s.samples, keys + 2)):
        if count * points > MAX_POINTS:
            raise ScenarioError(source, key, count, f"{count:,} x {points} = {count * points:,} "
                                f"points: at most {MAX_POINTS:,} a design")
    return {"trajectories": m.trajectories, "levels": m.levels, "samples": s.samples,
            "sobol_keys": keys}


def run(study: Any, workers: int, sizes: dict[str, int]) -> dict[str, Any]:
    import numpy as np
    import pandas as pd

    from cell.experiments.sensitivity import (
        columns,
        evaluate,
        morris_design,
        morris_indices,
        screened,
        sobol_design,
        sobol_indices,
    )
    from cell.plumbing.progress import Progress

    policies = study.policies_run()
    measures = list(study.settings.measures)
    cols = columns(policies, measures)
    seed = study.settings.seed
    md = morris_design(study.params, sizes["trajectories"], sizes["levels"], seed)
    params = list(study.params)
    keep = sizes["sobol_keys"]
    sd_n = sizes["samples"] * (keep + 2)
    bar = Progress(len(md.points) + sd_n, f"sensitivity {study.name}", "points")
    ym = evaluate(study, md, policies, measures, workers, bar)
    mrows, mu = [], {}
    for j, col in enumerate(cols):
        if not np.isfinite(ym[:, j]).any():  # the policy does not give it (thesis_slack_s)
            continue
        res = morris_indices(md, ym[:, j], sizes["levels"], seed)
        mu[col] = res["mu_star"]
        mrows += [{"policy": col[0], "measure": col[1], "key": k, "mu_star": res["mu_star"][i],
                   "mu_star_ci95": res["mu_star_conf"][i], "sigma": res["sigma"][i]}
                  for i, k in enumerate(md.keys)]
    spread = {col: float(np.ptp(ym[:, j])) for j, col in enumerate(cols) if col in mu}
    chosen = screened(params, mu, spread, keep)
    sd = sobol_design(chosen, sizes["samples"], seed)
    ys = evaluate(study, sd, policies, measures, workers, bar)
    bar.close()
    srows = []
    for j, col in enumerate(cols):
        if col not in mu:  # no index for a measure this policy does not give: none written
            continue
        res = sobol_indices(sd, ys[:, j], seed)
        srows += [{"policy": col[0], "measure": col[1], "key": k, "S1": res["S1"][i],
                   "S1_ci95": res["S1_conf"][i], "ST": res["ST"][i], "ST_ci95": res["ST_conf"][i]}
                  for i, k in enumerate(sd.keys)]
    names = [f"{p}/{m}" if m != "advantage" else m for p, m in cols]
    points = pd.concat([_points("morris", md, ym, names), _points("sobol", sd, ys, names)],
                       ignore_index=True)
    for p in study.params:  # a whole-number key as the runs had it
        if p.whole and p.key in points.columns:
            points[p.key] = points[p.key].round()
    sizes.update(morris=len(md.points), sobol=len(sd.points))
    return {"morris": pd.DataFrame(mrows), "sobol": pd.DataFrame(srows), "points": points,
            "policies": policies}


def _points(name: str, design: Any, y: Any, names: list[str]) -> Any:
    import pandas as pd

    f = pd.DataFrame(design.points, columns=list(design.keys))
    f.insert(0, "design", name)
    for j, n in enumerate(names):
        f[n] = y[:, j]
    return f


def write(study: Any, out: str, frames: dict[str, Any], sizes: dict[str, int], command: str) -> None:
    from cell.plumbing.output.atomic import OutputDir
    from cell.reporting.sensitivity_report import FILES, figure, markdown

    with OutputDir(out, FILES) as d:
        for n in ("morris", "sobol", "points"):
            d.write_csv(f"{n}.csv", frames[n])
        figure(frames["sobol"], d.path("sensitivity.png"))
        d.write_text("report.md", markdown(study, frames["sobol"], frames["morris"],
                                           frames["points"], frames["policies"], sizes, command))
