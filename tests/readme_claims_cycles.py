"""The README's claims about throughput, interference and the robot cycles (Fig. 23-30)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np
import pandas as pd
import pytest

from .readme_sources import Sources, claim, value


# Fig. 23-24
def _lots(values: pd.Series) -> np.ndarray:
    from cell.reporting.figures.runs import LOT

    v = values.to_numpy(dtype=float)
    return np.nanmean(v[: len(v) // LOT * LOT].reshape(-1, LOT), axis=1)


@claim("({}-part lot means {}–{} s; run mean {} s as counted by the thesis, {} %; {} s on the wall "
       "clock, {} %), and the non-adaptive one (robot cycle {} s) is far above it (lot means {}–{} "
       "s). Its mean as the thesis counted is {} s, **{} %**: this matches the thesis's \"{} "
       "percent out of spec\"")
def _fig23(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.reporting.figures.runs import LOT

    a, na = f.runs.adaptive.parts, f.runs.non_adaptive[22.5872].parts
    ideal = f.s.controller.nominal_cycle_s
    lots_a, lots_na = _lots(a["thesis_interval_s"]), _lots(na["thesis_interval_s"])
    ma, wa, mna = (float(np.nanmean(x)) for x in (a["thesis_interval_s"],
                                                  a["delivery_interval_s"], na["thesis_interval_s"]))
    return [(n[0], LOT), (n[1], lots_a.min()), (n[2], lots_a.max()), (n[3], ma),
            (n[4], 100 * (ma / ideal - 1)), (n[5], wa), (n[6], 100 * (wa / ideal - 1)),
            (n[7], ideal), (n[8], lots_na.min()), (n[9], lots_na.max()), (n[10], mna),
            (n[11], 100 * (mna / ideal - 1)), (n[12], 100 * (mna / ideal - 1))]


@claim("That mean is over all {} parts, a lost part booked as one more cycle (D = T + C); the run's "
       "summary (CODE) divides the same total by the {} parts delivered and reads {} s")
def _fig23_note(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    run = f.runs.non_adaptive[22.5872]
    d = run.parts
    delivered = len(d) - int(d["missed_thesis"].sum())
    assert run.summary["actual_cycle_thesis_s"] == pytest.approx(
        d["thesis_interval_s"].sum() / delivered)
    return [(n[0], len(d)), (n[1], delivered), (n[2], run.summary["actual_cycle_thesis_s"])]


@claim("The thesis's \"{} percent reduction in throughput\" is {}/{} lost parts")
def _throughput(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    missed = f.published("parts_missed")
    return [(n[1], missed), (n[2], f.s.run.parts), (n[0], 100 * missed / f.s.run.parts)]


@claim("On the wall clock the non-adaptive robot loses {} parts (the thesis's bookkeeping: {}) and "
       "averages {} s, {} %")
def _fig23_wall(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    run = f.runs.non_adaptive[22.5872]
    mean = float(np.nanmean(run.parts["delivery_interval_s"]))
    assert mean == pytest.approx(run.summary["actual_cycle_wallclock_s"])
    return [(n[0], run.summary["parts_missed"]), (n[1], run.summary["parts_missed_thesis"]),
            (n[2], mean), (n[3], 100 * (mean / f.s.controller.nominal_cycle_s - 1))]


@claim("the adaptive one (thesis count) reads {} s after {} parts and {} s after {}")
def _fig24_adaptive(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.reporting.figures.runs import running_mean

    y = running_mean(f.runs.adaptive.parts["thesis_interval_s"])
    return [(n[0], y[int(value(n[1])) - 1]), (n[2], y[int(value(n[3])) - 1])]


@claim("The non-adaptive one swings between {} and {} s over the first {} parts (thesis count; {} "
       "to {} s on the wall clock) and only slowly drifts to {} s (thesis count) or {} s (wall "
       "clock)")
def _fig24_non_adaptive(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.reporting.figures.runs import running_mean

    d = f.runs.non_adaptive[22.5872].parts
    first = int(value(n[2]))
    thesis, wall = (running_mean(d[c]) for c in ("thesis_interval_s", "delivery_interval_s"))
    return [(n[0], np.nanmin(thesis[:first])), (n[1], np.nanmax(thesis[:first])),
            (n[3], np.nanmin(wall[:first])), (n[4], np.nanmax(wall[:first])), (n[5], thesis[-1]),
            (n[6], wall[-1])]


# Fig. 25-30
@claim("Robot cycle {} s. Adaptive IP stays in a band ({}–{}, mean {} as the thesis counted, {} on "
       "the wall clock; the thesis reports {};")
def _fig25_adaptive(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    a = f.runs.adaptive.parts
    from cell.reporting.published import TABLE_7_1_CYCLES

    return [(n[0], TABLE_7_1_CYCLES[0]), (n[1], a["ip_thesis"].min()), (n[2], a["ip_thesis"].max()),
            (n[3], a["ip_thesis"].mean()), (n[4], a["ip_wallclock"].mean()),
            (n[5], f.published("ip", policy="adaptive"))]


@claim("gives {} and a cycle {} % short, next to the thesis's \"within {} percent\"")
def _memoryless(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.reporting.published import ADAPTIVE_CYCLE_PCT

    summary = f.runs.adaptive.summary
    return [(n[0], summary["ip_thesis_memoryless"]),
            (n[1], -summary["cycle_vs_nominal_memoryless_pct"]), (n[2], ADAPTIVE_CYCLE_PCT)]


def _lost_and_ip(f: Sources, count: str) -> tuple[np.ndarray, np.ndarray]:
    """Fig. 25's run (non-adaptive, cycle 22.5872 s): parts lost and their IP, counted the
    thesis's way (``"thesis"``) or on the wall clock (``"wallclock"``)."""
    d = f.runs.non_adaptive[22.5872].parts
    missed = "missed_thesis" if count == "thesis" else "missed"
    return d[missed].to_numpy(dtype=bool), d[f"ip_{count}"].to_numpy(dtype=float)


@claim("two bands, {}–{} for delivered parts (its doubled denominator) and {}–{} for the {} missed "
       "parts (triangles), mean {} against Table 7.1's {}")
def _fig25_bands(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    lost, ip = _lost_and_ip(f, "thesis")
    assert ip[~lost].min() > ip[lost].max()          # two bands, apart
    return [(n[0], ip[~lost].min()), (n[1], ip[~lost].max()), (n[2], ip[lost].min()),
            (n[3], ip[lost].max()), (n[4], lost.sum()), (n[5], ip.mean()),
            (n[6], f.published("ip"))]


@claim("a delivered part's IP averages {} when the part before it was delivered and {} when it was "
       "lost, and the {} lost parts (no delivery, no IP) are marked on the floor; mean {}")
def _fig25_wall(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    lost, ip = _lost_and_ip(f, "wallclock")
    after_loss = np.r_[False, lost[:-1]]
    shown = ~lost & np.isfinite(ip)
    assert np.all(np.isnan(ip[lost]))
    return [(n[0], ip[shown & ~after_loss].mean()), (n[1], ip[shown & after_loss].mean()),
            (n[2], lost.sum()), (n[3], np.nanmean(ip))]


def _cycle_claims(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    cycle = value(n[0])
    d = f.runs.non_adaptive[cycle].parts
    return [(n[1], d["missed_thesis"].sum()), (n[2], f.published("parts_missed", cycle)),
            (n[3], d["ip_thesis"].mean()), (n[4], f.published("ip", cycle)),
            (n[5], d["missed"].sum()), (n[6], np.nanmean(d["ip_wallclock"]))]


claim("Robot cycle {} s: {} parts missed as the thesis counted (Table 7.1: {}), mean IP {} "
      "(Table 7.1: {}); on the wall clock {} lost, mean IP {}")(_cycle_claims)
claim("Robot cycle {} s: {} missed as the thesis counted (Table 7.1: {}), IP {} (Table 7.1: {}); on "
      "the wall clock {} lost, IP {}")(_cycle_claims)
claim("Robot cycle {} s, the minimum feasible: {} missed as the thesis counted (Table 7.1: {}), IP {} "
      "(Table 7.1: {}); on the wall clock {} lost, IP {}")(_cycle_claims)
