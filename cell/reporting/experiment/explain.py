"""What the Reading of ``report.md`` says that its tables do not: the largest effects and
where a comparison changes from point to point (an interaction), where a measure does not
move and why, what costs each point its parts (the ``limit_*`` counts, and the robot's
state fractions when the summary has them), and which limit follows a trend in the
parts lost.  All drawn from ``summary.csv`` and ``differences.csv``.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import numpy as np
import pandas as pd

from cell.experiments.sweep import Sweep
from cell.experiments.sweep.columns import NAME_SUFFIX
from cell.reporting.experiment.compact import comparison_name, load_column
from cell.reporting.experiment.reading import scatter, show, where
from cell.reporting.formatting import Headline, decimals, half_width, number, plus_minus, too_few

#: The counts of :data:`cell.sim.records.LIMIT_COUNTS` as the Reading names them.
LIMIT_WORDS = {
    "limit_input_floor": "picks at the input belt's floor (the part after each let go)",
    "limit_input_ceiling": "input belt at its ceiling (robot waited)",
    "limit_input_tracking": "input belt held to the tracking limit",
    "limit_output_floor": "output belt at its floor (spacing off)",
    "limit_output_ceiling": "output belt at its ceiling (spacing off)",
    "limit_r2_peak": "R II at the motors' peak",
    "limit_r4_peak": "R IV at the base's peak rate",
    "parts_held": "parts held at the feeder",
}
#: OEE (ISO 22400-2) and the losses that make most of 1 − availability, shown when the summary
#: has them.
STATE_COLUMNS = {"availability": "availability", "loss_starved": "starved",
                 "loss_downtime": "down", "oee": "OEE"}
#: A trend in the parts lost is put down to a limit whose counts follow it this closely (|r|).
FOLLOWS = 0.8


def _means(summary: pd.DataFrame, measure: str, policy: str) -> pd.DataFrame:
    return summary[(summary["measure"] == measure) & (summary["policy"] == policy)]


def _at(row: dict, cols: Sequence[str]) -> str:
    at = where(row, cols)
    return f" at {at}" if at else ""


def _shown(d: dict) -> str:
    if not float(d["sd"]) > 0:
        return f"{float(d['mean']):+.6g}"
    return plus_minus(float(d["mean"]), half_width(d), signed=True)


def effects(h: Headline, differences: pd.DataFrame, cols: Sequence[str],
            policies: Sequence[str]) -> list[str]:
    """Each comparison's largest difference, and its smallest when the two intervals do not
    overlap: the comparison depends on the point (an interaction with the keys varied)."""
    out = []
    rows = differences[differences["measure"] == h.column]
    for (a, b), group in rows.groupby(["policy", "versus"], sort=False):
        every = group.to_dict("records")
        recs = [r for r in every if math.isfinite(float(r["mean"]))]
        if not recs:  # no replication gives the measure for both (runs too short)
            what = h.title if h.title[1:2].isupper() else h.title[:1].lower() + h.title[1:]
            n = max(int(r["n"]) for r in every)
            out.append(f"{comparison_name(str(a), str(b), policies, every[0], cols)} not "
                       f"compared, {too_few(n, what)}")
            continue
        name = comparison_name(str(a), str(b), policies, recs[0], cols)
        order = sorted(recs, key=lambda r: -abs(float(r["mean"])))
        big, small = order[0], order[-1]
        if all(float(r["mean"]) == 0.0 and not float(r["sd"]) > 0 for r in recs):
            out.append(f"{name} 0 at every point")
        elif len(recs) == 1:
            out.append(f"{name} {_shown(big)}{_at(big, cols)}")
        elif _apart(big, small):
            out.append(f"{name} from {_shown(small)} ({_values(small, cols)}) to {_shown(big)} "
                       f"({_values(big, cols)})")
        else:
            out.append(f"{name} {_shown(big)} at most ({_values(big, cols)}), the same within "
                       "its intervals at every point")
    if any(" from " in t for t in out):
        out[-1] += " (a comparison that changes from point to point: an interaction)"
    return out


def _values(row: dict, cols: Sequence[str]) -> str:
    return ", ".join(show(row[c]) for c in cols) or "the point"


def _apart(x: dict, y: dict) -> bool:
    lo = [float(x["ci_low"]), float(y["ci_low"])]
    hi = [float(x["ci_high"]), float(y["ci_high"])]
    if not all(math.isfinite(v) for v in lo + hi):
        return float(x["mean"]) != float(y["mean"])
    return max(lo) > min(hi)


def unmoved(h: Headline, summary: pd.DataFrame, policies: Sequence[str]) -> list[str]:
    """Policies whose mean of ``h`` stays within its intervals at every point, and why."""
    out = []
    for p in policies:
        rows = _means(summary, h.column, p)
        mean = rows["mean"].to_numpy(float)
        if len(rows) < 2 or not np.isfinite(mean).all():
            continue
        if mean.max() - mean.min() > STILL * max(1.0, float(abs(mean).max())):
            continue
        out.append(f"{p} does not move ({number(float(mean[0]))} at all {len(rows)} points): "
                   f"{_why(summary, p, h.column)}")
    return out


#: A mean that changes by less than this (relative) from point to point does not move.
STILL = 1e-9


def _why(summary: pd.DataFrame, policy: str, measure: str) -> str:
    cycle = _means(summary, "nominal_cycle_s", policy)["mean"].to_numpy(float)
    mean = _means(summary, "mean_interarrival_s", policy)["mean"].to_numpy(float)
    lost = _means(summary, "parts_missed", policy)["mean"].to_numpy(float)
    if measure in ("parts_delivered", "parts_missed") and len(lost) and np.all(lost == 0):
        return "it loses no part at any point"
    if len(cycle) == len(mean) > 1 and np.ptp(mean) > 0 and np.allclose(cycle, mean, rtol=1e-9):
        return ("its cycle follows each point's mean inter-arrival time (controller.nominal_cycle_s "
                f"left out: {mean.min():.4g} to {mean.max():.4g} s), so it keeps pace with "
                "the arrivals in the same proportion")
    if len(lost) and np.all(lost == 0):
        return "it loses no part at any point"
    return "the keys varied leave it within its intervals"


def trend(h: Headline, summary: pd.DataFrame, cols: Sequence[str]) -> list[str]:
    """With no comparison of ``h`` to say its effect (one policy, no ``baseline:``), along a
    single numeric key: each policy's mean at the first and last values that have one (a
    run too short for a rate has none), when they differ as shown."""
    if len(cols) != 1 or cols[0].endswith(NAME_SUFFIX):
        return []
    col, out = cols[0], []
    for policy, group in summary[summary["measure"] == h.column].groupby("policy", sort=False):
        if pd.to_numeric(group[col], errors="coerce").isna().any():
            continue
        group = group[np.isfinite(group["mean"].to_numpy(dtype=float))]
        if len(group) < 2:
            continue
        first, last = group.iloc[0], group.iloc[-1]
        a, b = _ends(first, last)
        if a != b:
            out.append(f"{str(policy).capitalize()} goes from {a} at {col} = "
                       f"{show(first[col])} to {b} at {show(last[col])}.")
    return out


def _ends(first: pd.Series, last: pd.Series) -> tuple[str, str]:
    """Two summary rows' means to the precision of the wider interval (of the one there is,
    when an end has a single replication); as plain figures when neither varies."""
    if float(first["sd"]) == 0.0 and float(last["sd"]) == 0.0:
        return number(float(first["mean"])), number(float(last["mean"]))
    halves = [w for w in (half_width(first), half_width(last)) if math.isfinite(w)]
    d = decimals(max(halves, default=math.nan))
    return f"{float(first['mean']):.{d}f}", f"{float(last['mean']):.{d}f}"


def costs(summary: pd.DataFrame, cols: Sequence[str], policies: Sequence[str]) -> list[str]:
    """A line per point: each policy's parts lost per run, how many of them after picks at
    the input belt's floor (the rest let go while the robot was busy), its spacings off
    and how many with an output belt held at a bound, and its state fractions if the
    summary has them."""
    lost = summary[summary["measure"] == "parts_missed"]
    have = set(summary["measure"])
    states = [c for c in STATE_COLUMNS if c in have]
    loaded = load_column(summary)
    lines: dict[str, list[str]] = {}
    for r in lost.to_dict("records"):
        key = str({c: r[c] for c in cols})
        same = summary[summary["policy"] == r["policy"]]
        for c in cols:
            same = same[same[c].astype(str) == str(r[c])]
        mean = dict(zip(same["measure"], same["mean"].astype(float), strict=False))
        if key not in lines:
            load = mean.get(loaded, math.nan) if loaded else math.nan
            lines[key] = [(where(r, cols) or "the point")
                          + (f" (load {load:.3f})" if math.isfinite(load) else "") + ":"]
        lines[key].append(_cost(str(r["policy"]), mean) + "".join(
            f", {STATE_COLUMNS[c]} {mean[c]:.3f}" for c in states
            if math.isfinite(mean.get(c, math.nan))))
    return [" ".join([parts[0], "; ".join(parts[1:])]) for parts in lines.values()]


def _cost(policy: str, mean: dict[str, float]) -> str:
    """``adaptive loses 4.15 (3.9 after picks at the input belt's floor), spacing off 3.5
    (3.4 with the output belt at a bound)``."""
    lost, floor = mean.get("parts_missed", 0.0), mean.get("limit_input_floor", 0.0)
    off = mean.get("spacing_outside_tol", 0.0)
    bound = mean.get("limit_output_floor", 0.0) + mean.get("limit_output_ceiling", 0.0)
    text = f"{policy} loses {lost:.3g}" if lost > 0 else f"{policy} loses none"
    if lost > 0:
        text += (" (all after picks at the input belt's floor)" if floor >= lost else
                 f" ({floor:.3g} after picks at the input belt's floor, the rest while the "
                 "robot was busy)") if floor > 0 else " (let go while the robot was busy)"
    if off > 0:
        text += f", spacing off {off:.3g}" + (f" (output belt at a bound {bound:.3g} times)"
                                              if bound > 0 else "")
    return text


def causes(summary: pd.DataFrame, cols: Sequence[str], policies: Sequence[str]) -> list[str]:
    """For each policy whose parts lost change across three or more points: the limit whose
    counts follow them most closely (Pearson r at least :data:`FOLLOWS`), and the load's
    direction beside it."""
    out = []
    have = set(summary["measure"])
    loaded = load_column(summary)
    for p in policies:
        lost = _means(summary, "parts_missed", p)
        m = lost["mean"].to_numpy(float)
        if len(m) < 3 or not np.isfinite(m).all() or np.ptp(m) == 0:
            continue
        best: tuple[float, str] | None = None
        for c in LIMIT_WORDS:
            x = _means(summary, c, p)["mean"].to_numpy(float) if c in have else np.array([])
            if len(x) != len(m) or np.ptp(x) == 0:
                continue
            r = float(np.corrcoef(x, m)[0, 1])
            if r >= FOLLOWS and (best is None or r > best[0]):
                best = (r, c)
        recs = lost.to_dict("records")
        lo, hi = recs[int(np.argmin(m))], recs[int(np.argmax(m))]
        text = (f"{p}'s parts lost go from {float(lo['mean']):.3g}{_at(lo, cols)} to "
                f"{float(hi['mean']):.3g}{_at(hi, cols)}")
        if loaded in have:
            load = _means(summary, str(loaded), p)["mean"].to_numpy(float)
            if len(load) == len(m) and np.ptp(load) > 0:
                r_load = float(np.corrcoef(load, m)[0, 1])
                text += "; with the load" if r_load > 0 else "; against the load" \
                    if r_load < 0 else ""
        if best is not None:
            text += f"; they follow {LIMIT_WORDS[best[1]]} (r = {best[0]:.2f})"
        else:
            text += "; no limit count follows them"
        out.append(text)
    return out


def reading(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
            cols: Sequence[str], present: Sequence[Headline],
            whole: Collection[str] = ()) -> list[str]:
    """What the tables do not say (:mod:`cell.reporting.experiment.explain`): per headline
    measure its largest effects (with no comparison of it, each policy's trend along the
    key), where they depend on the point, where a policy does not
    move and why, and where single runs scatter so widely that the mean says little; then
    what costs each point its parts, and which limit follows a trend in the parts lost.
    ``whole``: the measures that count things (shown as whole numbers)."""
    policies = sweep.policies
    out: list[str] = []
    if differences.empty:
        out.append("No paired differences: the sweep runs one policy and names no "
                   "`baseline:`; name a point there to compare the others with it.")
    for h in present:
        said = effects(h, differences, cols, policies)
        text = ["; ".join(said) + "." if said else ""]
        text += [s[:1].upper() + s[1:] + "." for s in unmoved(h, summary, policies)]
        text += [] if said else trend(h, summary, cols)
        text += scatter(h, summary, cols, h.column in whole)
        text = [t for t in text if t]
        if text:
            out.append(f"- **{h.title}.** " + " ".join(text))
    where_lost = costs(summary, cols, policies)
    if where_lost:
        out.append("")
        out.append("**What costs the parts, per point** (means per run):")
        out += [f"- {line}" for line in where_lost]
    trends = causes(summary, cols, policies)
    if trends:
        out.append("")
        out += [f"- {t[:1].upper() + t[1:]}." for t in trends]
    return out
