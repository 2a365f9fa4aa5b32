"""The reliability study: throughput against downtime from motor wear (``make reliability``).

The thesis argues (§7.2) that the fixed-cycle robot, run at a shorter cycle to lose fewer
parts, "is continuously being operated at its maximum performance limits ... This will lead
to a substantially reduced mean time to failure of the robot", while the adaptive robot
asks only the rates each cycle needs.  From the replications of ``scenarios/reliability.yaml``
(both policies at Table 7.1's cycles, wear on, a year of two shifts, wear exponents 0 to 3)
this writes, as one set,

- ``reliability.csv``: one row per (exponent, policy, cycle): throughput, the robot's wear
  stops and downtime, OEE and its factors, and the motors' lives at that duty;
- ``reliability.png``: throughput against downtime as the fixed cycle shortens, the
  adaptive robot on the same axes, one panel per exponent;
- ``README.md``: the headline and a reading generated from the numbers: whether the
  argument holds, by how much, and for which exponents it holds or flips.

Downtime is given twice: as the runs had it (the robot stopped ``wear.repair_h`` at every
worn-out motor: a handful a year, so it varies run to run), and as expected from each run's
exposure (motor lives η_j = up hours / ε_j; only the worn motor is replaced, so each motor's
place is a renewal process and the robot's mean time between wear stops is MTBF =
1 / Σ_j 1 / (η_j Γ(1 + 1/β)); availability MTBF / (MTBF + repair), an alternating renewal
process).  The reading uses the expected figures, which do not depend on how the few stops
fell.

With a ``costs:`` section in the sweep's scenarios, the table gains each option's money per
year (:mod:`cell.reporting.money_reading`: parts lost, good parts, downtime, repairs, options
per hour and cost) and the README a money reading: the cheapest way to each of
:data:`LOSS_TARGETS`.  Without one, nothing changes.

``python -m cell.reporting.maps.reliability SWEEP.yaml BUILD_DIR REPORT_DIR``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cell.plumbing.output.atomic import OutputDir
from cell.reporting import money_reading
from cell.reporting.maps import map_report

FILES = map_report.files("reliability")
#: Hours of a year of two shifts (250 days × 16 h), what downtime is quoted per.
YEAR_H = 4000.0
FIXED, ADAPTIVE = "non-adaptive", "adaptive"
#: The money reading's loss targets, parts lost a year (``math.inf``: none).
LOSS_TARGETS = (1_000.0, 15_000.0, 100_000.0, float("inf"))


def wear_summary(scenario: Any, seed: np.random.SeedSequence) -> Mapping[str, Any]:
    """One replication: the run's summary row and its wear measures (cell.sim.wear)."""
    from cell.experiments.sweep.runner import assembled
    from cell.sim.simulation import simulate

    result = simulate(assembled(scenario), seed=seed, keep_parts=False, keep_belts=False)
    return {**result.summary.as_dict(), **(result.wear.measures if result.wear else {})}


def table(reps: pd.DataFrame) -> pd.DataFrame:
    """One row per (exponent, policy, cycle): means over the replications."""
    r = reps.copy()
    hours = r["wear_hours"]
    r["parts_per_h"] = r["parts_delivered"] / hours
    r["down_h_per_year"] = r["wear_down_h"] / hours * YEAR_H
    r["expected_down_h_per_year"] = (1 - r["wear_availability"]) * YEAR_H
    r["stops_per_year"] = r["wear_failures"] / hours * YEAR_H
    # OEE and its losses are each run's own (ISO 22400-2, cell.sim.oee), averaged below
    r["cycle_s"] = np.where(r["policy"] == ADAPTIVE, np.nan, r["ideal_cycle_s"])
    keep = ["parts_per_h", "parts_missed", "down_h_per_year", "expected_down_h_per_year",
            "stops_per_year", "availability", "performance", "quality", "oee",
            "loss_downtime", "loss_starved", "loss_blocked", "loss_speed", "loss_quality",
            "wear_mtbf_h",
            "wear_life_base_h", "wear_life_shoulder_h", "wear_life_elbow_h",
            "wear_life_pitch_h", "wear_life_roll_h"]
    g = r.groupby(["wear_exponent", "policy", "cycle_s"], dropna=False, sort=True)
    out = g[keep].mean().reset_index()
    out.insert(3, "replications", g.size().to_numpy())
    out["parts_missed"] = out["parts_missed"] / r["wear_hours"].mean() * YEAR_H
    out = out.rename(columns={"parts_missed": "parts_missed_per_year",
                              "wear_mtbf_h": "robot_mtbf_h"})
    order = out["policy"].map({FIXED: 0, ADAPTIVE: 1})
    out = out.assign(_o=order).sort_values(["wear_exponent", "_o", "cycle_s"],
                                           ascending=[True, True, False]).drop(columns="_o")
    return out.reset_index(drop=True)


def verdicts(t: pd.DataFrame) -> pd.DataFrame:
    """Per exponent: the adaptive robot against the fixed one at its shortest cycle."""
    rows = []
    for p, sub in t.groupby("wear_exponent", sort=True):
        fixed = sub[sub["policy"] == FIXED]
        by_cycle = fixed.sort_values("cycle_s")
        short, slow = by_cycle.iloc[0], by_cycle.iloc[-1]
        ad = sub[sub["policy"] == ADAPTIVE].iloc[0]
        rows.append({
            "wear_exponent": float(p),  # type: ignore[arg-type]
            "shortest_cycle_s": float(short["cycle_s"]),
            "mtbf_ratio": float(short["robot_mtbf_h"] / ad["robot_mtbf_h"]),
            "down_fixed_h": float(short["expected_down_h_per_year"]),
            "down_adaptive_h": float(ad["expected_down_h_per_year"]),
            "down_slowest_h": float(slow["expected_down_h_per_year"]),
            "parts_fixed_per_h": float(short["parts_per_h"]),
            "parts_adaptive_per_h": float(ad["parts_per_h"]),
            "oee_fixed": float(short["oee"]), "oee_adaptive": float(ad["oee"]),
            "holds": bool(short["robot_mtbf_h"] < ad["robot_mtbf_h"])})
    return pd.DataFrame(rows)


def flip_exponent(v: pd.DataFrame) -> float | None:
    """The exponent at which log(MTBF ratio) crosses 0, by linear interpolation (None: no
    crossing in the grid)."""
    p, y = v["wear_exponent"].to_numpy(float), np.log(v["mtbf_ratio"].to_numpy(float))
    for i in range(len(p) - 1):
        if y[i] == 0:
            return float(p[i])
        if y[i] * y[i + 1] < 0:
            return float(p[i] + (p[i + 1] - p[i]) * y[i] / (y[i] - y[i + 1]))
    return None


def headline(t: pd.DataFrame) -> str:
    """The one sentence the README quotes (tests/reporting/test_reliability.py checks it)."""
    v = verdicts(t)
    holds = v[v["holds"]]["wear_exponent"].tolist()
    flip = flip_exponent(v)
    worst = v.iloc[-1]
    where = ("for no exponent swept" if not holds else
             "for every exponent swept" if len(holds) == len(v) else
             "only for exponents " + ", ".join(f"{p:g}" for p in holds))
    at = f" (it flips at p ≈ {flip:.2f})" if flip is not None else ""
    return (f"The thesis's reliability argument holds {where}{at}: at p = "
            f"{worst['wear_exponent']:g} the fixed robot at its shortest cycle "
            f"({worst['shortest_cycle_s']:.4f} s) has {abs(100 * (1 - worst['mtbf_ratio'])):.0f} % "
            f"{'shorter' if worst['mtbf_ratio'] < 1 else 'longer'} mean time between wear stops "
            "than the adaptive robot, "
            f"{worst['down_fixed_h']:.1f} against {worst['down_adaptive_h']:.1f} h of downtime "
            f"a year, while delivering {worst['parts_fixed_per_h']:.1f} against "
            f"{worst['parts_adaptive_per_h']:.1f} parts/h.")


def reading(t: pd.DataFrame) -> list[str]:
    """Sentences from the numbers, one paragraph each."""
    v = verdicts(t)
    out = [headline(t)]
    for _, row in v.iterrows():
        ratio = row["mtbf_ratio"]
        word = "shorter" if ratio < 1 else "longer"
        out.append(
            f"**p = {row['wear_exponent']:g}.** The fixed robot at "
            f"{row['shortest_cycle_s']:.4f} s runs {abs(100 * (1 - ratio)):.1f} % {word} "
            f"between wear stops than the adaptive robot: {row['down_fixed_h']:.1f} h of "
            f"downtime a year against {row['down_adaptive_h']:.1f} h (at the nominal cycle, "
            f"{row['down_slowest_h']:.1f} h). OEE {row['oee_fixed']:.3f} against "
            f"{row['oee_adaptive']:.3f}: " + (
                "the claim holds here." if row["holds"] else "the claim does not hold here."))
    gap = v["parts_adaptive_per_h"] - v["parts_fixed_per_h"]
    down = v["down_fixed_h"] - v["down_adaptive_h"]
    lost_h = (down * v["parts_adaptive_per_h"]).abs().max()
    spread = (f"{gap.min():.1f}" if f"{gap.min():.1f}" == f"{gap.max():.1f}"
              else f"{gap.min():.1f} to {gap.max():.1f}")
    more = "more" if gap.mean() >= 0 else "fewer"
    out.append(
        f"**Scale.** Whatever the exponent, the difference in downtime is at most "
        f"{down.abs().max():.1f} h a year, worth about {lost_h:.0f} parts, while the adaptive "
        f"robot delivers {spread} parts/h {more} than the fixed one at its shortest cycle "
        f"({abs(gap.mean()) * YEAR_H:.0f} parts a year): with these assumed lives the "
        "throughput argument (§7.2, Table 7.1) outweighs the reliability one by far.")
    out.append(quality_note(t))
    out.append(
        "Why it can flip: with p = 1 a move's wear is its steps (life in revolutions, the "
        "bearing case), so a faster cycle wears the same per part, and the robot that "
        "transfers more parts wears more; with p = 0 wear is time in motion, and the fixed "
        "robot at a short cycle spends less of it moving; only for p above 1 does running R IV "
        "at the base's peak rate cost more wear than it saves in time.")
    return out


def quality_note(t: pd.DataFrame) -> str:
    """Why the OEEs differ as much as they do: the factor that differs most (ISO 22400-2)."""
    fixed = t[t["policy"] == FIXED]
    short = fixed[fixed["cycle_s"] == fixed["cycle_s"].min()]
    ad = t[t["policy"] == ADAPTIVE]
    factors = {name: (float(short[name].mean()), float(ad[name].mean()))
               for name in ("availability", "performance", "quality", "loss_starved")}
    worst = min(("availability", "performance", "quality"),
                key=lambda k: factors[k][0] / factors[k][1])
    f, a = factors[worst]
    why = {"availability": (": the fixed robot stands still with no part to pick (loss_starved "
                            f"{factors['loss_starved'][0]:.3f} against "
                            f"{factors['loss_starved'][1]:.3f}): the parts it lets go never reach "
                            "its hand."),
           "quality": ": parts scrapped in the hand are produced and not good."}
    return (f"**OEE.** The two robots' OEEs differ mostly by {worst}: {f:.3f} for the fixed "
            f"robot at its shortest cycle against {a:.3f} for the adaptive one"
            + why.get(worst, "."))


def figure(t: pd.DataFrame) -> bytes:
    """Throughput against expected downtime, one panel per exponent."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    exps = sorted(t["wear_exponent"].unique())
    fig = Figure(figsize=(4.2 * len(exps), 4.0), dpi=90, layout="constrained")
    axes = fig.subplots(1, len(exps), squeeze=False)[0]
    for ax, p in zip(axes, exps, strict=True):
        sub = t[t["wear_exponent"] == p]
        fixed, ad = sub[sub["policy"] == FIXED], sub[sub["policy"] == ADAPTIVE]
        ax.plot(fixed["expected_down_h_per_year"], fixed["parts_per_h"], "o-", color="C0",
                label="fixed cycle")
        for _, row in fixed.iterrows():
            ax.annotate(f"{row['cycle_s']:.2f}", (row["expected_down_h_per_year"],
                                                  row["parts_per_h"]), fontsize=7,
                        xytext=(4, -8), textcoords="offset points")
        ax.plot(ad["expected_down_h_per_year"], ad["parts_per_h"], "*", color="C3",
                markersize=14, label="adaptive")
        ax.scatter(sub["down_h_per_year"], sub["parts_per_h"], marker="x", color="grey",
                   s=18, label="downtime as run")
        ax.set_title(f"wear exponent p = {p:g}", fontsize=10)
        ax.set_xlabel("downtime from wear, h a year (expected)", fontsize=8)
        ax.set_ylabel("parts delivered per hour", fontsize=8)
        ax.legend(fontsize=7)
    fig.suptitle("Throughput against downtime as the fixed cycle shortens "
                 "(scenarios/reliability.yaml; labels: the fixed cycle, s)", fontsize=11)
    return map_report.png_bytes(fig)


def markdown(t: pd.DataFrame, reps: pd.DataFrame) -> str:
    hours = float(reps["wear_hours"].mean())
    n = int(reps.groupby(["wear_exponent", "policy", "ideal_cycle_s"]).size().min())
    lines = [
        "# Reliability: throughput against downtime from motor wear", "",
        "Generated by `make reliability` (`python -m cell.reporting.maps.reliability "
        "scenarios/reliability.yaml build/reliability reports/reliability`): both policies, "
        "the fixed cycle at each of Table 7.1's, motor wear on (`wear:` in "
        f"scenarios/baseline.yaml, docs/wear.md), {hours:.0f} simulated hours a run "
        f"(a year of two shifts), {n} replications a point. Downtime is quoted per "
        f"{YEAR_H:.0f} h year; *expected* downtime is from each run's motor exposures "
        "(robot MTBF = 1 / Σ_j 1 / (η_j Γ(1 + 1/β)) over its five motors' lives η_j at that "
        "duty: only the worn motor is replaced, so each motor's place renews on its own), the "
        "figure the reading uses; the runs' own stops are in `down_h_per_year`. OEE as ISO "
        "22400-2 defines it (docs/model.md, \"OEE as plants define it\"): availability (the "
        "robot in motion over the planned time) × performance (the nominal cycle × parts "
        "produced / time in motion) × quality (every part set down is good), the planned time "
        "lost to downtime, starving, blocking, speed and quality in the `loss_` columns. "
        "`reliability.csv` has every figure.", "",
        "![throughput against downtime](reliability.png)", "", "## Reading", ""]
    for sentence in reading(t):
        lines += [sentence, ""]
    return "\n".join(lines + overview(t)).rstrip() + "\n"


def overview(t: pd.DataFrame) -> list[str]:
    """The main figures as a markdown table."""
    lines = ["## Figures", "",
             "| p | policy | cycle, s | parts/h | downtime h/yr, expected | as run | "
             "robot MTBF, h | base motor life, h | OEE |",
             "|---|---|---|---|---|---|---|---|---|"]
    for _, r in t.iterrows():
        cycle = "—" if r["policy"] == ADAPTIVE else f"{r['cycle_s']:.4f}"
        lines.append(
            f"| {r['wear_exponent']:g} | {r['policy']} | {cycle} | {r['parts_per_h']:.2f} | "
            f"{r['expected_down_h_per_year']:.2f} | {r['down_h_per_year']:.1f} | "
            f"{r['robot_mtbf_h']:.0f} | {r['wear_life_base_h']:.0f} | {r['oee']:.3f} |")
    return [*lines, ""]


def money(t: pd.DataFrame, reps: pd.DataFrame, sweep: Any) -> pd.DataFrame:
    """``t`` with each option's money a year (:func:`cell.reporting.money_reading.priced`):
    its runs' means (:func:`~cell.reporting.money_reading.run_inputs`) scaled from the runs'
    hours to a :data:`YEAR_H` year."""
    scenarios = {(p.policy, p.index): p.scenario for p in sweep.points}
    rows = []
    for _, runs in reps.groupby(["wear_exponent", "policy", "point"], sort=False):
        first = runs.iloc[0]
        p, policy, point = first["wear_exponent"], str(first["policy"]), int(first["point"])
        got = money_reading.run_inputs(runs, scenarios[(policy, point)])
        scale = YEAR_H / got["hours"]
        cycle = np.nan if policy == ADAPTIVE else float(runs["ideal_cycle_s"].iloc[0])
        rows.append({"wear_exponent": p, "policy": policy, "cycle_s": cycle,
                     **{k: (v if k == "options_per_h" else v * scale) for k, v in got.items()}})
    priced = money_reading.priced(pd.DataFrame(rows), sweep.points[0].scenario.costs)
    return t.merge(priced, on=["wear_exponent", "policy", "cycle_s"], how="left",
                   validate="one_to_one")


def option_name(row: pd.Series) -> str:
    """An option as the money reading names it."""
    return "the adaptive robot" if row["policy"] == ADAPTIVE else \
        f"the fixed robot at {row['cycle_s']:.4f} s"


def money_lines(t: pd.DataFrame, costs: Any) -> list[str]:
    """The money reading: per wear exponent, the cheapest way to each loss target a year."""
    lines = ["## Money", "",
             f"With the study's `costs:` (a part lost {costs.part_value:g}, an hour of the "
             f"robot down {costs.downtime_per_h:g}, a repair {costs.repair:g}, the robot "
             f"{costs.options_per_h.robot:g} an hour, the adaptive controller "
             f"{costs.options_per_h.adaptive_controller:g}; docs/usage.md, \"Energy and "
             f"cost\"), each option's cost a {YEAR_H:.0f} h year is its parts lost × their value "
             "+ its downtime (as run) × the hour's cost + its wear stops × a repair + its hours × "
             "the options it has; `reliability.csv` has each term (the `lost`, `good`, `down_h`, "
             "`repairs` columns are a year's).", ""]
    named = t.assign(option=[option_name(r) for _, r in t.iterrows()])
    for p in sorted(named["wear_exponent"].unique()):
        options = named[named["wear_exponent"] == p].reset_index(drop=True)
        ad = options[options["policy"] == ADAPTIVE].iloc[0]
        share = money_reading.shares(ad, costs)
        lines += [f"**p = {p:g}.** " + " ".join(money_reading.sentences(
            options, LOSS_TARGETS, "option", "a year")) + " The adaptive robot's cost is "
            f"{100 * share['options']:.0f} % its hours, {100 * share['lost parts']:.0f} % lost "
            f"parts, {100 * share['downtime']:.0f} % downtime and "
            f"{100 * share['repairs and maintenance']:.0f} % repairs.", ""]
    return lines


def write(replications: str | Path, out_dir: str | Path, sweep: Any = None) -> Path:
    """The report from the replications; with ``sweep`` (its scenarios with ``costs:``),
    the money reading too."""
    map_report.check(out_dir, "reliability")
    reps = pd.read_csv(replications)
    t = table(reps)
    text = markdown(t, reps)
    costs = sweep.points[0].scenario.costs if sweep is not None else None
    if costs is not None:
        t = money(t, reps, sweep)
        text = text + "\n" + "\n".join(money_lines(t, costs)).rstrip() + "\n"
    return map_report.write_set(out_dir, "reliability", t, figure(t), text)


def run(sweep_file: str | Path, build: str | Path, out_dir: str | Path,
        workers: int = 2) -> Path:
    """Run the sweep with the wear measures into ``build``, then write the report."""
    from cell.experiments.sweep.runner import run_sweep
    from cell.experiments.sweep.spec import load_sweep

    OutputDir.check(out_dir, FILES, option="DIR")
    sweep = load_sweep(sweep_file)
    outcome = run_sweep(sweep, build, workers=workers, replicate=wear_summary)
    return write(outcome.path, out_dir, sweep)


if __name__ == "__main__":  # pragma: no cover
    map_report.command_line("cell.reporting.maps.reliability", run, 3)
