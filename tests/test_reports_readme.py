"""Every number ``reports/README.md`` quotes is true of what it describes.

Each claim below is a phrase of the README with its numbers left open, and the
place the numbers come from: the baseline scenario and its path, the figures'
own runs (the seven simulations of Fig. 22-30), the committed
``reports/table_7_1/table_7_1.csv`` (the thesis's published column) and, for the thesis's
example lag, ``docs/sources.md``.  A number must equal its source rounded to the
digits printed.  Every number in the README's prose must belong to a claim or
be a reference (Fig. 8, §4.2, eq. 6.2, step 6.2, Table 7.1): a number added to
the README without a check fails the last test.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from cell.thesis import TABLE_7_1_CYCLES

REPO = Path(__file__).resolve().parents[1]
README = REPO / "reports" / "README.md"
NUMBER = r"([−+-]?\d+(?:\.\d+)?)"


def prose(text: str) -> str:
    """The README as read: images, link targets and code spans dropped, whitespace collapsed."""
    text = re.sub(r"^!\[.*$", "", text, flags=re.MULTILINE)
    text = re.sub(r"\]\([^)]*\)", "]", text)
    text = re.sub(r"`[^`]*`", "CODE", text)
    return re.sub(r"\s+", " ", text)


def phrase(template: str) -> re.Pattern[str]:
    """A README phrase with its numbers written ``{}``: the rest matched literally."""
    parts = re.sub(r"\s+", " ", template).split("{}")
    return re.compile(NUMBER.join(re.escape(p).replace(r"\ ", " ") for p in parts))


def value(printed: str) -> float:
    return float(printed.replace("−", "-").replace("+", ""))


def agrees(printed: str, expected: float, tol: float | None = None) -> bool:
    """``printed`` is ``expected`` rounded to the digits shown (or within ``tol``)."""
    if tol is None:
        decimals = len(printed.split(".")[1]) if "." in printed else 0
        tol = 0.5 * 10.0 ** -decimals + 1e-9
    return abs(value(printed) - expected) <= tol


# --------------------------------------------------------------------------- the sources
@dataclass
class Sources:
    """Where the README's numbers come from, each computed once."""

    @cached_property
    def s(self) -> Any:
        from cell.scenario import load_scenario

        return load_scenario("baseline")

    @cached_property
    def table(self) -> Any:
        from cell.assembly import step_table

        return step_table(self.s)

    @cached_property
    def tl(self) -> Any:
        """The figures' nominal transfer (Fig. 15-21), moves timed on the joints' travel."""
        from cell.figures.motion import joint_travel_min_times, nominal_timeline

        return nominal_timeline(self.table, self.s, joint_travel_min_times(self.table))

    @cached_property
    def rates(self) -> np.ndarray:
        """(N-1, 5) dθ/dt × steps/rad of every move of the nominal transfer (Fig. 17-21)."""
        k = np.asarray(self.s.robot.motors.steps_per_rad)
        return np.diff(self.table.path.q_rad, axis=0) * k / self.tl.dt_s[1:, None]

    @cached_property
    def limits(self) -> np.ndarray:
        """(N-1, 5) maximum step rates at each move's load, linear in the load (§6.1)."""
        m = self.s.robot.motors
        k = np.asarray(m.steps_per_rad)
        no_load, full = np.asarray(m.max_rate_no_load_rad_s), np.asarray(m.max_rate_full_load_rad_s)
        load = self.table.path.load_oz[1:, None]
        return k * (no_load + (full - no_load) * load / m.full_load_oz)

    @cached_property
    def runs(self) -> Any:
        from cell.figures.runs import simulate_runs

        return simulate_runs(self.s)

    @cached_property
    def t71(self) -> pd.DataFrame:
        return pd.read_csv(REPO / "reports" / "table_7_1" / "table_7_1.csv")

    def published(self, measure: str, cycle: float = 22.5872, policy: str = "non-adaptive") -> float:
        """The thesis's figure as the committed report prints it beside ours."""
        t = self.t71
        row = t[(t.policy == policy) & (t.accounting == "thesis") & (t.measure == measure)
                & np.isclose(t.ideal_cycle_s, cycle)]
        assert len(row) == 1, (measure, cycle, policy)
        return float(row["thesis"].iloc[0])

    def regime_rows(self, r: int) -> np.ndarray:
        return self.table.path.regime[1:] == r

    @cached_property
    def k_point(self) -> int:
        return int(np.flatnonzero(self.table.path.regime == 3)[-1])

    @cached_property
    def draws(self) -> np.ndarray:
        """The run's inter-arrival times, as the feeder draws them (Fig. 13-14)."""
        from cell.figures.arrivals import draws

        return draws(self.s, self.s.run.parts)

    @cached_property
    def weibull(self) -> Any:
        a = self.s.arrivals
        return getattr(scipy.stats, a.distribution)(**dict(a.params))

    @cached_property
    def fig22(self) -> dict[str, Any]:
        from cell.figures.tip import belt_speed_at, hand_moves, pick_transfer, tip_speeds, transfer_timeline

        run = self.runs.adaptive
        row = run.parts.iloc[pick_transfer(run)]
        tl = transfer_timeline(self.table, row)
        grasp, _ = hand_moves(self.table)
        hist = run.belts["input"]
        picked = run.parts[run.parts["picked"]]
        return {"row": row, "dt": tl.dt_s[grasp], "speed": tip_speeds(self.table, tl)[grasp - 1],
                "before": belt_speed_at(hist, row["pick_s"] - 1e-6),
                "after": belt_speed_at(hist, row["pick_s"]),
                "lags": (picked["pick_s"] - picked["at_bot_s"]).to_numpy()}


@pytest.fixture(scope="module")
def src() -> Sources:
    return Sources()


# --------------------------------------------------------------------------- the claims
Check = Callable[[Sources, list[str]], Iterable[tuple[Any, ...]]]
CLAIMS: list[tuple[re.Pattern[str], Check]] = []


def claim(template: str) -> Callable[[Check], Check]:
    def register(check: Check) -> Check:
        CLAIMS.append((phrase(template), check))
        return check
    return register


def points(f: Sources) -> dict[str, np.ndarray]:
    p, path = f.s.path, f.table.path
    return {"B": p.bot_in, "F": p.f_in, "G": p.g_in, "K": p.eot_in, "LO": path.xyz_in[path.lo],
            "TD": path.xyz_in[path.td], "base": f.s.cell.robot_base_in}


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


# Fig. 23-24
def _lots(values: pd.Series) -> np.ndarray:
    from cell.figures.runs import LOT

    v = values.to_numpy(dtype=float)
    return np.nanmean(v[: len(v) // LOT * LOT].reshape(-1, LOT), axis=1)


@claim("({}-part lot means {}–{} s; run mean {} s as counted by the thesis, {} %; {} s on the wall "
       "clock, {} %), and the non-adaptive one (robot cycle {} s) is far above it (lot means {}–{} "
       "s). Its mean as the thesis counted is {} s, **{} %**: this matches the thesis's \"{} "
       "percent out of spec\"")
def _fig23(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.figures.runs import LOT

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
    from cell.figures.runs import running_mean

    y = running_mean(f.runs.adaptive.parts["thesis_interval_s"])
    return [(n[0], y[int(value(n[1])) - 1]), (n[2], y[int(value(n[3])) - 1])]


@claim("The non-adaptive one swings between {} and {} s over the first {} parts (thesis count; {} "
       "to {} s on the wall clock) and only slowly drifts to {} s (thesis count) or {} s (wall "
       "clock)")
def _fig24_non_adaptive(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.figures.runs import running_mean

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
    from cell.thesis import TABLE_7_1_CYCLES

    return [(n[0], TABLE_7_1_CYCLES[0]), (n[1], a["ip_thesis"].min()), (n[2], a["ip_thesis"].max()),
            (n[3], a["ip_thesis"].mean()), (n[4], a["ip_wallclock"].mean()),
            (n[5], f.published("ip", policy="adaptive"))]


@claim("gives {} and a cycle {} % short, next to the thesis's \"within {} percent\"")
def _memoryless(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    from cell.thesis import ADAPTIVE_CYCLE_PCT

    summary = f.runs.adaptive.summary
    return [(n[0], summary["ip_thesis_memoryless"]),
            (n[1], -summary["cycle_vs_nominal_memoryless_pct"]), (n[2], ADAPTIVE_CYCLE_PCT)]


@claim("two bands, {}–{} for delivered parts (its doubled denominator) and {}–{} for the {} missed "
       "parts (triangles), mean {} against Table 7.1's {}")
def _fig25_bands(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    d = f.runs.non_adaptive[22.5872].parts
    lost = d["missed_thesis"].to_numpy(dtype=bool)
    ip = d["ip_thesis"].to_numpy(dtype=float)
    assert ip[~lost].min() > ip[lost].max()          # two bands, apart
    return [(n[0], ip[~lost].min()), (n[1], ip[~lost].max()), (n[2], ip[lost].min()),
            (n[3], ip[lost].max()), (n[4], lost.sum()), (n[5], ip.mean()),
            (n[6], f.published("ip"))]


@claim("a delivered part's IP averages {} when the part before it was delivered and {} when it was "
       "lost, and the {} lost parts (no delivery, no IP) are marked on the floor; mean {}")
def _fig25_wall(f: Sources, n: list[str]) -> Iterable[tuple[Any, ...]]:
    d = f.runs.non_adaptive[22.5872].parts
    lost = d["missed"].to_numpy(dtype=bool)
    ip = d["ip_wallclock"].to_numpy(dtype=float)
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


# --------------------------------------------------------------------------- the tests
#: Numbers that are references, not quantities: figures, sections, equations, steps, tables.
REFERENCES = [r"3-D", r"Fig\. \d+(?:–\d+)?", r"§\d+(?:\.\d+)*(?:–\d+(?:\.\d+)*)?", r"[Ee]q\. \d+\.\d+",
              r"step \d+\.\d+", r"Table \d+\.\d+", r"King \(1984\)"]


def matches() -> list[tuple[re.Match[str], Check]]:
    text = prose(README.read_text())
    return [(m, check) for pattern, check in CLAIMS for m in pattern.finditer(text)]


def test_every_claim_is_found_in_the_readme() -> None:
    text = prose(README.read_text())
    missing = [p.pattern for p, _ in CLAIMS if not p.search(text)]
    assert missing == []
    cycles = [value(m[1]) for m, check in matches() if check is _cycle_claims]
    assert sorted(cycles) == sorted(TABLE_7_1_CYCLES[1:])   # Fig. 26-30, one each


def test_every_number_quoted_is_its_source_rounded(src: Sources) -> None:
    wrong = []
    for m, check in matches():
        for printed, expected, *tol in check(src, list(m.groups())):
            if not agrees(printed, float(expected), *tol):
                wrong.append(f"{printed} (should read {float(expected):.6g}) in: {m[0][:90]}")
    assert wrong == []


def test_every_number_in_the_readme_is_checked() -> None:
    text = prose(README.read_text())
    checked = [range(*m.span(g)) for m, _ in matches() for g in range(1, len(m.groups()) + 1)]
    references = [range(*r.span()) for pattern in REFERENCES for r in re.finditer(pattern, text)]

    def covered(span: tuple[int, int]) -> bool:
        return any(span[0] in r for r in checked) or any(span[0] in r for r in references)

    loose = [text[max(n.start() - 40, 0):n.end() + 10] for n in
             re.finditer(r"(?<![\w.])[−+-]?\d+(?:\.\d+)?", text) if not covered(n.span())]
    assert loose == []


def anchors(doc: Path) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces to '-'."""
    heads = [line.lstrip("#").strip().lower() for line in doc.read_text().splitlines()
             if line.startswith("#")]
    return {"".join(c for c in h if c.isalnum() or c in " -_").replace(" ", "-") for h in heads}


def test_links_point_at_pages_and_sections_that_exist() -> None:
    links = re.findall(r"\]\((\.\./docs/[\w.-]+\.md)(?:#([\w-]+))?\)", README.read_text())
    assert len(links) >= 8
    for page, anchor in links:
        path = (README.parent / page).resolve()
        assert path.exists(), page
        if anchor:
            assert anchor in anchors(path), (page, anchor)
    for word in ("SPEC", "shared/"):
        assert word not in README.read_text()
    assert not re.search(r"issue|#\d", prose(README.read_text()), re.IGNORECASE)
