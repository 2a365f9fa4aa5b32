"""The sensor-quality map: the adaptive robot against its look-ahead sensor (``make sensor``).

From the replications of ``scenarios/sensor.yaml`` (the adaptive robot with the ideal
look-ahead and with a physical sensor made worse one quality at a time, the fixed-cycle
robot once, on the thesis's arrivals and on widely spread ones) this writes, as one set,

- ``sensor.csv``: one row per (arrivals, sensor): parts delivered, lost and off spacing,
  parts/hr, the share of the bound delivered, and the adaptive robot's paired advantage
  in parts delivered over the fixed-cycle robot on the same draws;
- ``sensor.png``: that advantage against each quality of the sensor;
- ``README.md``: a reading generated from the numbers: how good the sensor must be for
  the adaptive robot to keep its advantage, and how much the ideal look-ahead overstates it.

With the sweep file as a third argument and a ``costs:`` section in its scenarios, the
table gains each option's money (:mod:`cell.reporting.money_reading`: per 500-part run, the
parts lost, good parts, hours, downtime, options per hour and cost) and the README a money
reading: the cheapest way to each of :data:`LOSS_TARGETS`.  Without it, nothing changes.

``python -m cell.reporting.maps.sensor_map REPLICATIONS.csv DIR [SWEEP.yaml]``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from cell.experiments.stats import paired_difference, summarise
from cell.reporting import money_reading
from cell.reporting.maps import map_report

FILES = map_report.files("sensor")
#: A sensor's qualities as the sweep names them (``range_70``, ``noise_1``, ...): the column,
#: the figure's axis label and how the reading words a value.
AXES = {"range": ("range_in", "range, in before B", "a range of {:.4g} in"),
        "noise": ("noise_sd_in", "error sd, in", "an error of sd {:g} in"),
        "latency": ("latency_s", "latency, s", "a latency of {:g} s"),
        "miss": ("miss_probability", "share of parts missed", "{:.0%} of parts missed")}
AXIS_COLUMNS = tuple(column for column, _, _ in AXES.values())
#: The money reading's loss targets, parts lost per 500-part run (``math.inf``: none).
LOSS_TARGETS = (1.0, 5.0, 25.0, math.inf)
#: "Keeps its advantage": at least this share of the perfect drop-point sensor's paired
#: advantage over the fixed-cycle robot.
KEEP = 0.9


def _axis(name: str) -> str:
    return name.split("_", 1)[0] if "_" in name else name


def _settings(g: pd.DataFrame, drop_point_in: float) -> dict[str, float]:
    """A sensor's four qualities as the sweep set them (the reference's where it did not)."""
    def given(column: str, default: float) -> float:
        value = g[column].iloc[0] if column in g else math.nan
        return default if pd.isna(value) else float(value)

    return {"range_in": given("sensor.position_in", drop_point_in),
            "noise_sd_in": given("sensor.noise_sd_in", 0.0),
            "latency_s": given("sensor.latency_s", 0.0),
            "miss_probability": given("sensor.miss_probability", 0.0)}


def table(reps: pd.DataFrame, drop_point_in: float) -> pd.DataFrame:
    """One row per (arrivals, sensor) of the adaptive robot, and one per arrivals of the fixed."""
    rows = []
    for arrivals, runs in reps.groupby("arrivals.name", sort=False):
        fixed = runs[runs["policy"] == "non-adaptive"].sort_values("replication")
        parts = [("fixed cycle", "non-adaptive", fixed)]
        for name, g in runs[runs["policy"] == "adaptive"].groupby("sensor.name", sort=False):
            parts.append((str(name), "adaptive", g.sort_values("replication")))
        for name, policy, g in parts:
            delivered = g["parts_delivered"].to_numpy(float)
            diff = paired_difference(delivered, fixed["parts_delivered"].to_numpy(float))
            per_hr = summarise(g["parts_per_hr_wallclock"].to_numpy(float))
            row: dict[str, Any] = {
                "arrivals": arrivals, "sensor": name, "policy": policy,
                "axis": _axis(name) if policy == "adaptive" else "",
                **(_settings(g, drop_point_in) if policy == "adaptive" and name != "ideal"
                   else dict.fromkeys(AXIS_COLUMNS, math.nan)),
                "n": len(g), "parts_delivered": delivered.mean(),
                "parts_lost": float(g["parts_missed"].mean()),
                "spacing_off_pct": 100.0 * float(g["spacing_outside_tol"].sum()) /
                max(float(g["parts_delivered"].sum()), 1.0),
                "parts_per_hr": per_hr["mean"], "parts_per_hr_ci_low": per_hr["ci_low"],
                "parts_per_hr_ci_high": per_hr["ci_high"],
                "parts_bound": float(g["parts_bound"].mean()),
                "delivered_vs_bound": float(g["parts_delivered"].sum() / g["parts_bound"].sum()),
                "delivered_vs_fixed": diff["mean"], "delivered_vs_fixed_ci_low": diff["ci_low"],
                "delivered_vs_fixed_ci_high": diff["ci_high"]}
            rows.append(row)
    t = pd.DataFrame(rows)
    ref: dict[str, float] = dict(zip(t[t["sensor"] == "reference"]["arrivals"],
                                     t[t["sensor"] == "reference"]["delivered_vs_fixed"]))
    t["advantage_kept"] = [a / ref[str(where)] if policy == "adaptive" and ref[str(where)] > 0
                           else math.nan for a, where, policy in
                           zip(t["delivered_vs_fixed"], t["arrivals"], t["policy"])]
    return t


def _along(t: pd.DataFrame, arrivals: str, axis: str) -> pd.DataFrame:
    """One axis's settings with the reference sensor, from the best sensor to the poorest."""
    sub = t[(t["arrivals"] == arrivals) & ((t["axis"] == axis) | (t["sensor"] == "reference"))]
    sub = sub.sort_values(AXES[axis][0], ascending=axis != "range")
    return sub.assign(value=sub[AXES[axis][0]])


def _first(sub: pd.DataFrame, failed: pd.Series) -> float | None:
    """The value of the first setting (best first) at which ``failed`` holds."""
    hit = sub[failed.loc[sub.index]]
    return None if hit.empty else float(hit["value"].iloc[0])


def _needs(t: pd.DataFrame, arrivals: str) -> tuple[list[str], list[str]]:
    """Per axis: the poorest setting that keeps the advantage (and the first that does not),
    and the first at which the advantage is gone (paired interval reaching zero)."""
    needs, gone = [], []
    for axis, (_, _, words) in AXES.items():
        sub = _along(t, arrivals, axis)
        values, fails = sub["value"].tolist(), (sub["advantage_kept"] < KEEP).tolist()
        at = fails.index(True) if True in fails else len(values)  # the first short of KEEP
        best = words.format(values[at - 1]) if at > 0 else "no sensor tried"
        needs.append(f"{best} (not {words.format(values[at])})" if at < len(values)
                     else f"{best}, the poorest tried")
        nil = _first(sub, sub["delivered_vs_fixed_ci_low"] <= 0)
        if nil is not None:
            gone.append(words.format(nil))
    return needs, gone


def reading(t: pd.DataFrame) -> list[str]:
    """Sentences from the numbers: each arrivals' detail."""
    ad = t[t["policy"] == "adaptive"]
    out = []
    for arrivals in t["arrivals"].unique():
        here = ad[ad["arrivals"] == arrivals]
        ideal = here[here["sensor"] == "ideal"].iloc[0]
        ref = here[here["sensor"] == "reference"].iloc[0]
        fixed = t[(t["arrivals"] == arrivals) & (t["policy"] == "non-adaptive")].iloc[0]
        over = (ideal["delivered_vs_fixed"] - ref["delivered_vs_fixed"]) / \
            ref["delivered_vs_fixed"] if ref["delivered_vs_fixed"] > 0 else math.inf
        needs, gone = _needs(t, arrivals)
        out.append(
            f"**The {arrivals} arrivals.** With the ideal look-ahead the adaptive robot delivers "
            f"{ideal['delivered_vs_fixed']:.1f} parts per 500 more than the fixed-cycle robot "
            f"({ideal['parts_delivered']:.1f} against {fixed['parts_delivered']:.1f}); with a "
            f"perfect sensor at the feeder's drop point, {ref['delivered_vs_fixed']:.1f}: the "
            f"ideal look-ahead overstates the advantage by {over:.0%}. The robot keeps at least "
            f"{KEEP:.0%} of the perfect sensor's advantage with " + "; ".join(needs) + ". "
            + ("The advantage is gone (paired 95 % interval reaching zero) with "
               + ", or ".join(gone) + ". " if gone else
               "Its advantage holds with every sensor tried. ")
            + f"Parts lost per 500: {ideal['parts_lost']:.1f} with the ideal look-ahead, "
            f"{ref['parts_lost']:.1f} with the perfect sensor, up to "
            f"{here['parts_lost'].max():.1f} with the poorest; the fixed-cycle robot "
            f"{fixed['parts_lost']:.1f}. Off spacing: at most {here['spacing_off_pct'].max():.1f} "
            f"% of the adaptive robot's parts (the fixed-cycle robot, which does not steer its "
            f"belt, {fixed['spacing_off_pct']:.0f} %). Delivered against the bound: "
            f"{ideal['delivered_vs_bound']:.0%} (ideal look-ahead), "
            f"{ref['delivered_vs_bound']:.0%} (perfect sensor), "
            f"{fixed['delivered_vs_bound']:.0%} (fixed cycle).")
    return out


def headline(t: pd.DataFrame) -> str:
    """The one sentence the README quotes: the ideal look-ahead's advantage against a perfect
    physical sensor's, on each supply."""
    ad = t[t["policy"] == "adaptive"]
    parts = []
    for arrivals in t["arrivals"].unique():
        here = ad[ad["arrivals"] == arrivals]
        ideal = float(here[here["sensor"] == "ideal"]["delivered_vs_fixed"].iloc[0])
        ref = float(here[here["sensor"] == "reference"]["delivered_vs_fixed"].iloc[0])
        over = (ideal - ref) / ref if ref > 0 else math.inf
        parts.append(f"{ideal:.1f} against {ref:.1f} parts per 500 on the {arrivals} arrivals "
                     f"(the ideal look-ahead overstates it by {over:.0%})")
    return ("The adaptive robot's advantage over the fixed cycle, with the ideal look-ahead "
            "against a perfect sensor at the feeder's drop point: " + " and ".join(parts) + ".")


def figure(t: pd.DataFrame) -> bytes:
    """The paired advantage against each quality of the sensor, one line per arrivals."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(16, 4.2), dpi=90, layout="constrained")
    axes = fig.subplots(1, len(AXES))
    ad = t[t["policy"] == "adaptive"]
    for ax, (axis, (_, label, _unit)) in zip(axes, AXES.items()):
        for arrivals, colour in zip(t["arrivals"].unique(), ("tab:blue", "tab:orange")):
            sub = _along(ad, arrivals, axis)
            ax.errorbar(sub["value"], sub["delivered_vs_fixed"],
                        yerr=[sub["delivered_vs_fixed"] - sub["delivered_vs_fixed_ci_low"],
                              sub["delivered_vs_fixed_ci_high"] - sub["delivered_vs_fixed"]],
                        marker="o", color=colour, label=f"{arrivals}: sensor", capsize=2)
            ideal = ad[(ad["arrivals"] == arrivals) & (ad["sensor"] == "ideal")]
            ax.axhline(float(ideal["delivered_vs_fixed"].iloc[0]), color=colour, ls="--",
                       lw=1, label=f"{arrivals}: ideal look-ahead")
        ax.axhline(0.0, color="grey", lw=0.8)
        ax.set_xlabel(label)
        ax.set_ylabel("adaptive − fixed, parts delivered per 500")
        ax.grid(alpha=0.3)
    axes[0].invert_xaxis()
    axes[0].legend(fontsize=7)
    fig.suptitle("The adaptive robot's advantage against its sensor (scenarios/sensor.yaml; "
                 "95 % paired intervals)", fontsize=11)
    return map_report.png_bytes(fig)


def markdown(t: pd.DataFrame, source: str) -> str:
    lines = ["# The sensor-quality map: how good must the look-ahead be?", "",
             f"Generated by `python -m cell.reporting.maps.sensor_map {source} reports/sensor` (`make "
             "sensor`) from `scenarios/sensor.yaml`: the thesis's cell, 500 parts a run, 20 "
             "replications a point drawing the same parts for every sensor and for the "
             "fixed-cycle robot (common random numbers). The adaptive robot runs with the "
             "thesis's ideal look-ahead (it knows when the next part will be dropped: an "
             "idealisation, docs/model.md) and with a physical sensor: a reference sensor at the "
             "feeder's drop point that sees every part exactly and at once, and from it one "
             "quality at a time made worse (its range, the error on the position it reports, its "
             "latency, the share of parts it misses). Two supplies with the same mean, 22.59 s: "
             "the thesis's eq. 6.9 Weibull (cv 0.05) and a gamma with cv 0.75. `sensor.csv` has "
             "every figure; `sensor.png` plots the advantage.", "",
             "![the advantage against the sensor](sensor.png)", "",
             "## Headline", "", headline(t), "", "## Reading", ""]
    for sentence in reading(t):
        lines += [sentence, ""]
    lines += ["The bound (`parts_bound`, docs/model.md) counts the parts any controller could "
              "deliver from the same arrivals: each part's window at B (79 s long), picks a "
              "fastest cycle apart and far enough apart on the one belt. It takes each of these "
              "on its own, so on the spread arrivals it bounds both robots loosely "
              "(reports/benchmark: how far above the optimum it sits).", ""]
    return "\n".join(lines).rstrip() + "\n"


def drop_point(reps: pd.DataFrame) -> float:
    """The feeder's drop point of the sweep's cell (the reference sensor's range)."""
    from cell.scenario.schema import load_scenario
    from cell.sim.assembly import assemble

    del reps
    return float(assemble(load_scenario("baseline")).k.input_length)


def money(t: pd.DataFrame, reps: pd.DataFrame, sweep: Any) -> pd.DataFrame:
    """``t`` with each option's money (:func:`cell.reporting.money_reading.priced`, per
    500-part run), from its runs and its point's scenario."""
    scenarios = {(p.policy, p.index): p.scenario for p in sweep.points}
    rows = []
    for _, runs in reps.groupby(["arrivals.name", "policy", "point"], sort=False):
        policy, point = str(runs["policy"].iloc[0]), int(runs["point"].iloc[0])
        name = "fixed cycle" if policy == "non-adaptive" else str(runs["sensor.name"].iloc[0])
        rows.append({"arrivals": runs["arrivals.name"].iloc[0], "sensor": name,
                     **money_reading.run_inputs(runs, scenarios[(policy, point)])})
    priced = money_reading.priced(pd.DataFrame(rows), costs_of(sweep))
    return t.merge(priced, on=["arrivals", "sensor"], how="left", validate="one_to_one")


def run_parts(t: pd.DataFrame) -> int:
    """The parts of a run (delivered and lost, the same for every option)."""
    return int(round(float((t["good"] + t["lost"]).max())))


def costs_of(sweep: Any) -> Any:
    """The sweep's ``costs:`` (every point's, the same), or None."""
    return sweep.points[0].scenario.costs


def money_lines(t: pd.DataFrame, costs: Any) -> list[str]:
    """The money reading: per arrivals, the cheapest way to each loss target among the
    options one can buy (the ideal look-ahead is an idealisation, not one of them)."""
    parts = run_parts(t)
    lines = ["## Money", "",
             f"With the study's `costs:` (a part lost {costs.part_value:g}, the robot "
             f"{costs.options_per_h.robot:g} an hour, the adaptive controller "
             f"{costs.options_per_h.adaptive_controller:g}, the sensor "
             f"{costs.options_per_h.sensor:g}; docs/usage.md, \"Energy and cost\"), each "
             f"option's cost per {parts}-part run is its parts lost × their value + its hours × the "
             "options it has (+ its downtime, repairs and energy where it has them); `sensor.csv` has each "
             "term. Every physical sensor has the same price, so among them the cheapest is the "
             "one that loses least and keeps the pace best.", ""]
    for arrivals in t["arrivals"].unique():
        options = t[(t["arrivals"] == arrivals) & (t["sensor"] != "ideal")].reset_index(drop=True)
        fixed = options[options["sensor"] == "fixed cycle"].iloc[0]
        lines += [f"**The {arrivals} arrivals.** " + " ".join(money_reading.sentences(
            options, LOSS_TARGETS, "sensor", f"per {parts} parts")) + f" The fixed-cycle robot's "
            f"lost parts are {100 * money_reading.shares(fixed, costs)['lost parts']:.0f} % of "
            f"its cost, {fixed['cost_per_good_part']:.4f} a good part.", ""]
    return lines


def write(replications: str | Path, out_dir: str | Path, sweep_file: str | Path | None = None
          ) -> Path:
    map_report.check(out_dir, "sensor")
    reps = pd.read_csv(replications)
    t = table(reps, drop_point(reps))
    text = markdown(t, str(replications))
    if sweep_file is not None:
        from cell.experiments.sweep.spec import load_sweep

        sweep = load_sweep(sweep_file)
        if costs_of(sweep) is not None:
            t = money(t, reps, sweep)
            text = text + "\n" + "\n".join(money_lines(t, costs_of(sweep))).rstrip() + "\n"
    return map_report.write_set(out_dir, "sensor", t, figure(t), text)


if __name__ == "__main__":  # pragma: no cover
    map_report.command_line("cell.reporting.maps.sensor_map", write, 2, optional=1)
