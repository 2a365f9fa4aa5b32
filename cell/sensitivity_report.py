"""What ``cell sensitivity`` writes: morris.csv, sobol.csv, points.csv, sensitivity.png and
report.md, whose reading is generated from the numbers."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from cell.sensitivity import ADVANTAGE
from cell.study import Study

FILES = ("morris.csv", "sobol.csv", "points.csv", "sensitivity.png", "report.md")
#: A key "moves" a measure when its total index's lower 95 % bound is above this.
MOVES = 0.05
HEADLINE = {"parts_missed": "parts lost", "spacing_outside_pct": "spacing off",
            "parts_per_hr_wallclock": "throughput", ADVANTAGE: "the adaptive robot's advantage"}


def movers(sobol: Any, policy: str, measure: str) -> list[tuple[str, float, float]]:
    """(key, ST, its half-width) of the keys that move ``measure`` under ``policy``, largest first."""
    f = sobol[(sobol["policy"] == policy) & (sobol["measure"] == measure)]
    f = f[f["ST"] - f["ST_ci95"] > MOVES].sort_values(["ST", "key"], ascending=[False, True])
    return [(r.key, float(r.ST), float(r.ST_ci95)) for r in f.itertuples()]


def reading(study: Study, sobol: Any, morris: Any, points: Any, policies: Sequence[str]) -> list[str]:
    """The report's conclusions, in sentences built from the tables."""
    out = []
    for policy in policies:
        for m, words in HEADLINE.items():
            if m == ADVANTAGE or not ((sobol["policy"] == policy) & (sobol["measure"] == m)).any():
                continue
            mv = movers(sobol, policy, m)
            if mv:
                keys = ", ".join(f"`{k}` (ST {st:.2f} ± {h:.2f})" for k, st, h in mv)
                out.append(f"- **{words}, {policy}**: moved by {keys}.")
            else:
                out.append(f"- **{words}, {policy}**: no key's total index is surely above "
                           f"{MOVES:g}; within these ranges it does not depend on them.")
    if ADVANTAGE in points.columns:
        adv = points[ADVANTAGE]
        worst = points.loc[adv.idxmin()]
        keys = [c for c in points.columns if c not in ("design", ADVANTAGE) and "/" not in c]
        base = {p.key: study_value(study, p.key) for p in study.params}
        at = ", ".join(f"{k} = {worst[k]:.4g}" for k in keys
                       if worst[k] == worst[k] and abs(worst[k] - base[k]) > 1e-9 * max(1, abs(base[k])))
        at = f"{worst['design']} point {int(adv.idxmin())}: " + (at or "the base values")
        n_bad = int((adv <= 0).sum())
        if n_bad == 0:
            out.append(f"- **The thesis's conclusion** (the adaptive robot delivers more parts "
                       f"than the fixed-cycle one) holds at every one of the {len(points)} points "
                       f"evaluated, each assumption anywhere in its plausible range: the smallest "
                       f"advantage is {adv.min():.1f} parts of {study.scenario({}).run.parts} "
                       f"(at {at}); the mean {adv.mean():.1f}.")
        else:
            out.append(f"- **The thesis's conclusion is reversed** at {n_bad} of {len(points)} "
                       f"points: the fixed-cycle robot delivers as many or more (worst "
                       f"{adv.min():.1f} parts, at {at}).")
        mv = movers(sobol, "both", ADVANTAGE)
        if mv:
            out.append("- The advantage's size depends most on " + ", ".join(
                f"`{k}` (ST {st:.2f} ± {h:.2f})" for k, st, h in mv) + ".")
    return out


def study_value(study: Study, key: str) -> float:
    """A key's value in the study's base scenario (with ``set``)."""
    import re

    m = re.match(r"^(.*)\[(\d+)\]$", key)
    s = study.scenario({})
    return float(s.get(m[1])[int(m[2])]) if m else float(s.get(key))


def figure(sobol: Any, path: Any) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = list(dict.fromkeys(zip(sobol["policy"], sobol["measure"])))
    keys = list(dict.fromkeys(sobol["key"]))
    fig, axes = plt.subplots(1, len(groups), figsize=(2.3 * len(groups) + 2.5, 0.35 * len(keys) + 1.6),
                             sharey=True, squeeze=False)
    y = np.arange(len(keys))
    for ax, (policy, m) in zip(axes[0], groups):
        f = sobol[(sobol["policy"] == policy) & (sobol["measure"] == m)].set_index("key").loc[keys]
        ax.barh(y + 0.2, f["ST"], 0.4, xerr=f["ST_ci95"], color="C0", label="total ST")
        ax.barh(y - 0.2, f["S1"], 0.4, xerr=f["S1_ci95"], color="C1", label="first order S1")
        ax.set_title(f"{HEADLINE.get(m, m)}\n{policy}", fontsize=8)
        ax.set_xlim(-0.05, 1.05)
        ax.axvline(MOVES, color="0.7", lw=0.8, ls=":")
    axes[0][0].set_yticks(y, keys, fontsize=7)
    axes[0][0].invert_yaxis()
    axes[0][-1].legend(fontsize=7, loc="lower right")
    fig.suptitle("Sobol indices with 95 % intervals", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def markdown(study: Study, sobol: Any, morris: Any, points: Any, policies: Sequence[str],
             sizes: dict[str, int], command: str) -> str:
    s = study.settings
    lines = [f"# {study.name}", "", s.description, "", f"Regenerate: `{command}`", "",
             "## Reading", "", *reading(study, sobol, morris, points, policies), "",
             "## What was run, and what it buys", "",
             f"- Morris screening of all {len(study.params)} keys: {sizes['trajectories']} "
             f"trajectories of {len(study.params) + 1} points ({sizes['morris']} points), "
             f"{sizes['levels']} levels. μ* ranks the keys; its interval is a bootstrap one.",
             f"- Sobol indices of the {sizes['sobol_keys']} keys Morris ranks first (the others "
             f"held at the base scenario's values): {sizes['samples']} base samples × "
             f"({sizes['sobol_keys']} + 2) = {sizes['sobol']} points; S1 and ST with bootstrap 95 % "
             f"intervals. With this many samples an index is known to about ±"
             f"{float(np.nanmedian(sobol['ST_ci95'])):.2f} (the median half-width): "
             "enough to tell a key that matters from one that does not, not to rank close ones.",
             f"- Every point runs {', '.join(policies)} on the same {s.replications} "
             f"replication streams of {study.scenario({}).run.parts} parts (common random numbers), "
             "so a measure is a deterministic function of the keys and an index is the keys' "
             "share, not the draws'.",
             "", "## Sobol indices", "", "![sensitivity](sensitivity.png)", "",
             "| policy | measure | key | S1 | ST |", "|---|---|---|---|---|"]
    for r in sobol.sort_values(["policy", "measure", "ST"], ascending=[True, True, False]).itertuples():
        lines.append(f"| {r.policy} | {r.measure} | {r.key} | {r.S1:.3f} ± {r.S1_ci95:.3f} | "
                     f"{r.ST:.3f} ± {r.ST_ci95:.3f} |")
    lines += ["", "## Morris screening (μ*, the mean absolute elementary effect)", "",
              "| key | " + " | ".join(f"{p} {HEADLINE.get(m, m)}" for p, m in
                                     dict.fromkeys(zip(morris['policy'], morris['measure']))) + " |"]
    groups = list(dict.fromkeys(zip(morris["policy"], morris["measure"])))
    lines.append("|---" * (1 + len(groups)) + "|")
    for key in dict.fromkeys(morris["key"]):
        cells = []
        for p, m in groups:
            r = morris[(morris["policy"] == p) & (morris["measure"] == m) & (morris["key"] == key)].iloc[0]
            cells.append(f"{r.mu_star:.3g} ± {r.mu_star_ci95:.2g}")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
