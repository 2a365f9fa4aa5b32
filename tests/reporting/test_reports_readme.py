"""Every number ``reports/README.md`` quotes is true of what it describes, from one table.

Each row of :data:`CLAIMS` is a phrase of the README with its numbers written ``{}`` and, in
order, the values they must read rounded to the digits printed: expressions over the sources of
:func:`sources` (the baseline scenario and its path, the figures' own seven runs of Fig. 22-30,
the committed Table 7.1's published column, docs/sources.md's quote of the thesis's lag).
``None`` marks a number the phrase itself chooses; ``n[i]`` is the phrase's i-th number.  Every
number of the README's prose belongs to a row or is a reference (Fig. 8, §4.2, eq. 6.2).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from cell.reporting.published import ADAPTIVE_CYCLE_PCT, TABLE_7_1_CYCLES

ROOT = Path(__file__).resolve().parents[2]
NUMBER = r"([−+-]?\d+(?:,\d{3})*(?:\.\d+)?)"  # 99,800 too


def prose(text: str) -> str:
    """A page as read: images, link targets and code spans dropped, whitespace collapsed."""
    text = re.sub(r"^!\[.*$", "", text, flags=re.MULTILINE)
    return re.sub(r"\s+", " ", re.sub(r"`[^`]*`", "CODE", re.sub(r"\]\([^)]*\)", "]", text)))


def phrase(template: str) -> re.Pattern[str]:
    """A phrase with its numbers written ``{}`` and ``…`` for prose skipped (a few lines at most)."""
    parts = re.sub(r"\s+", " ", template).split("{}")
    return re.compile(NUMBER.join(r".{0,160}?".join(re.escape(q).replace(r"\ ", " ")
                                                       for q in p.split("…")) for p in parts))


def value(printed: str) -> float:
    return float(printed.replace("−", "-").replace("+", "").replace(",", ""))


def agrees(printed: str, expected: float) -> bool:
    """``printed`` is ``expected`` rounded to the digits shown."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    return abs(value(printed) - expected) <= 0.5 * 10.0 ** -decimals + 1e-9


def sources() -> dict[str, Any]:
    """The names :data:`CLAIMS` reads: ``s`` the scenario, ``p`` its solved path, ``rates`` and
    ``lim`` (N-1, 5) step rates of each move of the nominal transfer and their loaded maxima,
    ``m(r)``/``q(r)`` a regime's moves/points, ``a``/``na(c)`` the adaptive and non-adaptive runs'
    parts, ``pub(measure, cycle, policy)`` the thesis's published figure."""
    from cell.reporting.figures import tip
    from cell.reporting.figures.interarrival import draws
    from cell.reporting.figures.motion import joint_travel_min_times, nominal_timeline
    from cell.reporting.figures.runs import LOT, running_mean, simulate_runs
    from cell.scenario.schema import load_scenario
    from cell.sim.physics_checks import step_table

    s = load_scenario("baseline")
    t = step_table(s)
    p, mo, hand, b = t.path, s.robot.motors, s.robot.hand, s.belts
    tl = nominal_timeline(t, s, joint_travel_min_times(t))
    rates = np.diff(p.q_rad, axis=0) * np.asarray(mo.steps_per_rad) / tl.dt_s[1:, None]
    no_load, full = np.asarray(mo.max_rate_no_load_rad_s), np.asarray(mo.max_rate_full_load_rad_s)
    lim = np.asarray(mo.steps_per_rad) * (no_load + (full - no_load) * p.load_oz[1:, None] / mo.full_load_oz)
    runs = simulate_runs(s)
    a, A = runs.adaptive.parts, runs.adaptive.summary
    x = draws(s, s.run.parts)
    w = getattr(scipy.stats, s.arrivals.distribution)(**dict(s.arrivals.params))
    c_, loc, scale = (s.arrivals.params[k] for k in ("c", "loc", "scale"))
    t71 = pd.read_csv(ROOT / "reports" / "table_7_1" / "table_7_1.csv")
    row = a.iloc[tip.pick_transfer(runs.adaptive)]
    picked = a[a["picked"]]
    grasp, _ = tip.hand_moves(t)
    lag_quote = (ROOT / "docs" / "sources.md").read_text().split("## Fig. 22, the look-ahead lag")[1]

    def na(c: float = 22.5872) -> pd.DataFrame:
        return runs.non_adaptive[c].parts

    def pub(measure: str, cycle: float = 22.5872, policy: str = "non-adaptive") -> float:
        sel = t71[(t71.policy == policy) & (t71.accounting == "thesis") & (t71.measure == measure)
                  & np.isclose(t71.ideal_cycle_s, cycle)]
        return float(sel["thesis"].iloc[0])

    def lost_ip(count: str, c: float = 22.5872) -> tuple[np.ndarray, np.ndarray]:
        """Which parts the non-adaptive run lost, counted the thesis's way or on the wall
        clock, and their IP."""
        missed = na(c)["missed_thesis" if count == "thesis" else "missed"].to_numpy(dtype=bool)
        return missed, na(c)[f"ip_{count}"].to_numpy(dtype=float)

    def lots(v: pd.Series) -> np.ndarray:
        v = v.to_numpy(dtype=float)
        return np.nanmean(v[: len(v) // LOT * LOT].reshape(-1, LOT), axis=1)

    def cycle_row(c: float) -> list[Any]:
        d = na(c)
        return [None, d["missed_thesis"].sum(), pub("parts_missed", c), d["ip_thesis"].mean(),
                pub("ip", c), d["missed"].sum(), np.nanmean(d["ip_wallclock"])]

    names = dict(
        np=np, s=s, t=t, p=p, b=b, hand=hand, tl=tl, rates=rates, lim=lim, runs=runs, a=a, A=A,
        NA=runs.non_adaptive[22.5872].summary, x=x, w=w, c=c_, na=na, pub=pub, lost_ip=lost_ip,
        lots=lots, running=running_mean, cycle_row=cycle_row, LOT=LOT, C=s.controller.nominal_cycle_s,
        xyz=p.xyz_in, deg=np.degrees(p.q_rad), k=int(np.flatnonzero(p.regime == 3)[-1]),
        m=lambda r: p.regime[1:] == r, q=t.regime_rows, ks=scipy.stats.kstest(x, w.cdf),
        mode=loc + scale * ((c_ - 1) / c_) ** (1 / c_), belt=s.path.f_in[0] - s.path.bot_in[0],
        w11=lambda g: hand.l1_in + np.sqrt(max(hand.l2_in ** 2 - (g - hand.g0_in) ** 2 / 2, 0.0)),
        pt=lambda *names: np.concatenate([np.asarray(
            {"B": s.path.bot_in, "F": s.path.f_in, "G": s.path.g_in, "K": s.path.eot_in,
             "LO": p.xyz_in[p.lo], "TD": p.xyz_in[p.td], "base": s.cell.robot_base_in}[n][:2])
            for n in names]),
        radius=lambda r: np.linalg.norm(p.xyz_in[t.regime_rows(r), :2]
                                        - np.asarray(s.cell.robot_base_in[:2]), axis=1),
        row=row, lags=(picked["pick_s"] - picked["at_bot_s"]).to_numpy(),
        before=tip.belt_speed_at(runs.adaptive.belts["input"], row["pick_s"] - 1e-6),
        after=tip.belt_speed_at(runs.adaptive.belts["input"], row["pick_s"]),
        grasp_dt=tip.transfer_timeline(t, row).dt_s[grasp],
        grasp_v=tip.tip_speeds(t, tip.transfer_timeline(t, row))[grasp - 1],
        thesis_lag=float(re.search(r"a lag of ([\d.]+) s", lag_quote)[1]),
        PCT=ADAPTIVE_CYCLE_PCT, CYCLES=TABLE_7_1_CYCLES)
    return names


#: (a phrase of the README, the values of its numbers in order: an expression each, a tuple for
#: a number read as several, None for a number the phrase chooses)
CLAIMS: list[tuple[str, str]] = [
    ("(CODE, seed {}, {} parts)", "s.run.seed, s.run.parts"),
    ("all seven runs see the same {} inter-arrival times", "len(a)"),
    # Fig. 8, 9 and 12
    ("the {} in input belt along y = {} and the output belt along x = {}, the robot's base axis at "
     "({}, {}), B ({}, {}) → F ({}, {}) … G ({}, {}) → K ({}, {}) … LO at ({}, {}) and TD at ({}, {})",
     "s.cell.belt_width_in, s.path.bot_in[1], s.path.g_in[0], *pt('base', 'B', 'F', 'G', 'K', 'LO', 'TD')"),
    ("quarter arc of radius {} in; the R IV return arc (radius {} in) … to x = {} in and y = {} in",
     "radius(2)[0], radius(4)[0], xyz[:, 0].max(), xyz[:, 1].min()"),
    ("R I and R III are {} moves and {} in each ({} in of belt … from z = {} in to {} in at LO and TD), "
     "R II {} moves and {} in at z = {} in, R IV {} moves and {} in at z = {} in; {} points in all",
     "m(1).sum(), t.regime_length(1), belt, s.path.bot_in[2], s.path.pick_height_in, m(2).sum(), "
     "t.regime_length(2), xyz[q(2), 2].max(), m(4).sum(), t.regime_length(4), xyz[q(4), 2].min(), "
     "p.n_points"),
    ("up to the shoulder at {} in", "s.cell.shoulder_height_in"),
    ("the hand is longest, {} in, at G = G0 = {} in; holding the {} in cube it is {} in; at the "
     "assumed {} in open width {} in; it falls to L1 = {} in at G = {} in, … The {} in between",
     "w11(hand.g0_in), hand.g0_in, s.part.size_in, w11(s.part.size_in), hand.open_in, "
     "w11(hand.open_in), hand.l1_in, hand.g0_in + hand.l2_in * np.sqrt(2), "
     "w11(s.part.size_in) - w11(hand.open_in)"),
    # Fig. 13-14
    ("The run's own {} inter-arrival times", "len(x)"),
    ("pdf mean {} s and sd {} s, the draws {} s and {} s, from {} to {} s; … at {} s (the shape {} "
     "… The thesis's mean {} s is the distribution's {} s",
     "w.mean(), w.std(), x.mean(), x.std(ddof=1), x.min(), x.max(), mode, c, C, w.mean()"),
    ("(Kolmogorov–Smirnov D = {}, p = {}); … u = {} → T = {} s (the median)",
     "ks.statistic, ks.pvalue, 0.5, w.median()"),
    # Fig. 15-21
    ("locked to their belts ({} and {} in/s), R IV with the base at its nominal {} % rate, R II the "
     "rest of the {} s ideal cycle. … R I takes {} s rather than {}/{} s",
     "b.input_nominal_in_s, b.output_nominal_in_s, 100 * s.robot.motors.nominal_fraction, C, "
     "tl.regime_s[1], belt, b.input_nominal_in_s"),
    ("R III {} s, R IV {} s (the calibrated nominal), and R II {} s, not the thesis's {} − {}/{} − "
     "{} − {} = {} s",
     "tl.regime_s[3], tl.regime_s[4], tl.regime_s[2], C, belt, b.input_nominal_in_s, "
     "(s.path.eot_in[1] - s.path.g_in[1]) / b.output_nominal_in_s, tl.regime_s[4], "
     "n[3] - n[4] / n[5] - n[6] - n[7]"),
    ("x rises from {} to {} and y from {} to {} over the first {} s; z dips to {} in at LO ({} s) and "
     "TD ({} s). … {} in at K, {} s, … x swings out to {} in and y to {} in",
     "xyz[0, 0], xyz[k, 0], xyz[0, 1], xyz[k, 1], tl.t_s[k], xyz[:, 2].min(), tl.t_s[p.lo], "
     "tl.t_s[p.td], xyz[:, 1].max(), tl.t_s[k], xyz[:, 0].max(), xyz[:, 1].min()"),
    ("θ1 (base) climbs from {}° to {}° … a sharp peak at {} s; the wrist roll θ5 goes {}° → {}° in "
     "R I, holds {}° through R II",
     "deg[:, 0].min(), deg[k, 0], tl.t_s[k], deg[0, 4], deg[np.flatnonzero(p.regime == 1)[-1], 4], "
     "deg[q(2), 4].mean()"),
    ("reaches {}° at K and is turned back to {}° during R IV", "deg[k, 4], deg[-1, 4]"),
    ("the two dips ({}° to {}°) and is constant at {}° from K to B, because R IV stays at z = {} in",
     "deg[:k + 1, 1].min(), deg[:k + 1, 1].max(), deg[k, 1], xyz[q(4), 2].max()"),
    ("Base: {} steps/s through R II, rising to a peak of {} steps/s …below its {} steps/s loaded "
     "maximum) and falling to {} steps/s at K; R IV is a flat {} steps/s, exactly the nominal {} %",
     "rates[m(2), 0][0], rates[m(1) & (np.arange(len(rates)) >= p.lo), 0].max(), lim[p.lo, 0], "
     "rates[k - 1, 0], rates[m(4), 0][0], 100 * s.robot.motors.nominal_fraction"),
    ("loaded maximum of {} steps/s (the red line drops from {} to {} steps/s at LO, when the {} oz part "
     "is picked), and the two single-move spikes to ±{} steps/s",
     "np.abs(rates[p.lo:p.td - 1, 1]).max(), lim[p.lo - 1, 1], lim[p.lo, 1], s.part.weight_oz, "
     "tuple(np.abs(rates[[p.lo - 1, p.td], 1]))"),
    ("Elbow: {} steps/s leaving B, … up to {} steps/s in R III, far below its {}–{} steps/s limits",
     "rates[0, 2], rates[m(3), 2].max(), lim[:, 2].min(), lim[:, 2].max()"),
    ("Wrist pitch: never above {} steps/s against a maximum of {}–{} steps/s",
     "np.abs(rates[:, 3]).max(), lim[:, 3].min(), lim[:, 3].max()"),
    ("Wrist roll: {}–{} steps/s in R I and {}–{} steps/s in R III, zero in R II (the part's {}° turn "
     "… a steady {} steps/s in R IV",
     "rates[m(1), 4].min(), rates[m(1), 4].max(), rates[m(3), 4].min(), rates[m(3), 4].max(), "
     "np.degrees(p.phi_rad[p.td] - p.phi_rad[0]), rates[m(4), 4][0]"),
    # Fig. 22
    ("One adaptive transfer (part {}, the part with the longest lag", "row['part']"),
    ("the look-ahead lag, {} s of tracking B → LO at the current belt speed {} in/s, … (here to {} "
     "in/s). The tip then averages {} (R I), {} (R II), {} (R III, the belt's {} in/s plus the dip) "
     "and {} in/s (R IV)",
     "row['pick_s'] - row['at_bot_s'], before, after, row['v_r1_in_s'], row['v_r2_in_s'], "
     "row['v_r3_in_s'], b.output_nominal_in_s, row['v_r4_in_s']"),
    ("so each lasts {} s at {} in/s", "grasp_dt, grasp_v"),
    ("its example lag is {} s", "thesis_lag"),
    ("the lag is B → LO ({} in) over the belt speed, {}–{} s over all {} parts. A {} s lag would need "
     "LO about {} in from B at {} in/s",
     "s.path.lo_from_bot_in, lags.min(), lags.max(), len(a), None, n[4] * b.input_nominal_in_s, "
     "b.input_nominal_in_s"),
    # Fig. 23-24
    ("({}-part lot means {}–{} s; run mean {} s as counted by the thesis, {} %; {} s on the wall "
     "clock, {} %), and the non-adaptive one (robot cycle {} s) … (lot means {}–{} s). Its mean as "
     "the thesis counted is {} s, **{} %**: this matches the thesis's \"{} percent out of spec\"",
     "LOT, lots(a.thesis_interval_s).min(), lots(a.thesis_interval_s).max(), a.thesis_interval_s.mean(), "
     "100 * (a.thesis_interval_s.mean() / C - 1), a.delivery_interval_s.mean(), "
     "100 * (a.delivery_interval_s.mean() / C - 1), C, lots(na().thesis_interval_s).min(), "
     "lots(na().thesis_interval_s).max(), na().thesis_interval_s.mean(), "
     "*[100 * (na().thesis_interval_s.mean() / C - 1)] * 2"),
    ("That mean is over all {} parts, … by the {} parts delivered and reads {} s",
     "len(na()), len(na()) - na().missed_thesis.sum(), NA['actual_cycle_thesis_s']"),
    ("The thesis's \"{} percent reduction in throughput\" is {}/{} lost parts",
     "100 * pub('parts_missed') / s.run.parts, pub('parts_missed'), s.run.parts"),
    ("the non-adaptive robot loses {} parts (the thesis's bookkeeping: {}) and averages {} s, {} %",
     "NA['parts_missed'], NA['parts_missed_thesis'], np.nanmean(na().delivery_interval_s), "
     "100 * (np.nanmean(na().delivery_interval_s) / C - 1)"),
    ("the adaptive one (thesis count) reads {} s after {} parts and {} s after {}",
     "running(a.thesis_interval_s)[int(n[1]) - 1], None, running(a.thesis_interval_s)[int(n[3]) - 1], None"),
    ("The non-adaptive one swings between {} and {} s over the first {} parts (thesis count; {} to "
     "{} s on the wall clock) and only slowly drifts to {} s (thesis count) or {} s (wall clock)",
     "np.nanmin(running(na().thesis_interval_s)[:int(n[2])]), "
     "np.nanmax(running(na().thesis_interval_s)[:int(n[2])]), None, "
     "np.nanmin(running(na().delivery_interval_s)[:int(n[2])]), "
     "np.nanmax(running(na().delivery_interval_s)[:int(n[2])]), "
     "running(na().thesis_interval_s)[-1], running(na().delivery_interval_s)[-1]"),
    # Fig. 25-30
    ("Robot cycle {} s. Adaptive IP stays in a band ({}–{}, mean {} as the thesis counted, {} on the "
     "wall clock; the thesis reports {};",
     "CYCLES[0], a.ip_thesis.min(), a.ip_thesis.max(), a.ip_thesis.mean(), a.ip_wallclock.mean(), "
     "pub('ip', policy='adaptive')"),
    ("gives {} and a cycle {} % short, next to the thesis's \"within {} percent\"",
     "A['ip_thesis_memoryless'], -A['cycle_vs_nominal_memoryless_pct'], PCT"),
    ("two bands, {}–{} for delivered parts … and {}–{} for the {} missed parts (triangles), mean {} "
     "against Table 7.1's {}",
     "*(lambda lost, ip: [ip[~lost].min(), ip[~lost].max(), ip[lost].min(), ip[lost].max(), "
     "lost.sum(), ip.mean()])(*lost_ip('thesis')), pub('ip')"),
    ("a delivered part's IP averages {} when the part before it was delivered and {} when it was "
     "lost, and the {} lost parts … mean {}",
     "*(lambda lost, ip, after: [np.nanmean(ip[~lost & ~after]), np.nanmean(ip[~lost & after]), "
     "lost.sum(), np.nanmean(ip)])(*lost_ip('wallclock'), np.r_[False, lost_ip('wallclock')[0][:-1]])"),
    ("Robot cycle {} s: {} parts missed as the thesis counted (Table 7.1: {}), mean IP {} (Table "
     "7.1: {}); on the wall clock {} lost, mean IP {}", "*cycle_row(n[0])"),
    ("Robot cycle {} s: {} missed as the thesis counted (Table 7.1: {}), IP {} (Table 7.1: {}); on "
     "the wall clock {} lost, IP {}", "*cycle_row(n[0])"),
    ("Robot cycle {} s, the minimum feasible: {} missed as the thesis counted (Table 7.1: {}), IP {} "
     "(Table 7.1: {}); on the wall clock {} lost, IP {}", "*cycle_row(n[0])"),
]
#: Numbers that are references, not quantities: figures, sections, equations, steps, tables.
REFERENCES = [r"3-D", r"Fig\. \d+(?:–\d+)?", r"§\d+(?:\.\d+)*(?:–\d+(?:\.\d+)*)?", r"[Ee]q\. \d+\.\d+",
              r"step \d+\.\d+", r"Table \d+\.\d+", r"King \(1984\)"]
TEXT = prose((ROOT / "reports" / "README.md").read_text(encoding="utf-8"))
MATCHES = [(m, row) for template, row in CLAIMS for m in phrase(template).finditer(TEXT)]


@pytest.fixture(scope="module")
def src() -> dict[str, Any]:
    return sources()


def test_every_claim_is_in_the_readme_and_each_cycle_has_its_figure() -> None:
    assert [t for t, _ in CLAIMS if not phrase(t).search(TEXT)] == []
    cycles = [value(m[1]) for m, row in MATCHES if row == "*cycle_row(n[0])"]
    assert sorted(cycles) == sorted(TABLE_7_1_CYCLES[1:])   # Fig. 26-30, one each


def test_every_number_quoted_is_its_source_rounded(src: dict[str, Any]) -> None:
    wrong = []
    for m, row in MATCHES:
        expected = eval(f"[{row}]", {**src, "n": [value(g) for g in m.groups()]})  # noqa: S307
        for printed, want in zip(m.groups(), expected, strict=True):
            for w in want if isinstance(want, tuple) else () if want is None else (want,):
                if not agrees(printed, float(w)):
                    wrong.append(f"{printed} (should read {float(w):.6g}) in: {m[0][:90]}")
    assert wrong == []


def test_every_number_in_the_readme_is_checked() -> None:
    checked = [range(*m.span(g)) for m, _ in MATCHES for g in range(1, len(m.groups()) + 1)]
    checked += [range(*r.span()) for pattern in REFERENCES for r in re.finditer(pattern, TEXT)]
    loose = [TEXT[max(n.start() - 40, 0):n.end() + 10] for n in re.finditer(
        r"(?<![\w.])[−+-]?\d+(?:\.\d+)?", TEXT) if not any(n.start() in r for r in checked)]
    assert loose == []


def test_what_the_readings_rest_on_holds(src: dict[str, Any]) -> None:
    """The shapes the prose describes that no other test holds (the arcs' radii, R II's and R IV's
    still joints and the rates' limits are tests/arm/test_path.py's and test_figures.py's): R I
    and R III alike, y's peak at K, the base's flat rates (R IV at its nominal fraction), the
    Weibull's mode right of its mean, two bands of thesis IP, no wall-clock IP for a lost part,
    the summary's cycles the parts' own."""
    t, p, rates, lim, k, m = (src[n] for n in ("t", "p", "rates", "lim", "k", "m"))
    assert m(1).sum() == m(3).sum() and t.regime_length(1) == pytest.approx(t.regime_length(3))
    assert p.xyz_in[: k + 1, 1].max() == p.xyz_in[k, 1] and rates[0, 2] == rates[m(1), 2].min()
    assert np.ptp(rates[m(2), 0]) < 1e-6 and np.ptp(rates[m(4), 0]) < 1e-6 and np.ptp(rates[m(4), 4]) < 1e-6
    fraction = src["s"].robot.motors.nominal_fraction
    assert -rates[m(4), 0][0] == pytest.approx(fraction * lim[m(4), 0][0], rel=1e-3)
    assert src["mode"] > src["w"].mean()
    lost, ip = src["lost_ip"]("thesis")
    assert ip[~lost].min() > ip[lost].max()
    lost, ip = src["lost_ip"]("wallclock")
    assert np.all(np.isnan(ip[lost]))
    d, summary = src["na"](), src["NA"]
    assert summary["actual_cycle_wallclock_s"] == pytest.approx(np.nanmean(d["delivery_interval_s"]))
    assert summary["actual_cycle_thesis_s"] == pytest.approx(
        d["thesis_interval_s"].sum() / (len(d) - d["missed_thesis"].sum()))
