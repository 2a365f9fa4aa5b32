"""Warnings for a run whose times look like a unit mixed up: milliseconds written where the
scenario reads seconds (a trace exported in ms, ``controller.nominal_cycle_s: 22587``).

Said, not refused: a supply that slow may be meant.  A belt whose length is left out is
derived from the nominal cycle (:func:`cell.sim.policy_setup.constants`: twice the nominal input
speed times the cycle), so a cycle in ms makes it kilometres long; the warning says so.
"""

from __future__ import annotations

from cell.sim.assembly import AssembledCell

#: Below this offered load (the robot's fastest cycle over the mean inter-arrival time) the
#: arrivals look like milliseconds; the thesis's cell runs at about 0.8.
LOW_OFFERED_LOAD = 0.05
#: A stated nominal cycle this many times the arrivals' mean, or this many times shorter,
#: looks like a unit slip (seconds are 1000 ms, a minute is 60 s).
CYCLE_RATIO = 10.0


def _duration(seconds: float) -> str:
    """``seconds`` in hours or minutes when that reads better ('' for under two minutes)."""
    if seconds >= 2 * 3600:
        return f" ({seconds / 3600:.3g} h)"
    return f" ({seconds / 60:.3g} min)" if seconds >= 120 else ""


def _times(ratio: float) -> str:
    """``ratio`` as 'N times' or '1/N of', N to three figures (whole from 100 on)."""
    n = ratio if ratio >= 1 else 1 / ratio
    shown = f"{n:.0f}" if n >= 100 else f"{n:.3g}"
    return f"{shown} times" if ratio >= 1 else f"1/{shown} of"


def cycle_slip(cell: AssembledCell) -> bool:
    """Whether the stated nominal cycle is more than :data:`CYCLE_RATIO` times off the
    arrivals' mean (then :func:`unit_warnings` says too that the controller aims at it)."""
    stated = cell.scenario.controller.nominal_cycle_s
    return stated is not None and not 1 / CYCLE_RATIO <= stated / cell.k.mean_interarrival_s <= CYCLE_RATIO


def unit_warnings(cell: AssembledCell) -> list[str]:
    """One line each: an offered load below :data:`LOW_OFFERED_LOAD`; a stated nominal cycle
    more than :data:`CYCLE_RATIO` times off the arrivals' mean (:func:`cycle_slip`; the line
    says what ``cell.reporting.run_summary.warnings`` would, which then leaves it out).  The line
    about a long cycle adds the input belt's length when that is derived from it."""
    s, k = cell.scenario, cell.k
    mean = k.mean_interarrival_s
    out: list[str] = []
    long_cycle = False
    if k.offered_load < LOW_OFFERED_LOAD:
        a = s.arrivals
        where = f"arrivals.trace_csv ({a.trace_csv})" if a.trace_csv is not None else \
            "arrivals.mean_s" if a.mean_s is not None else "arrivals.params"
        out.append(f"offered load {k.offered_load:.3g}: a part every {mean:.6g} s on average"
                   f"{_duration(mean)}, and the robot's fastest cycle is {k.fastest_cycle_s:.4g} s: "
                   f"are the times in milliseconds? {where} is read in seconds")
        long_cycle = k.nominal_from == "arrivals"
    stated = s.controller.nominal_cycle_s
    if stated is not None and cycle_slip(cell):
        out.append(f"controller.nominal_cycle_s = {stated:.6g} s{_duration(stated)} is "
                   f"{_times(stated / mean)} the arrivals' mean ({mean:.6g} s): milliseconds "
                   "for seconds, or the other way round? both are in seconds; the controller "
                   "aims at it, not at the arrivals (set it to null to follow them)")
        long_cycle = long_cycle or stated > mean
    if long_cycle and s.belts.input_length_in is None:
        metres = k.input_length * 0.0254
        shown = f"{metres / 1000:.3g} km" if metres >= 1000 else f"{metres:.3g} m"
        out[-1] += (f"; the input belt's length, derived from the nominal cycle (belts.input_length_in "
                    f"left out), is {k.input_length:.6g} in ({shown})")
    return out


def run_warnings(cell: AssembledCell) -> list[str]:
    """What ``cell run``, ``cell animate`` and ``cell figures`` warn of before they run: an
    overloaded cell, a nominal cycle off the arrivals, a unit slip (one line for a slip of
    the nominal cycle, not that and its percentage)."""
    from cell.reporting.run_summary import warnings

    return [*warnings(cell.k, nominal=not cycle_slip(cell)), *unit_warnings(cell)]
