"""The README's claims about the runs and one transfer's path, kinematics and speeds (Fig. 8-22)."""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Any

import numpy as np
import pytest
import scipy.stats

from .readme_sources import REPO, Sources, claim, points, value


@claim("(CODE, seed {}, {} parts)")
def _run(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], f.s.run.seed), (n[1], f.s.run.parts)]


@claim("all seven runs see the same {} inter-arrival times")
def _draws(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], len(f.runs.adaptive.parts))]


# Fig. 8
@claim("the {} in input belt along y = {} and the output belt along x = {}, the robot's base "
       "axis at ({}, {}), B ({}, {}) → F ({}, {}) on the input belt, G ({}, {}) → K ({}, {}) on "
       "the output belt, LO at ({}, {}) and TD at ({}, {})")
def _fig8_points(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    pts = points(f)
    expected = [f.s.cell.belt_width_in, pts["B"][1], pts["G"][0]]
    for name in ("base", "B", "F", "G", "K", "LO", "TD"):
        expected += [pts[name][0], pts[name][1]]
    return zip(n, expected)


@claim("R II is the quarter arc of radius {} in; the R IV return arc (radius {} in) swings out "
       "over the belts' corner to x = {} in and y = {} in")
def _fig8_arcs(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    xyz = f.table.path.xyz_in
    base = np.asarray(f.s.cell.robot_base_in[:2])
    radius = {r: np.linalg.norm(xyz[f.table.regime_rows(r), :2] - base, axis=1) for r in (2, 4)}
    assert np.ptp(radius[2]) < 1e-9 and np.ptp(radius[4]) < 1e-9
    return [(n[0], radius[2][0]), (n[1], radius[4][0]), (n[2], xyz[:, 0].max()),
            (n[3], xyz[:, 1].min())]


# Fig. 9
@claim("R I and R III are {} moves and {} in each ({} in of belt plus the clamped-spline dip from "
       "z = {} in to {} in at LO and TD), R II {} moves and {} in at z = {} in, R IV {} moves and "
       "{} in at z = {} in; {} points in all")
def _fig9(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    t, p = f.table, f.table.path
    moves = {r: int(t.regime_rows(r).sum()) for r in (1, 2, 3, 4)}
    assert moves[1] == moves[3] and t.regime_length(1) == pytest.approx(t.regime_length(3))
    z = {r: p.xyz_in[t.regime_rows(r), 2] for r in (2, 4)}
    return [(n[0], moves[1]), (n[1], t.regime_length(1)),
            (n[2], f.s.path.f_in[0] - f.s.path.bot_in[0]), (n[3], f.s.path.bot_in[2]),
            (n[4], f.s.path.pick_height_in), (n[5], moves[2]), (n[6], t.regime_length(2)),
            (n[7], z[2].max()), (n[8], moves[4]), (n[9], t.regime_length(4)), (n[10], z[4].min()),
            (n[11], p.n_points)]


@claim("up to the shoulder at {} in")
def _shoulder(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], f.s.cell.shoulder_height_in)]


# Fig. 12
@claim("the hand is longest, {} in, at G = G0 = {} in; holding the {} in cube it is {} in; at the "
       "assumed {} in open width {} in; it falls to L1 = {} in at G = {} in, where the square root "
       "vanishes. The {} in between open and closed")
def _fig12(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    h = f.s.robot.hand
    l2 = h.l2_in

    def w11(g: float) -> float:               # eq. 6.2 as corrected (docs/sources.md)
        return h.l1_in + np.sqrt(max(l2 ** 2 - (g - h.g0_in) ** 2 / 2, 0.0))

    held, opened = w11(f.s.part.size_in), w11(h.open_in)
    return [(n[0], w11(h.g0_in)), (n[1], h.g0_in), (n[2], f.s.part.size_in), (n[3], held),
            (n[4], h.open_in), (n[5], opened), (n[6], h.l1_in), (n[7], h.g0_in + l2 * np.sqrt(2)),
            (n[8], held - opened)]


# Fig. 13-14
@claim("The run's own {} inter-arrival times")
def _fig13_n(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], len(f.draws))]


@claim("pdf mean {} s and sd {} s, the draws {} s and {} s, from {} to {} s; the mode sits a "
       "little right of the mean, at {} s (the shape {} leaves a slight left skew). The thesis's "
       "mean {} s is the distribution's {} s to rounding")
def _fig13(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    w, x = f.weibull, f.draws
    c, loc, scale = (f.s.arrivals.params[k] for k in ("c", "loc", "scale"))
    mode = loc + scale * ((c - 1) / c) ** (1 / c)
    assert mode > w.mean()
    return [(n[0], w.mean()), (n[1], w.std()), (n[2], x.mean()), (n[3], x.std(ddof=1)),
            (n[4], x.min()), (n[5], x.max()), (n[6], mode), (n[7], c),
            (n[8], f.s.controller.nominal_cycle_s), (n[9], w.mean())]


@claim("(Kolmogorov–Smirnov D = {}, p = {}); the dashed line shows eq. 6.9 at work, u = {} → T = {} s "
       "(the median)")
def _fig14(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    ks = scipy.stats.kstest(f.draws, f.weibull.cdf)
    return [(n[0], ks.statistic), (n[1], ks.pvalue), (n[2], 0.5), (n[3], f.weibull.median())]


# Fig. 15-21
@claim("R I and R III locked to their belts ({} and {} in/s), R IV with the base at its nominal {} % "
       "rate, R II the rest of the {} s ideal cycle. No move is shorter than its motors allow, so "
       "R I takes {} s rather than {}/{} s")
def _nominal(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    b, p = f.s.belts, f.s.path
    return [(n[0], b.input_nominal_in_s), (n[1], b.output_nominal_in_s),
            (n[2], 100 * f.s.robot.motors.nominal_fraction), (n[3], f.s.controller.nominal_cycle_s),
            (n[4], f.tl.regime_s[1]), (n[5], p.f_in[0] - p.bot_in[0]), (n[6], b.input_nominal_in_s)]


@claim("R III {} s, R IV {} s (the calibrated nominal), and R II {} s, not the thesis's "
       "{} − {}/{} − {} − {} = {} s")
def _split(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    b, p, r = f.s.belts, f.s.path, f.tl.regime_s
    belt = p.f_in[0] - p.bot_in[0]
    r3_pace = (p.eot_in[1] - p.g_in[1]) / b.output_nominal_in_s
    thesis_r2 = value(n[3]) - value(n[4]) / value(n[5]) - value(n[6]) - value(n[7])
    return [(n[0], r[3]), (n[1], r[4]), (n[2], r[2]), (n[3], f.s.controller.nominal_cycle_s),
            (n[4], belt), (n[5], b.input_nominal_in_s), (n[6], r3_pace), (n[7], r[4]),
            (n[8], thesis_r2)]


@claim("x rises from {} to {} and y from {} to {} over the first {} s; z dips to {} in at LO ({} s) "
       "and TD ({} s). As the thesis says, y has a sharp peak, {} in at K, {} s, where R IV turns "
       "back; during R IV x swings out to {} in and y to {} in")
def _fig15(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    p, t, k = f.table.path, f.tl.t_s, f.k_point
    xyz = p.xyz_in
    assert xyz[: k + 1, 1].max() == xyz[k, 1]      # y's peak is at K
    return [(n[0], xyz[0, 0]), (n[1], xyz[k, 0]), (n[2], xyz[0, 1]), (n[3], xyz[k, 1]),
            (n[4], t[k]), (n[5], xyz[:, 2].min()), (n[6], t[p.lo]), (n[7], t[p.td]),
            (n[8], xyz[:, 1].max()), (n[9], t[k]), (n[10], xyz[:, 0].max()), (n[11], xyz[:, 1].min())]


@claim("θ1 (base) climbs from {}° to {}° over R I–R III and comes straight back in R IV, a sharp "
       "peak at {} s; the wrist roll θ5 goes {}° → {}° in R I, holds {}° through R II")
def _fig16_roll(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    deg, k = np.degrees(f.table.path.q_rad), f.k_point
    end_r1 = int(np.flatnonzero(f.table.path.regime == 1)[-1])
    r2 = f.table.regime_rows(2)
    assert np.ptp(deg[r2, 4]) < 1e-6
    return [(n[0], deg[:, 0].min()), (n[1], deg[k, 0]), (n[2], f.tl.t_s[k]), (n[3], deg[0, 4]),
            (n[4], deg[end_r1, 4]), (n[5], deg[r2, 4].mean())]


@claim("reaches {}° at K and is turned back to {}° during R IV")
def _fig16_back(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    deg = np.degrees(f.table.path.q_rad)
    return [(n[0], deg[f.k_point, 4]), (n[1], deg[-1, 4])]


@claim("smooth bumps at the two dips ({}° to {}°) and is constant at {}° from K to B, because "
       "R IV stays at z = {} in")
def _fig16_shoulder(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    deg, k = np.degrees(f.table.path.q_rad), f.k_point
    after_k = deg[k:, 1]
    assert np.ptp(after_k) < 1e-6
    return [(n[0], deg[: k + 1, 1].min()), (n[1], deg[: k + 1, 1].max()), (n[2], after_k[0]),
            (n[3], f.table.path.xyz_in[f.table.regime_rows(4), 2].max())]


@claim("Base: {} steps/s through R II, rising to a peak of {} steps/s in R I after LO (below its {} "
       "steps/s loaded maximum) and falling to {} steps/s at K; R IV is a flat {} steps/s, exactly "
       "the nominal {} % line")
def _fig17(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    base, lim, lo = f.rates[:, 0], f.limits[:, 0], f.table.path.lo
    r2, r4 = f.regime_rows(2), f.regime_rows(4)
    after_lo = f.regime_rows(1) & (np.arange(len(base)) >= lo)
    assert np.ptp(base[r2]) < 1e-6 and np.ptp(base[r4]) < 1e-6
    fraction = f.s.robot.motors.nominal_fraction
    assert -base[r4][0] == pytest.approx(fraction * lim[r4][0], rel=1e-3)
    return [(n[0], base[r2][0]), (n[1], base[after_lo].max()), (n[2], lim[lo]),
            (n[3], base[f.k_point - 1]), (n[4], base[r4][0]), (n[5], 100 * fraction)]


@claim("After LO it runs at its loaded maximum of {} steps/s (the red line drops from {} to {} "
       "steps/s at LO, when the {} oz part is picked), and the two single-move spikes to ±{} "
       "steps/s are the hand closing at LO and opening after TD")
def _fig18(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    shoulder, lim, lo, td = f.rates[:, 1], f.limits[:, 1], f.table.path.lo, f.table.path.td
    assert np.all(np.abs(shoulder) <= lim * (1 + 1e-9))
    spikes = np.abs(shoulder[[lo - 1, td]])
    return [(n[0], np.abs(shoulder[lo:td - 1]).max()), (n[1], lim[lo - 1]), (n[2], lim[lo]),
            (n[3], f.s.part.weight_oz), (n[4], spikes.min()), (n[4], spikes.max())]


@claim("Elbow: {} steps/s leaving B, easing off towards F, up to {} steps/s in R III, far below its "
       "{}–{} steps/s limits")
def _fig19(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    elbow, lim = f.rates[:, 2], f.limits[:, 2]
    assert elbow[0] == elbow[f.regime_rows(1)].min()
    return [(n[0], elbow[0]), (n[1], elbow[f.regime_rows(3)].max()), (n[2], lim.min()),
            (n[3], lim.max())]


@claim("Wrist pitch: never above {} steps/s against a maximum of {}–{} steps/s")
def _fig20(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], np.abs(f.rates[:, 3]).max()), (n[1], f.limits[:, 3].min()),
            (n[2], f.limits[:, 3].max())]


@claim("Wrist roll: {}–{} steps/s in R I and {}–{} steps/s in R III, zero in R II (the part's {}° "
       "turn is the base's), a steady {} steps/s in R IV")
def _fig21(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    roll = f.rates[:, 4]
    r1, r2, r3, r4 = (f.regime_rows(r) for r in (1, 2, 3, 4))
    assert np.abs(roll[r2]).max() < 1e-6 and np.ptp(roll[r4]) < 1e-6
    phi = np.degrees(f.table.path.phi_rad)
    return [(n[0], roll[r1].min()), (n[1], roll[r1].max()), (n[2], roll[r3].min()),
            (n[3], roll[r3].max()), (n[4], phi[f.table.path.td] - phi[0]), (n[5], roll[r4][0])]


# Fig. 22
@claim("One adaptive transfer (part {}, the part with the longest lag")
def _fig22_part(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], f.fig22["row"]["part"])]


@claim("the look-ahead lag, {} s of tracking B → LO at the current belt speed {} in/s, before the "
       "belt may change (here to {} in/s). The tip then averages {} (R I), {} (R II), {} (R III, "
       "the belt's {} in/s plus the dip) and {} in/s (R IV)")
def _fig22_speeds(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    row = f.fig22["row"]
    return [(n[0], row["pick_s"] - row["at_bot_s"]), (n[1], f.fig22["before"]),
            (n[2], f.fig22["after"]), (n[3], row["v_r1_in_s"]), (n[4], row["v_r2_in_s"]),
            (n[5], row["v_r3_in_s"]), (n[6], f.s.belts.output_nominal_in_s),
            (n[7], row["v_r4_in_s"])]


@claim("so each lasts {} s at {} in/s")
def _fig22_hand(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    return [(n[0], f.fig22["dt"]), (n[1], f.fig22["speed"])]


@claim("its example lag is {} s")
def _thesis_lag(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    section = (REPO / "docs" / "sources.md").read_text().split("## Fig. 22, the look-ahead lag")[1]
    quoted = re.search(r"a lag of ([\d.]+) s", section)
    assert quoted, "docs/sources.md no longer quotes the thesis's lag"
    return [(n[0], float(quoted[1]))]


@claim("here the lag is B → LO ({} in) over the belt speed, {}–{} s over all {} parts. A {} s lag "
       "would need LO about {} in from B at {} in/s")
def _fig22_lags(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    lags, v = f.fig22["lags"], f.s.belts.input_nominal_in_s
    thesis_lag = value(n[4])
    return [(n[0], f.s.path.lo_from_bot_in), (n[1], lags.min()), (n[2], lags.max()),
            (n[3], len(f.runs.adaptive.parts)), (n[5], thesis_lag * v), (n[6], v)]
