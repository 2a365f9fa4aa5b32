"""What ``cell sensitivity`` writes: morris.csv, sobol.csv, points.csv, sensitivity.png and
report.md, whose reading is generated from the numbers."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from cell.experiments.sensitivity import ADVANTAGE
from cell.experiments.study import Study
from cell.scenario.run_length import RunLength

FILES = ("morris.csv", "sobol.csv", "points.csv", "sensitivity.png", "report.md")
#: A key "moves" a measure when its total index's lower 95 % bound is above this ...
MOVES = 0.05
#: ... and the measure itself spreads over the points by more than this share of its mean
#: (below it, the indices apportion a variance too small to matter to anyone).
MATERIAL = 0.005
HEADLINE = {"parts_missed": "parts lost", "spacing_outside_pct": "spacing off",
            "parts_per_hr_wallclock": "throughput", "r4_s": "R IV's time (the robot's own motion)",
            ADVANTAGE: "the adaptive robot's advantage"}


def movers(sobol: Any, policy: str, measure: str) -> list[tuple[str, float, float]]:
    """(key, ST, its half-width) of the keys that move ``measure`` under ``policy``, largest first."""
    f = sobol[(sobol["policy"] == policy) & (sobol["measure"] == measure)]
    f = f[f["ST"] - f["ST_ci95"] > MOVES].sort_values(["ST", "key"], ascending=[False, True])
    return [(r.key, float(r.ST), float(r.ST_ci95)) for r in f.itertuples()]


def _span(points: Any, policy: str, m: str) -> tuple[str, bool]:
    """A measure's range over the points, in words, and whether that range is material."""
    col = f"{policy}/{m}" if m != ADVANTAGE else m
    if col not in points.columns:
        return "", True
    lo, hi = float(points[col].min()), float(points[col].max())
    if lo == hi:
        return f"{lo:.5g} at every point", False
    share = (hi - lo) / max(abs(float(points[col].mean())), 1e-300)
    return f"{lo:.5g} to {hi:.5g} over the points, a spread of {100 * share:.2g} %", share > MATERIAL


def reading(study: Study, sobol: Any, morris: Any, points: Any, policies: Sequence[str]) -> list[str]:
    """The report's conclusions, in sentences built from the tables."""
    out = []
    for policy in policies:
        for m in study.settings.measures:  # each measure asked for, in the study's order
            words = HEADLINE.get(m, f"`{m}`")
            if m == ADVANTAGE:
                continue
            if not ((sobol["policy"] == policy) & (sobol["measure"] == m)).any():
                if f"{policy}/{m}" in points.columns and points[f"{policy}/{m}"].isna().all():
                    out.append(f"- **{words}, {policy}**: n/a, no run of this policy gives it "
                               "a value, so it has no indices.")
                continue
            mv = movers(sobol, policy, m)
            span, material = _span(points, policy, m)
            if not material and "every point" in span:
                out.append(f"- **{words}, {policy}** ({span}): no assumption moves it at all.")
            elif not material:
                out.append(f"- **{words}, {policy}** ({span}): practically the same whatever the "
                           f"assumptions (a spread under {100 * MATERIAL:g} % of its mean); the "
                           "indices below share out a variance too small to matter.")
            elif mv:
                named = ", ".join(f"`{k}` (ST {st:.2f} ± {h:.2f})" for k, st, h in mv)
                out.append(f"- **{words}, {policy}** ({span}): moved by {named}.")
            else:
                out.append(f"- **{words}, {policy}** ({span}): no key's total index is surely "
                           f"above {MOVES:g}; within these ranges it does not depend on them.")
    if ADVANTAGE in points.columns:
        out += _conclusion(study, sobol, points)
    return out


def _conclusion(study: Study, sobol: Any, points: Any) -> list[str]:
    """Whether any point reverses the thesis's conclusion, and what the advantage depends on."""
    adv = points[ADVANTAGE]
    length = RunLength.of(study.scenario({}).run)
    of = f"of {length.number}" if length.unit == "part" else f"per {length.run}"  # parts of 500
    n_bad = int((adv <= 0).sum())
    fixed = study.scenario({"controller.policy": "non-adaptive"}).controller
    cycle = fixed.ideal_cycle_s if fixed.ideal_cycle_s is not None else fixed.nominal_cycle_s
    claim = ("the adaptive robot delivers more parts than the fixed-cycle one"
             + (f" at {cycle:g} s" if cycle is not None else ""))
    if n_bad:
        worst = points.loc[adv.idxmin()]
        keys = [c for c in points.columns if c not in ("design", ADVANTAGE) and "/" not in c]
        base = {p.key: study_value(study, p.key) for p in study.params}
        at = ", ".join(f"{k} = {worst[k]:.4g}" for k in keys if worst[k] == worst[k]
                       and not abs(worst[k] - base[k]) <= 1e-9 * max(1, abs(base[k])))
        return [f"- **The thesis's conclusion ({claim}) is reversed** at {n_bad} of {len(points)} "
                f"points: the fixed-cycle robot delivers as many or more (worst {adv.min():.1f} "
                f"parts {of}, at {worst['design']} point {int(adv.idxmin())}: "
                f"{at or 'the base values'})."]
    if adv.min() == adv.max():
        size = (f"the advantage is {adv.min():.1f} parts {of} at every point: no "
                "assumption in its range changes it")
    else:
        size = (f"the advantage is {adv.min():.1f} to {adv.max():.1f} parts {of} "
                f"(mean {adv.mean():.1f})")
    out = [f"- **The thesis's conclusion holds** ({claim}) at every one of the {len(points)} "
           f"points, each assumption anywhere in its plausible range: {size}. None of them, alone or "
           "together within these ranges, reversed it at any point evaluated."]
    mv = movers(sobol, "both", ADVANTAGE)
    if mv:
        out.append("- The advantage's size depends most on " + ", ".join(
            f"`{k}` (ST {st:.2f} ± {h:.2f})" for k, st, h in mv) + ".")
    return out


def negative_indices(sobol: Any) -> tuple[int, int, tuple[str, float, float] | None]:
    """The indices (S1 and ST) estimated below 0: how many, how many of them have an interval
    that covers 0, and the lowest as (index, estimate, half-width); None if there are none.

    A share of a variance is never negative; Saltelli's and Jansen's estimators are differences
    of sample means, so a key with no effect gets estimates scattered around 0, some below it.
    One whose interval covers 0 is that noise, and reads as 0."""
    found: list[tuple[str, float, float]] = []
    for index in ("S1", "ST"):
        below = sobol[sobol[index] < 0]
        found += [(index, float(v), float(h)) for v, h in zip(below[index], below[f"{index}_ci95"])]
    if not found:
        return 0, 0, None
    covered = sum(1 for _, v, h in found if v + h >= 0)
    return len(found), covered, min(found, key=lambda f: f[1])


def negative_note(sobol: Any) -> list[str]:
    """What a negative index means, if the table has one: sampling noise around 0."""
    n, covered, lowest = negative_indices(sobol)
    if lowest is None:
        return []
    index, v, h = lowest
    out = [f"{n} of the indices below are estimated below 0 (the lowest, {index} "
           f"{v:.3f} ± {h:.3f}). An index is a share of a variance and cannot be negative: "
           "such an estimate is sampling noise around 0 (the key moves the measure little or "
           "not at all)"]
    if covered == n:
        out[0] += ", and each one's interval covers 0: read them as 0."
    else:
        out[0] += (f"; {n - covered} of them have intervals that stop short of 0: too few "
                   "samples to say more; more `sobol.samples` would narrow them.")
    return out + [""]


def _widest(sobol: Any) -> float:
    moving = sobol[sobol["ST"] > 0]
    return float(moving["ST_ci95"].max()) if len(moving) else 0.0


def study_value(study: Study, key: str) -> float:
    """A key's value in the study's base scenario (with ``set``)."""
    import re

    m = re.match(r"^(.*)\[(\d+)\]$", key)
    s = study.scenario({})
    v = s.get(m[1])[int(m[2])] if m else s.get(key)
    return float("nan") if v is None else float(v)  # None: derived (belts.input_length_in)


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
             f"intervals. With this many samples a total index is known to ±"
             f"{_widest(sobol):.2f} at worst (the widest half-width of a key that moves its "
             "measure at all): enough to tell a key that matters from one that does not, not to "
             "rank close ones; quadrupling the samples would halve it.",
             f"- Every point runs {', '.join(policies)} on the same {s.replications} "
             f"replication streams of {RunLength.of(study.scenario({}).run)} (common random numbers), "
             "so a measure is a deterministic function of the keys and an index is the keys' "
             "share, not the draws'.",
             "", "## Sobol indices", "", "![sensitivity](sensitivity.png)", "",
             *negative_note(sobol),
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
