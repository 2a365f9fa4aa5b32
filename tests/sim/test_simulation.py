"""Whole runs (cell.sim.simulation, ``cell run``): docs/model.md facts, invariants, hostile input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.scenario import catalog
from cell.scenario.schema import default_scenario, load_scenario
from cell.sim.assembly import assemble
from cell.sim.records import LET_GO, PART_COLUMNS, SUMMARY_COLUMNS, Part, PartRecord
from cell.sim.simulation import RunLog, simulate

BASELINE = catalog.path("baseline")
NON_ADAPTIVE = catalog.path("non_adaptive")


@pytest.fixture(scope="module")
def adaptive():
    return simulate(load_scenario(BASELINE))


@pytest.fixture(scope="module")
def fixed():
    return simulate(load_scenario(NON_ADAPTIVE))


def test_issue_columns_are_present(adaptive):
    required_parts = ["part", "arrival_s", "interarrival_s", "picked", "missed", "pick_s",
                      "touchdown_s", "delivery_interval_s", "motion_cycle_s", "ip_wallclock",
                      "ip_thesis", "input_speed_in_s", "output_speed_in_s", "spacing_in",
                      "v_r1_in_s", "v_r2_in_s", "v_r3_in_s", "v_r4_in_s"]
    required_summary = ["policy", "ideal_cycle_s", "parts_arrived", "parts_delivered",
                        "parts_missed", "actual_cycle_wallclock_s", "actual_cycle_thesis_s",
                        "parts_per_hr_wallclock", "parts_per_hr_thesis", "vavg_r4_in_s",
                        "ip_wallclock", "ip_thesis", "spacing_min_in", "spacing_max_in"]
    assert set(required_parts) <= set(adaptive.parts.columns) == set(PART_COLUMNS)
    assert set(required_summary) <= set(adaptive.summary.as_dict()) == set(SUMMARY_COLUMNS)
    assert len(adaptive.parts) == 500


def test_adaptive_baseline_loses_nothing_and_spaces_parts_45_in(adaptive):
    p, s = adaptive.parts, adaptive.summary
    assert s["parts_missed"] == 0 and s["parts_delivered"] == 500           # §7.2
    sp = p["spacing_in"].dropna()
    assert len(sp) == 499
    assert ((sp - 45.0).abs() <= 0.25).all()                                # §4.3 f
    # every delivered part was picked after it reached B and set down after
    assert (p["pick_s"] > p["at_bot_s"]).all() and (p["touchdown_s"] > p["pick_s"]).all()
    # the thesis's accounting lands near its published figures (printed, not equal)
    assert 0.95 < s["ip_thesis"] < 1.05
    assert abs(s["cycle_vs_nominal_pct"]) < 5


def test_adaptive_never_exceeds_motor_or_belt_limits(adaptive):
    s = load_scenario(BASELINE)
    from cell.sim.timing_cache import robot_timing

    t = robot_timing(s)
    p = adaptive.parts
    assert (p["v_r4_in_s"] <= t.r4.length_in / t.r4_min_s + 1e-9).all()
    assert (p["v_r2_in_s"] <= t.r2.length_in / t.r2_min_s + 1e-9).all()
    assert (p["input_speed_in_s"] <= t.input_track_max_in_s + 1e-9).all()
    speeds = [v for _, v in adaptive.belts["input"]]
    assert 0 < min(speeds) and max(speeds) <= s.belts.input_max_in_s
    out = [v for _, v in adaptive.belts["output"]]
    assert 0 < min(out) and max(out) <= s.belts.output_max_in_s
    # robot cycles never overlap: each starts after the previous one ended
    start = p["at_bot_s"].to_numpy()
    assert (start[1:] >= start[:-1] + p["motion_cycle_s"].to_numpy()[:-1] - 1e-6).all()


def assert_conserved(summary, parts) -> None:
    """Exactly: arrived = delivered + missed + in the cell, each counted from the part records
    (delivered: set down; missed: let go; in the cell: picked, not yet set down)."""
    delivered = int(np.isfinite(parts["touchdown_s"].to_numpy(dtype=float)).sum())
    missed = int(parts["missed"].sum())
    in_cell = int((parts["picked"] & ~np.isfinite(parts["touchdown_s"].to_numpy(dtype=float))).sum())
    assert (summary["parts_delivered"], summary["parts_missed"], summary["parts_in_cell"]) == \
        (delivered, missed, in_cell)
    assert summary["parts_arrived"] == len(parts) == delivered + missed + in_cell


def test_non_adaptive_loses_what_the_physics_says(fixed):
    p, s = fixed.parts, fixed.summary
    assert s["parts_arrived"] == 500
    assert_conserved(s, p)
    # lost iff the part reached B before the robot was back (§6.3)
    free_at = 0.0
    for at_bot, picked, cycle in zip(p["at_bot_s"], p["picked"], p["motion_cycle_s"]):
        assert picked == (at_bot >= free_at - 1e-6)
        if picked:
            free_at = at_bot + cycle
    np.testing.assert_allclose(p.loc[p.picked, "motion_cycle_s"], 22.5872, atol=1e-9)
    # the thesis's bookkeeping is computed from the same draws beside it
    assert s["parts_missed_thesis"] == int(p["missed_thesis"].sum())
    assert s["parts_missed_thesis"] > s["parts_missed"]


def test_non_adaptive_loss_rate_matches_spec_8():
    s = load_scenario(NON_ADAPTIVE)
    lost = [simulate(s, seed=seed).summary["parts_missed"] for seed in range(12)]
    assert np.mean(lost) == pytest.approx(162, abs=10)        # docs/accounting.md: about 162 of 500
    shortest = s.with_overrides({"controller.ideal_cycle_s": 20.0907})
    lost = [simulate(shortest, seed=seed).summary["parts_missed"] for seed in range(12)]
    assert np.mean(lost) == pytest.approx(10, abs=4)          # docs/accounting.md: about 10


def test_conservation_over_seeds_and_cycles():
    base = default_scenario().with_overrides({"run.parts": 120})
    for policy in ("adaptive", "non-adaptive"):
        for seed in range(4):
            r = simulate(base.with_overrides({"controller.policy": policy}), seed=seed)
            assert_conserved(r.summary, r.parts)


def test_same_seed_gives_byte_identical_csvs(tmp_path, capsys):
    for out in ("a", "b"):
        assert main(["run", str(BASELINE), "--set", "run.parts=80", "--out",
                     str(tmp_path / out)]) == 0
    for name in ("parts.csv", "summary.csv"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    text = capsys.readouterr().out
    assert "1.0214" not in text and "only beside a run of its own scenario" in text
    frame = pd.read_csv(tmp_path / "a" / "parts.csv", keep_default_na=False)
    assert list(frame.columns) == PART_COLUMNS and len(frame) == 80


def test_the_thesis_figures_are_printed_beside_the_thesis_run_only(tmp_path, capsys):
    assert main(["run", "baseline", "--out", str(tmp_path / "a")]) == 0
    text = capsys.readouterr().out
    assert "(thesis: 1.0214)" in text and "within 2.1 %" in text
    assert main(["run", "non_adaptive", "--set", "controller.ideal_cycle_s=21.0",
                 "--out", str(tmp_path / "b")]) == 0
    text = capsys.readouterr().out
    assert "(thesis: 25.8622)" in text and "(thesis: 35)" in text      # Table 7.1, 21.0 s row
    assert main(["run", "baseline", "--set", "belts.output_nominal_in_s=2.5",
                 "--out", str(tmp_path / "c")]) == 0
    assert "(thesis:" not in capsys.readouterr().out


def test_the_thesis_figures_of_each_table_7_1_row_are_that_row():
    from cell.reporting.published import TABLE_7_1
    from cell.reporting.run_summary import thesis_figures

    base = load_scenario("baseline", {"controller.policy": "non-adaptive"})
    for cycle, (actual, missed, per_hr, vavg, ip) in TABLE_7_1.items():
        shown = thesis_figures(base.with_overrides({"controller.ideal_cycle_s": cycle}))
        assert shown == {"parts_missed_thesis": f"{missed}", "actual_cycle_thesis_s": f"{actual:.4f}",
                         "parts_per_hr_thesis": f"{per_hr:.4f}", "vavg_r4_in_s": f"{vavg:.4f}",
                         "ip_thesis": f"{ip:.4f}"}
    assert thesis_figures(base.with_overrides({"controller.ideal_cycle_s": 21.25})) is None


def test_other_seed_other_parts(tmp_path):
    s = default_scenario().with_overrides({"run.parts": 30})
    a = simulate(s, seed=1).parts["interarrival_s"]
    b = simulate(s, seed=2).parts["interarrival_s"]
    assert not np.array_equal(a, b)


def _hostile(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "hostile.yaml"
    path.write_text(text)
    return path


HOSTILE = {
    "unknown key": ("belts:\n  speed_in_s: 3.0\n", "belts.speed_in_s", "3.0"),
    "wrong type": ("run:\n  parts: many\n", "run.parts", "'many'"),
    "negative speed": ("belts:\n  input_nominal_in_s: -3.0\n", "belts.input_nominal_in_s",
                       "-3.0"),
    "zero speed": ("belts:\n  output_nominal_in_s: 0\n", "belts.output_nominal_in_s", "0"),
    "no parts": ("run:\n  parts: 0\n", "run.parts", "0"),
    "no such distribution": ("arrivals:\n  distribution: weibull_maxx\n",
                             "arrivals.distribution", "weibull_maxx"),
    "missing trace": ("arrivals:\n  trace_csv: nowhere.csv\n", "arrivals.trace_csv",
                      "nowhere.csv"),
    "negative trace": ("arrivals:\n  trace_csv: trace.csv\n", "arrivals.trace_csv",
                       "trace.csv"),
    "cycle too short": ("controller:\n  policy: non-adaptive\n  ideal_cycle_s: 19.5\n",
                        "controller.ideal_cycle_s", "19.5"),
}


@pytest.fixture
def short_tmp():
    """A folder with a short name: a value the message shows (the trace's full path) is cut
    at 80 characters, and pytest-xdist's tmp_path is longer than that on its own."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="cell-") as tmp:
        yield Path(tmp)


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_scenario_one_line_exit_2_nothing_written(short_tmp, capsys, case):
    tmp_path = short_tmp
    text, key, value = HOSTILE[case]
    (tmp_path / "trace.csv").write_text("interarrival_s\n22.0\n-4.0\n21.0\n")
    path = _hostile(tmp_path, text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert str(path) in err and key in err and value in err
    assert not out.exists()


def test_hostile_override_on_the_command_line(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(BASELINE), "--set", "belts.input_max_in_s=0",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "belts.input_max_in_s" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_minimum_time_robot_takes_its_fastest_r4_from_the_planner():
    from cell.arm.mintime.regimes import fastest_regime_times
    from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

    s = default_scenario().with_overrides({"robot.timing": "minimum-time", "run.parts": 60})
    fastest = fastest_regime_times(geometry_of(s), motors_of(s), planner_bounds(s))
    r = simulate(s)
    t_r4 = r.parts["v_r4_in_s"].rdiv(35.5424)          # R IV times (docs/model.md length)
    assert (t_r4 >= fastest["R4"] - 1e-3).all()
    fixed = s.with_overrides({"controller.policy": "non-adaptive",
                              "controller.ideal_cycle_s": 22.5872 - (9.9855 - fastest["R4"])
                              - 0.01})
    from cell.plumbing.errors import ScenarioError
    with pytest.raises(ScenarioError, match="controller.ideal_cycle_s"):
        simulate(fixed)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), policy=st.sampled_from(["adaptive", "non-adaptive"]),
       ideal=st.floats(20.1, 24.0), input_max=st.floats(3.0, 12.0))
def test_invariants_hold_for_any_seed(seed, policy, ideal, input_max):
    s = default_scenario().with_overrides({
        "run.parts": 40, "controller.policy": policy, "belts.input_max_in_s": input_max,
        "controller.ideal_cycle_s": ideal if policy == "non-adaptive" else None})
    r = simulate(s, seed=seed)
    p, sm = r.parts, r.summary
    assert_conserved(sm, p)
    done = p[p.picked]
    assert (done["pick_s"] >= done["at_bot_s"]).all()
    assert (done["touchdown_s"] > done["pick_s"]).all()
    assert (p["missed"] == ~p["picked"]).all()
    if policy == "adaptive":
        clean = ~p["limits"].str.contains("output_")
        sp = p.loc[clean, "spacing_in"].dropna()
        assert ((sp - 45.0).abs() <= 0.25 + 1e-9).all()
        assert max(v for _, v in r.belts["input"]) <= input_max + 1e-12


# --------------------------------------------------------------------------- to the bit
def _bits(values) -> list[str]:
    return [f"{v:.17g}" if isinstance(v, float) else repr(v) for v in values]


@pytest.mark.parametrize("family, params", [
    ("weibull_min", {"c": 1 / 0.2038, "loc": 17.6019, "scale": 5.4342}),       # eq. 6.9
    ("weibull_min", {"c": 0.7, "scale": 20.0}),
    ("weibull_min", {"c": 11.0, "loc": 2.5, "scale": 0.25}),
    ("expon", {"loc": 5.0, "scale": 17.0}),
    ("expon", {}),
])
def test_closed_form_draws_are_scipys_inverse_cdf_to_the_bit(family, params):
    import scipy.stats

    from cell.scenario.arrivals import closed_form_ppf, stream

    for seed in range(4):
        u = stream(seed, 0).random(250_000)
        ours = closed_form_ppf(family, params, u)
        theirs = np.asarray(getattr(scipy.stats, family)(**params).ppf(u), dtype=float)
        assert np.array_equal(ours.view(np.int64), theirs.view(np.int64))


def test_log1p_is_scipys_to_the_bit_at_the_branch_edges():
    import scipy.special

    from cell.scenario.arrivals import log1p_as_scipy

    edge = np.sqrt(0.5) - 1.0
    x = np.concatenate([np.nextafter(edge, -1) - np.arange(50) * 1e-17,
                        edge + np.arange(-50, 50) * 1e-17, -np.geomspace(1e-300, 0.999, 2000),
                        np.linspace(-0.9999999, 0.4, 20001), [0.0, -0.0]])
    assert np.array_equal(log1p_as_scipy(x).view(np.int64), scipy.special.log1p(x).view(np.int64))


def test_kept_and_streamed_runs_give_the_same_rows():
    s = default_scenario().with_overrides({"run.parts": 400})
    kept = simulate(s, seed=3)
    streamed_parts, streamed_belts = [], []
    streamed = simulate(s, seed=3, keep_parts=False, keep_belts=False,
                        on_part=lambda r: streamed_parts.append(_bits(
                            getattr(r, c) for c in PART_COLUMNS)),
                        on_belt=streamed_belts.append)
    assert streamed.records is None and streamed.belt_changes == []
    assert [_bits(getattr(r, c) for c in PART_COLUMNS) for r in kept.records] == streamed_parts
    assert sorted(kept.belt_changes, key=lambda c: (c.belt, c.from_s)) == \
        sorted(streamed_belts, key=lambda c: (c.belt, c.from_s))
    assert _bits(getattr(kept.summary, c) for c in SUMMARY_COLUMNS) == \
        _bits(getattr(streamed.summary, c) for c in SUMMARY_COLUMNS)
    frame = kept.parts
    assert list(frame.columns) == PART_COLUMNS and len(frame) == 400


def test_summary_counts_the_parts_that_name_each_limit():
    from cell.sim.records import LIMIT_COUNTS, LIMITS

    s = default_scenario().with_overrides({"arrivals.distribution": "gamma", "arrivals.mean_s": 21.0,
                                           "arrivals.cv": 1.0, "run.parts": 300})
    r = simulate(s, seed=7)
    named = [set(names.split()) for names in r.parts["limits"].fillna("")]
    counts = {}
    for name, counted in LIMIT_COUNTS.items():
        assert name in LIMITS and counted.field in SUMMARY_COLUMNS
        counts[counted.field] = sum(name in n for n in named)
        assert r.summary[counted.field] == counts[counted.field], name
    assert sum(v > 0 for v in counts.values()) >= 4   # the run hits several limits


def _reference_non_adaptive(s, seed):
    """The non-adaptive cell as a plain loop, no SimPy: belts never change speed, so a part
    reaches B when the belt has carried it the belt's length, the robot takes it if it is
    back, sets it down B → TD later.  Each instant is computed with the same float
    operations as the simulation's (a belt's time for a travel is t₀ + (x − x₀)/v, a
    delay is added to the instant it is measured from)."""
    from cell.scenario.arrivals import interarrival_times
    from cell.sim.accounting import THESIS_SLACK_S
    from cell.sim.assembly import assemble
    from cell.sim.records import R4_PEAK, SPACING_OFF, limit_names

    cell = assemble(s)
    k, plan, c = cell.k, cell.policy.cycle, cell.policy.ideal_cycle_s
    n = s.run.parts
    t = interarrival_times(s.arrivals, n + 1, seed)
    fed = np.cumsum(t).tolist()
    t = t.tolist()
    v, u, length = k.v_nom, k.u_nom, k.input_length
    tm = k.timing
    r1, r3 = plan.r1_pre + plan.r1_post, plan.r3_pre + plan.r3_post
    to_td = plan.r1_pre + (plan.to_g - plan.r1_pre + plan.r3_pre)
    free_at, at_bot, last_x, last_td, clear = 0.0, -np.inf, None, None, -np.inf
    out = []
    for i in range(n):
        x = 0.0 + v * (fed[i] - 0.0)
        assert x >= clear - 1e-9                       # never held on these arrivals
        clear = x + k.part_size
        now = max(fed[i], at_bot)                      # the conveyor times it from here
        delay = max((0.0 + (x + length - 0.0) / v) - now, 0.0)
        at_bot = now + delay
        p = {c: np.nan for c in PART_COLUMNS}
        p.update(part=i + 1, arrival_s=fed[i], interarrival_s=t[i], at_bot_s=at_bot,
                 picked=False, missed=False, feed_delay_s=0.0)
        flags = 0
        if free_at <= at_bot + 1e-6:
            free_at = at_bot + plan.cycle
            p.update(picked=True, motion_cycle_s=plan.cycle, input_speed_in_s=plan.input_speed,
                     output_speed_in_s=plan.output_to_g, r1_s=r1, r2_s=plan.r2, r3_s=r3,
                     r4_s=plan.r4, v_r1_in_s=tm.r1_length_in / r1,
                     v_r2_in_s=tm.r2.length_in / plan.r2, v_r3_in_s=tm.r3_length_in / r3,
                     v_r4_in_s=tm.r4.length_in / plan.r4, pick_s=at_bot + plan.r1_pre)
            p["touchdown_s"] = td = at_bot + to_td
            x_td = 0.0 + u * (td - 0.0)
            if last_x is not None:
                p["spacing_in"], p["delivery_interval_s"] = x_td - last_x, td - last_td
            last_x, last_td = x_td, td
            flags |= R4_PEAK if plan.limits else 0
        else:
            p["missed"], flags = True, LET_GO
        p["ip_wallclock"] = t[i + 1] / p["delivery_interval_s"]
        lost = t[i] < c - THESIS_SLACK_S
        p["missed_thesis"], p["thesis_interval_s"] = lost, t[i] + c if lost else t[i]
        p["ip_thesis"] = t[i + 1] / (2.0 * p["thesis_interval_s"])
        sp = p["spacing_in"]
        if sp == sp and abs(sp - k.spacing) > k.tol + 1e-9:
            flags |= SPACING_OFF
        p["limits"] = limit_names(flags) if flags else ""
        out.append(PartRecord(**p))
    return out


@pytest.mark.parametrize("ideal, seed", [(22.5872, 1), (21.0, 2), (20.0907, 3)])
def test_non_adaptive_run_is_the_plain_reference_to_the_bit(ideal, seed):
    s = load_scenario(NON_ADAPTIVE, {"run.parts": 1500, "controller.ideal_cycle_s": ideal})
    ours = simulate(s, seed=seed).records
    ref = _reference_non_adaptive(s, seed)
    assert len(ours) == len(ref) == 1500
    for a, b in zip(ours, ref):
        assert _bits(getattr(a, c) for c in PART_COLUMNS) == \
            _bits(getattr(b, c) for c in PART_COLUMNS), a.part


@settings(max_examples=40, deadline=None)
@given(st.permutations(list(range(1, 9))))
def test_the_run_log_hands_parts_on_in_part_order_whatever_order_they_finish(finish_order):
    policy = assemble(default_scenario()).policy
    handed: list[int] = []
    log = RunLog([20.0] * 9, policy.accounting(), lambda p: handed.append(p.part), 45.0, 0.25)
    done: set[int] = set()
    for i in finish_order:
        part = Part(i - 1, float(i))
        log.flag(part, LET_GO)
        log.missed(part)
        done.add(i)
        ready = 0  # every part up to the first not yet done has been handed on, no other
        while ready + 1 in done:
            ready += 1
        assert handed == list(range(1, ready + 1))
    assert log.handed_on == 8  # each part's PER_PART values, once
    assert log.column("part").tolist() == list(range(8))
    assert log.column("picked").tolist() == [0.0] * 8  # all let go


@pytest.mark.parametrize("policy", ["adaptive", "non-adaptive"])
def test_parts_in_cell_are_the_parts_come_but_not_done_when_the_run_ends(policy):
    """``run.hours`` stops the run sharp: the parts on the belt or in the hand then are
    ``parts_in_cell``, the parts that came less the rows (every part done has its row)."""
    s = default_scenario().with_overrides({"run.hours": 0.25, "controller.policy": policy})
    r = simulate(s, seed=2)
    assert r.summary.parts_in_cell == r.summary.parts_arrived - len(r.records) >= 1
    assert r.summary.parts_arrived == r.summary.parts_delivered + r.summary.parts_missed + \
        r.summary.parts_in_cell
