"""The benchmark report (issue 36 item 4, ``make benchmark``): every controller's parts
delivered as a share of the hindsight optimum, on the stress map's arrivals and the thesis's.

From :func:`cell.experiments.benchmark_runs.runs` this writes, as one set, ``runs.csv`` (each run's
parts per controller, the hindsight schedule's, the MILP's proved bound and ``parts_bound``),
``benchmark.csv`` (per point and controller: the mean share of the optimum with its 95 % t
interval, and the learned controller's and the optimum's paired differences from the adaptive
one), ``benchmark.png`` and ``report.md``, whose reading is generated from the numbers.

``python -m cell.reporting.benchmark DIR``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cell.experiments import benchmark_runs as bm
from cell.experiments.stats import paired_difference, summarise

FILES = ("report.md", "benchmark.csv", "runs.csv", "benchmark.png")
#: What each column of a run is, as the report names it.
SHOWN = {"non-adaptive": "fixed cycle", "adaptive": "adaptive (thesis)", "learned": "learned",
         "milp_upper": "MILP bound", "parts_bound": "parts_bound"}
#: A controller is near-optimal at a point where its share's interval lies above this.
NEAR = 0.95


def table(runs: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for label, _, _ in bm.POINTS:
        r = runs[runs["point"] == label].sort_values("replication")
        opt = r["optimum"].to_numpy(float)
        for name in (*bm.CONTROLLERS, "milp_upper", "parts_bound"):
            got = r[name].to_numpy(float)
            share = summarise(got / opt)
            row: dict[str, Any] = {"point": label, "controller": SHOWN[name], "n": share["n"],
                                   "parts": float(got.mean()), "optimum": float(opt.mean()),
                                   "share": share["mean"], "share_ci_low": share["ci_low"],
                                   "share_ci_high": share["ci_high"]}
            vs = paired_difference(got, r["adaptive"].to_numpy(float))
            row.update({"vs_adaptive": vs["mean"], "vs_adaptive_ci_low": vs["ci_low"],
                        "vs_adaptive_ci_high": vs["ci_high"]})
            rows.append(row)
        gap = paired_difference(opt, r["adaptive"].to_numpy(float))
        rows.append({"point": label, "controller": "hindsight optimum", "n": len(opt),
                     "parts": float(opt.mean()), "optimum": float(opt.mean()), "share": 1.0,
                     "share_ci_low": 1.0, "share_ci_high": 1.0, "vs_adaptive": gap["mean"],
                     "vs_adaptive_ci_low": gap["ci_low"], "vs_adaptive_ci_high": gap["ci_high"]})
    return pd.DataFrame(rows)


def pooled(runs: pd.DataFrame, name: str) -> float:
    """Parts delivered over all runs as a share of the optimum over all runs."""
    return float(runs[name].sum() / runs["optimum"].sum())


def headline(runs: pd.DataFrame) -> str:
    n, exact = len(runs), int(runs["exact"].sum())
    return (f"Over {n} runs of {bm.PARTS} parts ({len(bm.POINTS)} arrival patterns x "
            f"{bm.REPLICATIONS}), the thesis's adaptive controller delivers "
            f"{100 * pooled(runs, 'adaptive'):.1f} % of the hindsight optimum, the learned "
            f"controller {100 * pooled(runs, 'learned'):.1f} % and the fixed cycle "
            f"{100 * pooled(runs, 'non-adaptive'):.1f} %; the optimum is proved (the MILP's "
            f"bound met) in {exact} of the {n} runs.")


def reading(t: pd.DataFrame, runs: pd.DataFrame) -> list[str]:
    """Sentences made from the numbers: the headline, where the thesis's rule is near-optimal,
    where learning pays or costs, where knowing the arrivals pays, how loose the bound is."""
    out = [headline(runs)]
    ad, le = t[t["controller"] == SHOWN["adaptive"]], t[t["controller"] == SHOWN["learned"]]
    hs = t[t["controller"] == "hindsight optimum"]
    near = ad[ad["share_ci_low"] >= NEAR]["point"].tolist()
    out.append("The thesis's rule is near-optimal (its share's 95 % interval above "
               f"{100 * NEAR:g} %) on {_list(near)}." if near else
               f"The thesis's rule is near-optimal (above {100 * NEAR:g} %) on none of the "
               "patterns.")
    wins = le[le["vs_adaptive_ci_low"] > 0]
    losses = le[le["vs_adaptive_ci_high"] < 0]
    out.append("Learning pays (the learned controller's paired difference from the adaptive "
               "one above zero at 95 %) on " + (_parts(wins) if len(wins) else "none of them")
               + "; it costs parts on " + (_parts(losses) if len(losses) else "none") + "; "
               "elsewhere the two cannot be told apart in these runs.")
    big = hs.sort_values("vs_adaptive", ascending=False)
    top, none = big.iloc[0], big[big["vs_adaptive"] == 0]["point"].tolist()
    out.append(f"Knowing every arrival in advance pays most on {top['point']}: the hindsight "
               f"schedule delivers {top['vs_adaptive']:.1f} parts a run more than the adaptive "
               f"controller (95 % interval {top['vs_adaptive_ci_low']:.1f} to "
               f"{top['vs_adaptive_ci_high']:.1f}) of an optimum of {top['optimum']:.1f}"
               + (f"; on {_list(none)} it pays nothing." if none else "."))
    bound = pooled(runs, "parts_bound")
    loose = t[t["controller"] == SHOWN["parts_bound"]].sort_values("share").iloc[-1]
    met = int((runs["parts_bound"] == runs["milp_upper"]).sum())
    out.append(f"parts_bound (each part's window at B, picks a fastest cycle apart, and far "
               f"enough apart on the one belt) is {100 * (bound - 1):.1f} % above the optimum "
               f"over all runs (the MILP's bound {100 * (pooled(runs, 'milp_upper') - 1):.1f} %) "
               f"and meets the MILP's bound in {met} of the {len(runs)}; loosest on "
               f"{loose['point']} ({100 * (loose['share'] - 1):.1f} % above).")
    return out


def _list(items: list[str]) -> str:
    return ", ".join(items[:-1]) + (" and " if len(items) > 1 else "") + items[-1] if items \
        else "none"


def _parts(rows: pd.DataFrame) -> str:
    return _list([f"{r.point} ({r.vs_adaptive:+.1f} parts a run)" for r in rows.itertuples()])


def figure(t: pd.DataFrame) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from cell.reporting.maps.map_report import png_bytes

    shown = [SHOWN[c] for c in (*bm.CONTROLLERS, "milp_upper", "parts_bound")]
    points = [p[0] for p in bm.POINTS]
    fig = Figure(figsize=(12, 4.8), dpi=90, layout="constrained")
    ax = fig.subplots()
    width = 0.8 / len(shown)
    for j, name in enumerate(shown):
        sub = t[t["controller"] == name].set_index("point").loc[points]
        x = np.arange(len(points)) + (j - (len(shown) - 1) / 2) * width
        err = np.vstack([sub["share"] - sub["share_ci_low"], sub["share_ci_high"] - sub["share"]])
        ax.bar(x, sub["share"], width, yerr=np.nan_to_num(err), capsize=2, label=name)
    ax.axhline(1.0, color="black", lw=0.8)
    ax.set_xticks(range(len(points)), points, fontsize=8)
    ax.set_ylabel("parts delivered / hindsight optimum")
    ax.set_ylim(0.5, None)
    ax.legend(fontsize=8, ncol=5, loc="upper left")
    ax.set_title(f"Each controller against the hindsight optimum ({bm.PARTS} parts a run, "
                 f"{bm.REPLICATIONS} replications a pattern, 95 % intervals)", fontsize=10)
    return png_bytes(fig)


def markdown(t: pd.DataFrame, runs: pd.DataFrame) -> str:
    lines = ["# Benchmark: every controller against the hindsight optimum", "",
             "Generated by `make benchmark` (`python -m cell.reporting.benchmark "
             "reports/benchmark`, code in cell/experiments/benchmark_runs.py). Each arrival pattern "
             f"runs {bm.REPLICATIONS} replications of {bm.PARTS} parts; replication r is "
             "`run.seed: r` for every controller and for the hindsight, so all see the same "
             "parts (common random numbers). The hindsight optimum is the best schedule the "
             "cell ran knowing every arrival (`cell hindsight`'s search, or a controller's own "
             "run if it delivered more); the MILP's bound (HiGHS, speeds discretised as "
             "docs/model.md says) is what no schedule can beat; `parts_bound` is the cheaper "
             "relaxation every run reports. Shares are per run, their mean with a 95 % t "
             f"interval; the hindsight budget was {bm.BUDGET_S:g} s a run. The learned "
             "controller is docs/rl.md's (its training runs: seeds 7001-7002, 150 parts, "
             "four of these patterns).", "", "| pattern | what |", "|---|---|"]
    lines += [f"| {label} | {what} |" for label, what, _ in bm.POINTS]
    lines += ["", "![shares of the optimum](benchmark.png)", "", "## Reading", ""]
    for sentence in reading(t, runs):
        lines += [sentence, ""]
    lines += ["## Shares of the optimum", "", "| pattern | " +
              " | ".join(SHOWN[c] for c in (*bm.CONTROLLERS, "milp_upper", "parts_bound")) +
              " | optimum (parts) |", "|---|" + "---|" * 6]
    for label, _, _ in bm.POINTS:
        sub = {r.controller: r for r in t[t["point"] == label].itertuples()}
        cells = []
        for c in (*bm.CONTROLLERS, "milp_upper", "parts_bound"):
            r = sub[SHOWN[c]]
            cells.append(f"{r.share:.3f} ({r.share_ci_low:.3f}-{r.share_ci_high:.3f})")
        optimum = sub["hindsight optimum"].parts
        lines.append(f"| {label} | " + " | ".join(cells) + f" | {optimum:.1f} |")
    return "\n".join(lines).rstrip() + "\n"


def write(out_dir: str | Path, rows: list[dict[str, Any]] | None = None) -> Path:
    from cell.plumbing.output.atomic import OutputDir

    OutputDir.check(out_dir, FILES, option="DIR")
    runs = pd.DataFrame(rows if rows is not None else bm.runs(), columns=list(bm.RUN_COLUMNS))
    t = table(runs)
    with OutputDir(out_dir, FILES, option="DIR") as out:
        out.write_text("report.md", markdown(t, runs))
        out.write_csv("benchmark.csv", t)
        out.write_csv("runs.csv", runs)
        with out.open("benchmark.png", "wb") as fh:
            fh.write(figure(t))
    return Path(out_dir)


if __name__ == "__main__":  # pragma: no cover
    if len(sys.argv) != 2:
        print("usage: python -m cell.reporting.benchmark DIR", file=sys.stderr)
        sys.exit(2)
    print(f"wrote {write(sys.argv[1])}")
