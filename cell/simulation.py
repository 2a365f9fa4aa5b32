"""One run of the cell in simulated time, and ``cell run`` (thesis §6; SPEC §5-8).

Five SimPy processes talk through stores and events: the feeder drops parts on
the input conveyor; the conveyor hands each to the controller as it reaches B;
the controller (adaptive, §5.3, or fixed-cycle, §6.3) plans the cycle, sets the
belts and sends the robot an order; the robot's lift-off and touch-down are
events; the output conveyor records each part's spacing.  A regime's moves are
summed with precomputed tables, so a part costs a handful of events.

:func:`simulate` is what sweeps call per replication (picklable inputs and
outputs; the solved path is cached per process).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import simpy

from cell import accounting
from cell import thesis as published
from cell.controller import Controller, Log, Plan, constants, fixed_plan
from cell.conveyors import InputConveyor, OutputConveyor
from cell.feeder import Feeder, interarrival_times
from cell.robot import Robot, robot_timing
from cell.scenario import Scenario

#: parts.csv columns, in order.
PART_COLUMNS = [
    "part", "arrival_s", "interarrival_s", "at_bot_s", "picked", "missed", "missed_thesis",
    "pick_s", "touchdown_s", "delivery_interval_s", "motion_cycle_s", "thesis_interval_s",
    "ip_wallclock", "ip_thesis", "input_speed_in_s", "output_speed_in_s", "spacing_in",
    "v_r1_in_s", "v_r2_in_s", "v_r3_in_s", "v_r4_in_s", "note"]

#: summary.csv columns, in order.
SUMMARY_COLUMNS = [
    "scenario", "policy", "seed", "ideal_cycle_s", "parts_arrived", "parts_delivered",
    "parts_missed", "parts_in_cell", "parts_missed_thesis", "actual_cycle_wallclock_s",
    "actual_cycle_thesis_s", "parts_per_hr_wallclock", "parts_per_hr_thesis",
    "vavg_r4_in_s", "ip_wallclock", "ip_thesis", "cycle_vs_nominal_pct",
    "ip_thesis_memoryless", "cycle_vs_nominal_memoryless_pct",
    "spacing_min_in", "spacing_max_in", "spacing_outside_tol", "parts_noted",
    "input_speed_max_in_s", "output_speed_min_in_s", "output_speed_max_in_s", "r1_nominal_s", "r2_nominal_s",
    "r4_s", "thesis_slack_s", "sim_end_s"]



@dataclass
class SimResult:
    """A run's per-part table (parts.csv) and its one-row summary (summary.csv)."""

    parts: pd.DataFrame
    summary: dict[str, Any]
    belts: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    """(instant, speed) of every speed change of the ``input`` and ``output`` belts."""


def _seed_value(seed: Any) -> Any:
    if isinstance(seed, np.random.SeedSequence):
        return str(seed.entropy) + ("/" + ".".join(map(str, seed.spawn_key))
                                    if seed.spawn_key else "")
    return seed


def simulate(scenario: Scenario, seed: int | np.random.SeedSequence | None = None) -> SimResult:
    """Run ``scenario.run.parts`` parts through the cell under its policy.

    ``seed``: int or SeedSequence; None means ``scenario.run.seed``.  Both
    policies given the same seed see the same inter-arrival times.
    """
    s = scenario
    seed = s.run.seed if seed is None else seed
    n = s.run.parts
    timing = robot_timing(s)
    k = constants(s, timing)
    adaptive = s.controller.policy == "adaptive"
    ideal = s.controller.ideal_cycle_s if s.controller.ideal_cycle_s is not None \
        else s.controller.nominal_cycle_s
    fixed = None if adaptive else fixed_plan(k, ideal, s.source)
    # T_1 .. T_{n+1}: the last is only the last part's "next arrival".
    t = interarrival_times(s.arrivals, n + 1, seed, s.base_dir)

    env = simpy.Environment()
    log = Log(n)
    conveyor = InputConveyor(env, k.v_nom, k.input_length, n)
    output = OutputConveyor(env, k.u_nom, n)
    robot = Robot(env, output.placed, log)
    feeder = Feeder(env, t, conveyor, n)
    Controller(env, k, adaptive, fixed, feeder.fed_s, n, conveyor, output, robot, log)
    env.run()

    return SimResult(*_tables(s, seed, ideal, adaptive, k, fixed, t, feeder, log, output,
                              env.now),
                     belts={"input": conveyor.belt.history(), "output": output.belt.history()})


def _tables(s: Scenario, seed: Any, ideal: float, adaptive: bool, k: Any, fixed: Any,
            t: np.ndarray, feeder: Feeder, log: Log, output: OutputConveyor, end_s: float
            ) -> tuple[pd.DataFrame, dict[str, Any]]:
    n = s.run.parts
    picked = np.array([p is not None for p in log.plan])
    nan_plan = (math.nan,) * len(Plan._fields[:-1])
    plans = np.array([p[:-1] if p is not None else nan_plan for p in log.plan], dtype=float)
    col = {name: plans[:, j] for j, name in enumerate(Plan._fields[:-1])}
    r1, r3 = col["r1_pre"] + col["r1_post"], col["r3_pre"] + col["r3_post"]
    tm = k.timing
    td = np.array(log.touchdown_s)
    t_next = t[1:]
    wall = accounting.wallclock(t_next, td)
    if adaptive:
        thesis = accounting.thesis_adaptive(t_next, np.where(picked, log.thesis_interval_s,
                                                             np.nan))
        missed_thesis = ~picked
        thesis_interval, ip_thesis = thesis.interval_s, thesis.ip
        actual_thesis, mean_ip_thesis = thesis.actual_cycle_s, thesis.mean_ip
    else:
        tna = accounting.thesis_non_adaptive(t, ideal)
        missed_thesis = tna.lost
        thesis_interval, ip_thesis = tna.interval_s, tna.ip
        actual_thesis, mean_ip_thesis = float(tna.actual_cycle_s), float(tna.mean_ip)
    spacing = np.array(output.spacing_in)
    parts = pd.DataFrame({
        "part": np.arange(1, n + 1),
        "arrival_s": np.array(feeder.fed_s[:n]),
        "interarrival_s": t[:n],
        "at_bot_s": np.array(log.at_bot_s),
        "picked": picked,
        "missed": ~picked,
        "missed_thesis": missed_thesis,
        "pick_s": np.array(log.pick_s),
        "touchdown_s": td,
        "delivery_interval_s": wall.interval_s,
        "motion_cycle_s": col["cycle"],
        "thesis_interval_s": thesis_interval,
        "ip_wallclock": wall.ip,
        "ip_thesis": ip_thesis,
        "input_speed_in_s": col["input_speed"],
        "output_speed_in_s": col["output_to_g"],
        "spacing_in": spacing,
        "v_r1_in_s": tm.r1_length_in / r1,
        "v_r2_in_s": tm.r2.length_in / col["r2"],
        "v_r3_in_s": tm.r3_length_in / r3,
        "v_r4_in_s": tm.r4.length_in / col["r4"],
        "note": np.array(log.note, dtype=object),
    }, columns=PART_COLUMNS)

    delivered = int(np.isfinite(td).sum())
    missed = int((~picked).sum())
    sp = spacing[np.isfinite(spacing)]
    r4 = col["r4"][picked]
    length_r4 = k.timing.r4.length_in
    if adaptive:
        cycle_pct = 100.0 * (actual_thesis - k.cycle_nom) / k.cycle_nom
        r4_s = float(r4.mean()) if r4.size else math.nan
        shortest = k.cycle_nom - (k.r4_nom - k.timing.r4_min_s)
        memo = accounting.thesis_adaptive_memoryless(t_next, k.cycle_nom, shortest)
        memo_ip = memo.mean_ip
        memo_pct = 100.0 * (memo.actual_cycle_s - k.cycle_nom) / k.cycle_nom
    else:
        cycle_pct = 100.0 * (actual_thesis - ideal) / ideal
        r4_s = fixed.r4
        memo_ip = memo_pct = math.nan
    vout = col["output_to_g"][picked]
    summary = {
        "scenario": s.name,
        "policy": s.controller.policy,
        "seed": _seed_value(seed),
        "ideal_cycle_s": ideal,
        "parts_arrived": n,
        "parts_delivered": delivered,
        "parts_missed": missed,
        "parts_in_cell": n - delivered - missed,
        "parts_missed_thesis": int(np.sum(missed_thesis)),
        "actual_cycle_wallclock_s": wall.actual_cycle_s,
        "actual_cycle_thesis_s": actual_thesis,
        "parts_per_hr_wallclock": float(accounting.parts_per_hr(wall.actual_cycle_s)),
        "parts_per_hr_thesis": float(accounting.parts_per_hr(actual_thesis)),
        "vavg_r4_in_s": length_r4 / r4_s if r4_s == r4_s else math.nan,
        "ip_wallclock": wall.mean_ip,
        "ip_thesis": mean_ip_thesis,
        "cycle_vs_nominal_pct": cycle_pct,
        "ip_thesis_memoryless": memo_ip,
        "cycle_vs_nominal_memoryless_pct": memo_pct,
        "spacing_min_in": float(sp.min()) if sp.size else math.nan,
        "spacing_max_in": float(sp.max()) if sp.size else math.nan,
        "spacing_outside_tol": int(np.sum(np.abs(sp - k.spacing) > k.tol + 1e-9)),
        "parts_noted": int(sum(1 for note in log.note if note)),
        "input_speed_max_in_s": feeder.conveyor.belt.max_speed(),
        "output_speed_min_in_s": float(vout.min()) if vout.size else math.nan,
        "output_speed_max_in_s": float(vout.max()) if vout.size else math.nan,
        "r1_nominal_s": k.r1_nom,
        "r2_nominal_s": k.r2_nom,
        "r4_s": r4_s,
        "thesis_slack_s": math.nan if adaptive else accounting.THESIS_SLACK_S,
        "sim_end_s": end_s,
    }
    return parts, summary


# --------------------------------------------------------------------------- cell run
def format_summary(summary: dict[str, Any]) -> str:
    """The summary as a two-column table, with the thesis's figures where it has them."""
    adaptive = summary["policy"] == "adaptive"
    row = None if adaptive else published.TABLE_7_1.get(round(summary["ideal_cycle_s"], 4))
    # the published figures as printed: four decimals, whole parts
    actual, missed, per_hr, vavg, ip = ((f"{x:.4f}" if isinstance(x, float) else f"{x}")
                                        for x in row) if row else ("",) * 5
    rows: list[tuple[str, str]] = []

    def add(label: str, value: Any, fmt: str = "{:.4f}", thesis: str = "") -> None:
        text = fmt.format(value) if isinstance(value, (int, float)) and value == value \
            else str(value)
        rows.append((label, text + (f"   (thesis: {thesis})" if thesis else "")))

    add("policy", summary["policy"], "{}")
    add("ideal cycle, s", summary["ideal_cycle_s"])
    add("parts arrived", summary["parts_arrived"], "{:d}")
    add("parts delivered", summary["parts_delivered"], "{:d}")
    add("parts lost (wall-clock)", summary["parts_missed"], "{:d}", "0" if adaptive else missed)
    if not adaptive:
        add("parts lost (thesis bookkeeping)", summary["parts_missed_thesis"], "{:d}", missed)
    add("actual cycle, wall-clock, s", summary["actual_cycle_wallclock_s"])
    add("actual cycle, thesis's accounting, s", summary["actual_cycle_thesis_s"], "{:.4f}",
        actual)
    add("parts/hr, wall-clock", summary["parts_per_hr_wallclock"])
    add("parts/hr, thesis's accounting", summary["parts_per_hr_thesis"], "{:.4f}",
        per_hr)
    add("Vavg R IV, in/s", summary["vavg_r4_in_s"], "{:.4f}",
        vavg)
    add("IP, wall-clock", summary["ip_wallclock"])
    add("IP, thesis's accounting", summary["ip_thesis"], "{:.4f}",
        f"{published.ADAPTIVE_IP}" if adaptive else ip)
    if adaptive:
        add("mean cycle (step 6.2) vs 22.5872 s, %", summary["cycle_vs_nominal_pct"],
            "{:+.2f}", f"within {published.ADAPTIVE_CYCLE_PCT} %")
        add("IP, arrivals counted from each pick-up", summary["ip_thesis_memoryless"],
            "{:.4f}", f"{published.ADAPTIVE_IP}")
        add("mean cycle, same reading, %", summary["cycle_vs_nominal_memoryless_pct"],
            "{:+.2f}", f"within {published.ADAPTIVE_CYCLE_PCT} %")
    add("spacing min / max, in",
        f"{summary['spacing_min_in']:.3f} / {summary['spacing_max_in']:.3f}", "{}",
        "45.00 ± 0.25")
    add("spacings outside tolerance", summary["spacing_outside_tol"], "{:d}")
    add("parts with a note (limits hit, lost)", summary["parts_noted"], "{:d}")
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label:<{width}}  {text}" for label, text in rows)


def cmd_run(args: argparse.Namespace) -> int:
    """``cell run SCENARIO --out DIR``: write DIR/parts.csv and DIR/summary.csv."""
    from cell.cli import parse_sets
    from cell.output import write_csv
    from cell.scenario import load_scenario

    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    result = simulate(scenario)  # every error is raised before anything is written
    out = Path(args.out)
    write_csv(result.parts, out / "parts.csv")
    write_csv(pd.DataFrame([result.summary], columns=SUMMARY_COLUMNS), out / "summary.csv")
    print(format_summary(result.summary))
    print(f"wrote {out / 'parts.csv'} and {out / 'summary.csv'}")
    return 0
