"""One run's summary for people: what ran, whether the cell can keep up, the
results beside the thesis's where the run is the thesis's own, and the limits hit."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.reporting import published
from cell.scenario.run_length import SECONDS_PER_HOUR, RunLength
from cell.scenario.schema import Scenario, load_scenario
from cell.sim.assembly import AssembledCell
from cell.sim.policies.base import CellConstants
from cell.sim.records import LIMIT_COUNTS, RunSummary

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Sweep

#: Relative difference between the nominal cycle and the arrivals' mean worth a warning.
NOMINAL_MISMATCH = 0.01
IP_LINE = ("IP (eq. 5.1) = the next part's inter-arrival time / the time between deliveries: "
           "1 means the cell keeps pace with its parts.  The thesis's accounting is how the "
           "thesis counted (docs/accounting.md, or `cell docs accounting`); the wall clock is what "
           "a stopwatch shows.")

#: Table 7.1's measures (cell.reporting.published), as printed beside the summary fields, by field.
TABLE_7_1_SHOWN = {"parts_missed_thesis": ("parts_missed", "{:.0f}"),
                   "actual_cycle_thesis_s": ("actual_cycle_s", "{:.4f}"),
                   "parts_per_hr_thesis": ("parts_per_hr", "{:.4f}"),
                   "vavg_r4_in_s": ("vavg_r4_in_s", "{:.4f}"), "ip_thesis": ("ip", "{:.4f}")}


def run_heading(cell: AssembledCell) -> str:
    """What runs, and at which ideal cycle, said before the run starts."""
    s, k = cell.scenario, cell.k
    source = {"scenario": "controller.nominal_cycle_s",
              "arrivals": "the arrivals' mean",
              "fastest": "the robot's fastest cycle: the arrivals come faster"}[k.nominal_from]
    length = RunLength.of(s.run)
    heading = (f"cell run: {s.name} ({cell.policy.name}), {length}, seed {s.run.seed}\n"
               f"nominal cycle {k.cycle_nom:.4f} s ({source}); mean inter-arrival "
               f"{k.mean_interarrival_s:.4f} s; the robot's fastest cycle {k.fastest_cycle_s:.4f} "
               f"s: offered load {k.offered_load:.3f}")
    if s.calendar is not None:
        from cell.scenario.calendar_section import describe as week

        heading += f"\ncalendar: {week(s.calendar, s.source)}"
    if s.arrivals.profile is not None:
        from cell.scenario.rate_profile import describe

        heading += f"\narrivals not stationary (arrivals.profile): {describe(s.arrivals.profile)}"
    trace = s.arrivals.trace_csv
    if trace is not None:
        from cell.scenario.arrivals import read_trace

        times = read_trace(Path(s.base_dir) / trace)
        n, hours = len(times), s.run.hours
        if hours is not None:  # the parts that come in the hours: replayed if it ends sooner
            covers = float(times.sum())
            if covers < hours * SECONDS_PER_HOUR:
                heading += (f"\narrivals: {trace} covers {covers / SECONDS_PER_HOUR:.3g} of the "
                            f"run's {hours:g} hours: it is replayed from the start")
        elif n == s.run.parts:  # every part has its own; only the look-ahead comes round again
            heading += (f"\narrivals: {trace} holds one inter-arrival time a part; the last "
                        "part's next arrival (for its IP) is the trace's first again")
        elif n < s.run.parts + 1:  # the run needs T_1 .. T_{parts+1}
            held = f"{n} inter-arrival times" if n > 1 else "one inter-arrival time"
            heading += (f"\narrivals: {trace} holds {held} and the run needs {s.run.parts + 1}: "
                        f"it is replayed from the start" + (f" every {n} parts" if n > 1 else ""))
    return heading


def warnings(k: CellConstants, nominal: bool = True) -> list[str]:
    """One line each: the cell cannot keep up on average; the nominal cycle is not the
    arrivals' mean (unless ``nominal`` is false: a line about its unit says so instead)."""
    from cell.experiments.sweep.spec import nominal_gap, overloaded

    out = []
    if k.offered_load >= 1:
        out.append(overloaded(f"offered load {k.offered_load:.3f}",
                              (k.fastest_cycle_s, k.mean_interarrival_s)))
    if nominal and abs(nominal_gap(k)) > NOMINAL_MISMATCH:  # NaN: the cycle follows the arrivals
        out.append(nominal_off(nominal_mismatch(k.cycle_nom, k.mean_interarrival_s)))
    return out


def nominal_warning(sweep: Sweep) -> str | None:
    """One line if some of a sweep's points keep a nominal cycle from its base that is more
    than :data:`NOMINAL_MISMATCH` off their arrivals' mean (a sweep that sets or varies
    ``controller.nominal_cycle_s`` itself chose it), naming the worst; else None."""
    from cell.experiments.sweep.options import show

    key = "controller.nominal_cycle_s"
    if key in sweep.keys or key in dict(sweep.fixed):
        return None
    off = [p for p in sweep.points if abs(p.nominal_gap) > NOMINAL_MISMATCH]  # NaN: never
    if not off:
        return None
    worst = max(off, key=lambda p: abs(p.nominal_gap))
    cycle = float(worst.scenario.controller.nominal_cycle_s or math.nan)
    where = ", ".join(f"{k} {worst.name_of(k) or show(v)}" for k, v in worst.values)
    return nominal_off(f"{len(off)} of {len(sweep.points)} points keep {key} from the base, "
                       f"up to {worst.nominal_gap:+.1%} off their arrivals' mean ({cycle:.4f} s "
                       f"against {cycle / (1 + worst.nominal_gap):.4f} s, at "
                       f"{where or worst.policy})", f" (set: {{{key}: null}} in the sweep file)")


def comparison_nominal_warning(sweep: Sweep) -> str | None:
    """``cell compare``'s :func:`nominal_warning`: one line if A's or B's controller aims at a
    nominal cycle it states that is off its arrivals' mean (as ``cell run`` warns of a run),
    else None."""
    from cell.experiments.sweep.spec import comparison_sides

    said: dict[str, list[str]] = {}
    for label, p in comparison_sides(sweep):
        if abs(p.nominal_gap) > NOMINAL_MISMATCH:  # NaN: it follows the arrivals
            cycle = float(p.scenario.controller.nominal_cycle_s or math.nan)
            said.setdefault(nominal_mismatch(cycle, cycle / (1 + p.nominal_gap)), []).append(label)
    if not said:
        return None
    return nominal_off("; ".join(f"{' and '.join(who)}: {text}" for text, who in said.items()),
                       " (--set controller.nominal_cycle_s=null)")


def nominal_mismatch(cycle_s: float, mean_s: float) -> str:
    """``controller.nominal_cycle_s (X s) is +N% off the arrivals' mean (Y s)``."""
    return (f"controller.nominal_cycle_s ({cycle_s:.4f} s) is {cycle_s / mean_s - 1:+.1%} off "
            f"the arrivals' mean ({mean_s:.4f} s)")


def nominal_off(how_much: str, how_to: str = "") -> str:
    """The one line, for a run, a sweep (:func:`nominal_warning`) or a comparison, saying the
    controller aims at a stated nominal cycle that is not the arrivals' mean: opened by
    ``how_much``, ``how_to`` saying where to set it to null."""
    return (f"{how_much}: the controller aims at it, not at the arrivals; set it to null to "
            f"follow them{how_to}")


def thesis_figures(s: Scenario) -> dict[str, str] | None:
    """The thesis's published figures for this run, as printed, if it is the thesis's own
    run: the built-in baseline (eq. 6.9 arrivals, 500 parts), either policy, a Table 7.1
    cycle for the non-adaptive robot; None otherwise."""
    c = s.controller
    if not is_thesis_cell(s):
        return None
    if c.policy == "adaptive":
        return {"parts_missed": f"{published.ADAPTIVE_PARTS_MISSED}",
                "ip_thesis": f"{published.ADAPTIVE_IP}",
                "cycle_vs_nominal_pct": f"within {published.ADAPTIVE_CYCLE_PCT} %"}
    # the thesis's cell: its nominal cycle is the built-in baseline's
    ideal = c.ideal_cycle_s if c.ideal_cycle_s is not None else c.nominal_cycle_s
    if c.policy != "non-adaptive":
        return None
    table = published.PUBLISHED[c.policy]
    values = {field: table.value(float(ideal or math.nan), measure)
              for field, (measure, _) in TABLE_7_1_SHOWN.items()}
    if any(v is None for v in values.values()):
        return None
    return {field: fmt.format(values[field]) for field, (_, fmt) in TABLE_7_1_SHOWN.items()}


def is_thesis_cell(s: Scenario, *, any_timing: bool = False,
                   baseline: Scenario | None = None) -> bool:
    """Whether ``s`` is the thesis's own run but for its policy, robot cycle and seed (and,
    with ``any_timing``, its robot timing): the built-in baseline's cell, eq. 6.9 arrivals,
    500 parts; names, descriptions and the planner's settings aside.  ``baseline``: the
    built-in baseline, if the caller has it already (it is read otherwise)."""
    c = s.controller
    same = {"controller.policy": c.policy, "controller.ideal_cycle_s": c.ideal_cycle_s,
            "run.seed": s.run.seed}
    if any_timing:
        same["robot.timing"] = s.robot.timing
    thesis = baseline if baseline is not None else load_scenario("baseline")
    return _comparable(s) == _comparable(thesis.with_overrides(same))


def _comparable(s: Scenario) -> dict[str, Any]:
    d = s.to_dict()
    for key in ("name", "description", "mintime"):
        d.pop(key, None)
    return d


#: A figure with no value (NaN: one delivery has no cycle), as every table prints it;
#: summary.csv leaves its cell empty.
UNDEFINED = "—"


def shown_figure(value: float, fmt: str = "{:.4f}") -> str:
    """A figure as printed: ``fmt``, or :data:`UNDEFINED` for NaN."""
    return fmt.format(value) if value == value else UNDEFINED


def _share(value: float) -> str:
    """A share to 0.1 %; one that rounds to zero prints 0.0 %, not -0.0 %."""
    return f"{round(value, 3) + 0.0:.1%}" if math.isfinite(value) else "n/a"


def _no_quality(r: RunSummary) -> str:
    """Why quality (and OEE with it) has no value, if it has none."""
    return "" if r.quality == r.quality else " (nothing produced: quality is undefined)"


#: The scenarios that are the thesis's own: ``cell run`` prints the thesis's accounting (IP,
#: R IV, the thesis's bookkeeping) after the plant's measures for a scenario of one of these
#: names (the built-in ones and their copies), and for any other when asked (``--thesis``).
THESIS_SCENARIOS = ("baseline", "non_adaptive", "table_7_1", "table_7_1_mintime")


def shows_thesis(s: Scenario, asked: bool = False) -> bool:
    """Whether ``cell run`` prints the thesis's accounting: asked for, or a thesis scenario."""
    return asked or s.name in THESIS_SCENARIOS


def oee_line(r: RunSummary) -> str:
    """OEE (ISO 22400-2) and what it is made of; a figure with no value (quality when nothing
    was produced, and OEE with it) is ``n/a`` with the reason, never ``nan``."""
    def shown(v: float) -> str:
        return f"{v:.4f}" if math.isfinite(v) else "n/a"

    return (f"availability {shown(r.availability)}, performance {shown(r.performance)}, quality "
            f"{shown(r.quality)}: OEE {shown(r.oee)}{_no_quality(r)}")


def _mtbf(r: RunSummary, failures: Any) -> str:
    """`` (MTBF 38.5 h, MTTR 0.52 h observed)`` in the units of ``failures.robot``'s times."""
    if not r.robot_failures:
        return ""
    from cell.scenario.failure_spec import SECONDS_PER_HOUR, unit

    robot = getattr(failures, "robot", None)
    units = ("s", "s") if robot is None else (unit(robot.time_to_failure), unit(robot.time_to_repair))

    def shown(v: float, u: str) -> str:
        if not math.isfinite(v):
            return "n/a"
        return f"{v / SECONDS_PER_HOUR:.4g} h" if u == "h" else f"{v:.1f} s"

    return (f" (MTBF {shown(r.mtbf_observed_s, units[0])}, MTTR {shown(r.mttr_observed_s, units[1])}"
            " observed)")


def waterfall_line(r: RunSummary) -> str:
    """Where the planned busy time went: the five losses (summary.csv's names), then OEE."""
    from cell.sim.oee import loss_waterfall

    steps = loss_waterfall(r)
    return ("; ".join(f"{name} {_share(share)}" for name, share in steps[:-1])
            + f"; left: OEE {_share(steps[-1][1])}")


def stops_line(r: RunSummary, failures: Any = None) -> str:
    """A run with failures or wear: the robot's stops, its observed MTBF and MTTR when it
    failed, and the parts they cost.  MTBF and MTTR are in the unit the scenario's
    ``failures`` section gives the robot's time to failure and to repair in: hours where it
    says ``mean_h``, else seconds (summary.csv keeps seconds whatever the unit)."""
    return (f"robot failures {r.robot_failures}{_mtbf(r, failures)}, parts lost to downtime "
            f"{r.parts_lost_downtime}, scrapped {r.parts_scrapped}")


def format_summary(r: RunSummary, thesis: dict[str, str] | None = None,
                   accounting: bool = True) -> str:
    """The summary as a two-column table: the plant's measures (throughput, OEE and its
    losses, parts lost), then, with ``accounting``, the thesis's (IP, R IV, the thesis's
    bookkeeping), its published figures beside ours when given."""
    rows: list[tuple[str, str]] = []

    def add(label: str, value: Any, fmt: str = "{:.4f}", field: str = "") -> None:
        text = value if isinstance(value, str) else shown_figure(value, fmt)
        shown = (thesis or {}).get(field)
        rows.append((label, text + (f"   (thesis: {shown})" if shown else "")))

    add("policy", r.policy, "{}")
    add("ideal cycle, s", r.ideal_cycle_s)
    add("parts arrived / delivered", f"{r.parts_arrived} / {r.parts_delivered}", "{}")
    add("parts lost (wall clock)", r.parts_missed, "{:d}", "parts_missed")
    add("actual cycle, wall clock, s", r.actual_cycle_wallclock_s)
    add("parts/hr, wall clock", r.parts_per_hr_wallclock)
    add("OEE (ISO 22400-2)", oee_line(r), "{}")
    add("planned busy time lost to", waterfall_line(r) + _no_quality(r), "{}")
    add("spacing min / max, in", f"{shown_figure(r.spacing_min_in, '{:.3f}')} / "
        f"{shown_figure(r.spacing_max_in, '{:.3f}')}")
    add("spacings outside 45 ± 0.25 in", r.spacing_outside_tol, "{:d}")
    hit = [f"{label} {getattr(r, field)}" for field, label in LIMIT_COUNTS.values()
           if getattr(r, field)]
    add("limits hit (parts)", "; ".join(hit) if hit else "none", "{}")
    if r.warmup_parts:
        add("warm-up left out, parts", r.warmup_parts, "{:d}")
    plant = len(rows)
    if accounting:
        add("parts lost (thesis's accounting)", r.parts_missed_thesis, "{:d}",
            "parts_missed_thesis")
        add("actual cycle, thesis's accounting, s", r.actual_cycle_thesis_s,
            field="actual_cycle_thesis_s")
        add("parts/hr, thesis's accounting", r.parts_per_hr_thesis, field="parts_per_hr_thesis")
        add("Vavg R IV, in/s", r.vavg_r4_in_s, field="vavg_r4_in_s")
        add("IP, wall clock", r.ip_wallclock)
        add("IP, thesis's accounting", r.ip_thesis, field="ip_thesis")
        add("cycle (thesis's accounting) vs ideal, %", r.cycle_vs_nominal_pct, "{:+.2f}",
            "cycle_vs_nominal_pct")
        if r.ip_thesis_memoryless == r.ip_thesis_memoryless:
            add("IP, next arrivals counted from each pick-up", r.ip_thesis_memoryless,
                field="ip_thesis")
    width = max(len(label) for label, _ in rows)
    lines = [f"{label:<{width}}  {text}" for label, text in rows]
    if not accounting:
        return "\n".join(lines) + "\n(the thesis's accounting: --thesis)"
    lines.insert(plant, "the thesis's accounting:")
    note = "" if thesis else "\n(the thesis's figures are shown only beside a run of its own scenario)"
    return "\n".join(lines) + f"\n{IP_LINE}{note}"
