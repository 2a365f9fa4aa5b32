"""The layout study: buffer against brains (``make layout``; issue 32, docs/layout.md).

From the replications of ``scenarios/layout_study.yaml`` (the fixed-cycle robot with 0, 1, 2, 3
and 5 places of buffer, the adaptive robot with 0 and 1, and two fixed-cycle robots one behind
the other, on the same parts, across arrival means and spreads) this writes, as one set,

- ``layout.csv``: one row per (spread, mean, layout): parts lost, the share of the parts set
  down within the spacing tolerance and parts/hr, means with 95 % t intervals over the
  replications;
- ``layout.png``: parts lost against the places of buffer, per arrival point, with the
  adaptive robot's and the two robots' losses beside them;
- ``README.md``: a reading generated from the numbers: how many places of buffer buy what the
  adaptive controller buys, and where a second robot pays.

With the sweep file as a third argument and a ``costs:`` section in its scenarios, the table
gains each layout's money (:mod:`cell.reporting.money_reading`: per 500-part run, the good
parts, hours, downtime, the options per hour, a robot and a buffer place counted per station as
:mod:`cell.sim.run_cost` counts them, and the cost) and the README a money reading: per arrival
point, the cheapest layout to each of :data:`LOSS_TARGETS`.  Without it, nothing changes.

``python -m cell.reporting.maps.layout_study REPLICATIONS.csv DIR [SWEEP.yaml]``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, cast

import numpy as np
import pandas as pd

from cell.experiments.stats import summarise
from cell.reporting import money_reading
from cell.reporting.maps import map_report

KEYS = ("arrivals.cv", "arrivals.mean_s")
#: The robot's fastest cycle (s) the study's means are loads of (scenarios/layout_study.yaml).
FASTEST_S = 18.0841
#: The fixed-cycle robot's places in the study.
PLACES = (0, 1, 2, 3, 5)
#: The layouts of the study, as the table names them.
FIXED = tuple(f"fixed, {n} places" for n in PLACES)
LAYOUTS = (*FIXED, "adaptive, 0 places", "adaptive, 1 places", "two fixed robots")
#: The money reading's loss targets, parts lost per 500-part run (``math.inf``: none).
LOSS_TARGETS = (5.0, 25.0, 50.0, math.inf)
#: The money's columns layout.csv gains with ``costs:`` (``lost`` is the table's own).
MONEY_COLUMNS = tuple(c for c in (*money_reading.INPUTS, *money_reading.OUTPUTS) if c != "lost")


def _layout(row: pd.Series) -> str | None:
    """The study's name of a replication's layout (None: a combination it does not read)."""
    places = int(row["buffer.places"])
    if row["policy"] == "adaptive":
        return f"adaptive, {places} places"
    if row.get("stations.name") == "two":
        return "two fixed robots" if places == 0 else None
    return f"fixed, {places} places"


def table(reps: pd.DataFrame) -> pd.DataFrame:
    """One row per (spread, mean, layout) with means and 95 % half-widths."""
    reps = reps.assign(layout=reps.apply(_layout, axis=1)).dropna(subset=["layout"])
    reps = reps.assign(spacing_kept=1.0 - reps["spacing_outside_tol"] / reps["parts_delivered"])
    rows = []
    for key, runs in reps.groupby([*KEYS, "layout"], sort=True):
        cv, mean, layout = cast(tuple[float, float, str], key)
        row: dict[str, object] = {"cv": float(cv), "mean_s": float(mean),
                                  "load": round(float(mean) / FASTEST_S, 2), "layout": layout}
        for column, name in (("parts_missed", "lost"), ("spacing_kept", "spacing_kept"),
                             ("parts_per_hr_wallclock", "parts_per_hr")):
            s = summarise(runs[column].to_numpy(dtype=float))
            row[name], row[f"{name}_hw"] = s["mean"], (s["ci_high"] - s["ci_low"]) / 2.0
        row["replications"] = len(runs)
        rows.append(row)
    t = pd.DataFrame(rows)
    t["layout"] = pd.Categorical(t["layout"], LAYOUTS, ordered=True)
    return t.sort_values(["cv", "mean_s", "layout"]).reset_index(drop=True)


def matches(t: pd.DataFrame) -> pd.DataFrame:
    """Per arrival point: the adaptive robot's loss, the fewest places with which the fixed
    robot loses no more (NaN: none of the study's), and the two robots' loss beside the
    adaptive robot's and the fixed robot's with 5 places."""
    rows = []
    for key, point in t.groupby(["cv", "mean_s"], sort=True):
        cv, mean = cast(tuple[float, float], key)
        lost = dict(zip(point["layout"].astype(str), point["lost"]))
        adaptive = lost["adaptive, 0 places"]
        enough = [n for n, name in zip(PLACES, FIXED) if lost[name] <= adaptive]
        rows.append({"cv": cv, "mean_s": mean, "load": round(mean / FASTEST_S, 2),
                     "adaptive_lost": adaptive, "places_to_match": min(enough) if enough
                     else np.nan, "two_lost": lost["two fixed robots"],
                     "fixed5_lost": lost["fixed, 5 places"]})
    return pd.DataFrame(rows)


def headline(m: pd.DataFrame) -> str:
    """The study's answer in one sentence (the README quotes it)."""
    found = m["places_to_match"].dropna()
    n = len(m)
    places = "no number of places up to 5" if found.empty else (
        f"{int(found.min())} to {int(found.max())} places (median {found.median():g})"
        if found.min() != found.max() else f"{int(found.min())} places")
    beat_adaptive = int((m["two_lost"] < m["adaptive_lost"]).sum())
    beat_buffer = int((m["two_lost"] < m["fixed5_lost"]).sum())
    return (f"A buffer buys what the adaptive controller buys: the fixed-cycle robot needs "
            f"{places} to lose no more parts than the adaptive robot, at {len(found)} of {n} "
            f"arrival points; a second fixed-cycle robot loses fewer parts than the adaptive "
            f"robot at {beat_adaptive} of {n} and than the fixed robot with 5 places at "
            f"{beat_buffer} of {n}.")


def reading(t: pd.DataFrame) -> list[str]:
    """The README's sentences, each from the numbers."""
    m = matches(t)
    kept = t.groupby("layout", observed=True)["spacing_kept"].mean()
    lines = [headline(m), "",
             f"Spacing kept (the share of parts set down within the tolerance, mean over the "
             f"arrival points): the adaptive robot {kept['adaptive, 0 places']:.3f}, the "
             f"fixed robot {kept['fixed, 0 places']:.3f} with no buffer and "
             f"{kept['fixed, 5 places']:.3f} with 5 places, two fixed robots "
             f"{kept['two fixed robots']:.3f}: a buffer and a second robot buy parts, the "
             "adaptive controller's output belt buys the spacing.", ""]
    for _, r in m.iterrows():
        n_places = r["places_to_match"]
        match = "none of 0-5 places" if np.isnan(n_places) else \
            f"{int(n_places)} place{'' if n_places == 1 else 's'}"
        lines.append(f"- cv {r['cv']:g}, load {r['load']:g}: the adaptive robot loses "
                     f"{r['adaptive_lost']:.1f} parts of 500; the fixed robot matches it with "
                     f"{match}; two fixed robots lose {r['two_lost']:.1f} (the fixed robot "
                     f"with 5 places {r['fixed5_lost']:.1f}).")
    return lines


def figure(t: pd.DataFrame) -> bytes:
    """Parts lost against places, one panel per spread, one line per mean."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cvs = sorted(t["cv"].unique())
    fig, axes = plt.subplots(1, len(cvs), figsize=(4.2 * len(cvs), 3.6), sharey=True)
    for ax, cv in zip(np.atleast_1d(axes), cvs):
        for mean, point in t[t["cv"] == cv].groupby("mean_s"):
            lost = dict(zip(point["layout"].astype(str), point["lost"]))
            line, = ax.plot(PLACES, [lost[name] for name in FIXED], marker="o",
                            label=f"load {mean / FASTEST_S:.2f}")
            colour = line.get_color()
            ax.axhline(lost["adaptive, 0 places"], color=colour, ls="--", lw=1)
            ax.plot([0], [lost["two fixed robots"]], marker="s", color=colour, ls="none")
        ax.set_title(f"cv {cv:g}")
        ax.set_xlabel("places of buffer (fixed-cycle robot)")
    axes_list = list(np.atleast_1d(axes))
    axes_list[0].set_ylabel("parts lost of 500")
    axes_list[-1].legend(title="dashed: adaptive, 0 places; square: two robots", fontsize=7,
                         title_fontsize=7)
    fig.tight_layout()
    png = map_report.png_bytes(fig)
    plt.close(fig)
    return png


def markdown(t: pd.DataFrame, source: str) -> str:
    lines = ["# Buffer against brains", "",
             f"Generated by `make layout` from `{source}` (scenarios/layout_study.yaml): the "
             "fixed-cycle robot with 0, 1, 2, 3 and 5 places of buffer at B, the adaptive robot "
             "with 0 and 1, and two fixed-cycle robots one behind the other, on the same parts "
             "(common random numbers), gamma inter-arrival times at three spreads and three "
             "means (loads of the robot's fastest cycle). Parts lost are of 500 a run; the "
             "table is `layout.csv`, the figure `layout.png` (docs/layout.md). As in the stress "
             "map, the fixed-cycle robot runs at each point's mean inter-arrival time, so its "
             "losses depend on the spread alone (its three lines in each panel lie on one "
             "another).", "",
             *reading(t), "", "![parts lost](layout.png)", ""]
    return "\n".join(lines)


def money(t: pd.DataFrame, reps: pd.DataFrame, sweep: Any) -> pd.DataFrame:
    """``t`` with each layout's money at each arrival point (:data:`MONEY_COLUMNS`;
    :func:`cell.reporting.money_reading.priced`, per 500-part run), from its runs and its
    point's scenario (a second robot's options counted as a station's)."""
    if reps["parts_scrapped"].sum() > 0:  # the table's lost counts ridden-off parts only
        raise ValueError("the layout study's money needs runs without scrapped parts")
    scenarios = {(p.policy, p.index): p.scenario for p in sweep.points}
    reps = reps.assign(layout=reps.apply(_layout, axis=1)).dropna(subset=["layout"])
    rows = []
    for key, runs in reps.groupby([*KEYS, "layout"], sort=True):
        cv, mean, name = cast(tuple[float, float, str], key)
        policy, point = str(runs["policy"].iloc[0]), int(runs["point"].iloc[0])
        rows.append({"cv": float(cv), "mean_s": float(mean), "layout": name,
                     **money_reading.run_inputs(runs, scenarios[(policy, point)])})
    priced = money_reading.priced(pd.DataFrame(rows), sweep.points[0].scenario.costs)
    out = t.assign(layout=t["layout"].astype(str)).merge(
        priced[["cv", "mean_s", "layout", *MONEY_COLUMNS]], on=["cv", "mean_s", "layout"],
        how="left", validate="one_to_one")
    out["layout"] = pd.Categorical(out["layout"], LAYOUTS, ordered=True)
    return out


def money_lines(t: pd.DataFrame, costs: Any) -> list[str]:
    """The money reading: per arrival point, the cheapest layout to each loss target."""
    o = costs.options_per_h
    lines = ["## Money", "",
             f"With the study's `costs:` (a part lost {costs.part_value:g}, a robot "
             f"{o.robot:g} an hour, its sensor {o.sensor:g}, a place of buffer "
             f"{o.buffer_place:g}, the adaptive controller {o.adaptive_controller:g}; "
             "docs/usage.md, \"Energy and cost\"), each layout's cost per 500-part run is its "
             "parts lost × their value + its hours × the options it has (two robots: two "
             "robots and two sensors); `layout.csv` has each term.", ""]
    for key, point in t.groupby(["cv", "mean_s"], sort=True):
        cv, mean = cast(tuple[float, float], key)
        options = point.assign(layout=point["layout"].astype(str)).reset_index(drop=True)
        lines += [f"**cv {cv:g}, load {mean / FASTEST_S:.2f}.** " + " ".join(
            money_reading.sentences(options, LOSS_TARGETS, "layout", "per 500 parts")), ""]
    return lines


def write(replications: str | Path, out_dir: str | Path, sweep_file: str | Path | None = None
          ) -> Path:
    map_report.check(out_dir, "layout")
    reps = pd.read_csv(replications)
    t = table(reps)
    text = markdown(t, str(replications))
    if sweep_file is not None:
        from cell.experiments.sweep.spec import load_sweep

        sweep = load_sweep(sweep_file)
        costs = sweep.points[0].scenario.costs
        if costs is not None:
            t = money(t, reps, sweep)
            text = text + "\n" + "\n".join(money_lines(t, costs)).rstrip() + "\n"
    return map_report.write_set(out_dir, "layout", t, figure(t), text)


if __name__ == "__main__":  # pragma: no cover
    map_report.command_line("cell.reporting.maps.layout_study", write, 2, optional=1)
