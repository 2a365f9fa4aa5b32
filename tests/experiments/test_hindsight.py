"""The hindsight optimum (docs/model.md, "The hindsight optimum"): the MILP's proved bound sits
above every controller and below ``parts_bound``, the schedule found by search through the
simulation below the MILP, and a burst where the bound is loose has its optimum by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.experiments.hindsight.milp import check_cycle_s, solve
from cell.experiments.hindsight.optimum import hindsight
from cell.sim.assembly import assemble
from cell.sim.bound import parts_bound
from cell.sim.simulation import simulate
from tests.traces import trace_scenario


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("traces")


#: A burst: ten parts in the same instant, 5 s into the run.
BURST = [5.0] + [0.0] * 9


def test_a_burst_of_ten_parts_has_optimum_one_and_the_one_belt_bound_one(folder: Path) -> None:
    """By hand, in the baseline cell (input belt 1.5 to 12 in/s, 3.0 nominal; L = 135.516 in
    from the feeder to B; parts 2 in; the shortest cycle a plan may have 17.566 s, the bound's
    16.63 s).  The feeder drops the ten parts a part's size apart, each as the belt has carried
    the last 2 in clear: part i is 2 i in behind part 0, whatever the belt does.
    The windows alone: every window opens at 5 + L / 12 = 16.29 s; part i's closes at
    5 + 2 i / 1.5 + L / 1.5 = 95.34 + 1.33 i s.  Picks 16.63 s apart from 16.29: 16.29, 32.92,
    49.55, 66.18, 82.81 (parts 0-4) and 99.44 <= 95.34 + 6.67 (part 5); part 6 at 116.07 is past
    every later window's end (at most 95.34 + 12.0): 6.  parts_bound counts the one belt: part 9
    is 18 in behind part 0, 12 s at the floor, less than a cycle: 1.
    Optimum: part 0 reaches B with the robot free (at 5 + L / 3, the belt untouched so far) and
    is picked.  The next pick is at least 17.566 s later; by then the belt, at 1.5 in/s at
    least, has carried 26.3 in past B, more than the 18 in to part 9: parts 1-9 all reach B
    while the robot is away.  1."""
    s = trace_scenario(folder, BURST)
    out = hindsight(s, budget_s=20.0).summary
    assert out["parts_bound"] == 1
    assert parts_bound(assemble(s).k, np.cumsum(BURST), one_belt=False) == 6
    assert out["parts_upper"] == 1 and out["milp_status"] == "optimal"
    assert out["parts_optimum"] == 1 and out["exact"]
    assert 17.56 < check_cycle_s(assemble(s).k) < 17.57
    # every controller is at or below it, the adaptive and the fixed cycle alike
    for policy in ("adaptive", "non-adaptive"):
        assert simulate(trace_scenario(folder, BURST, policy)).summary.parts_delivered <= 1


def test_a_part_of_the_burst_after_a_gap_the_belt_can_make_is_caught(folder: Path) -> None:
    """Two bursts of three, 60 s apart: the second's parts are 2 in apart again, so at most one
    of each burst, and the belt (1.5 to 12 in/s) can bring the second burst's first part to B
    17.566 s after the first pick: 2.  The MILP proves it and a simulated schedule reaches it."""
    gaps = [5.0, 0.0, 0.0, 60.0, 0.0, 0.0]
    out = hindsight(trace_scenario(folder, gaps), budget_s=20.0).summary
    assert (out["parts_upper"], out["parts_optimum"], out["exact"]) == (2, 2, True)


gap = st.one_of(st.just(0.0), st.floats(0.5, 45.0), st.floats(15.0, 30.0))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gaps=st.lists(gap, min_size=8, max_size=12).filter(lambda g: sum(g) > 1.0))
def test_controllers_sit_below_the_milp_and_the_milp_below_the_bound(folder: Path,
                                                                     gaps: list[float]) -> None:
    """On drawn traces of 8-12 parts, bursts among them: every built-in controller's count (the
    real simulation, the same trace) <= the MILP's proved optimum <= parts_bound <= the windows
    alone (the bound before it counted the one belt), and the search's simulated schedule <= the
    MILP's optimum."""
    s = trace_scenario(folder, gaps)
    out = hindsight(s, budget_s=20.0).summary
    assert out["milp_status"] == "optimal"
    upper = out["parts_upper"]
    assert out["parts_bound"] <= parts_bound(assemble(s).k, np.cumsum(gaps), one_belt=False)
    for policy in ("adaptive", "non-adaptive"):
        run = simulate(trace_scenario(folder, gaps, policy)).summary
        assert run.parts_delivered <= upper <= run.parts_bound == out["parts_bound"]
        assert run.parts_delivered <= out["parts_optimum"]  # its own run is a schedule too
    assert out["parts_optimum"] <= upper
    assert out["exact"] == (out["parts_optimum"] == upper)


def test_a_pick_is_a_cycle_at_its_own_tracking_speed_from_the_next(folder: Path) -> None:
    """Parts every 15 s, faster than any cycle: the MILP packs its picks as close as a plan may.
    The first part is tracked at the nominal 3 in/s (nobody has changed the belt), so the next
    pick is at least the cycle at 3 in/s later, 18.084 s (R I 2.7293 s, docs/model.md's nominal
    cycle with R II and R IV at their peak), not the 17.566 s at the tracking limit; every later
    gap at least 17.566 s."""
    k = assemble(trace_scenario(folder, [15.0] * 12)).k
    t = k.timing
    first = sum(t.shortest_parts(k.v_nom, k.u_nom))
    assert abs(first - 18.0841) < 1e-3
    result = solve(k, [15.0 * (i + 1) for i in range(12)])
    picks = [b for b, p in zip(result.at_b_s, result.picked) if p]
    gaps = [b - a for a, b in zip(picks, picks[1:])]
    assert gaps[0] >= first - 1e-4
    assert min(gaps) >= check_cycle_s(k) - 1e-4
    assert min(gaps[1:]) < first - 0.1  # the later ones at the tracking limit's, shorter


def test_the_warm_up_is_left_out_of_the_count_as_from_the_bound(folder: Path) -> None:
    """With the first three parts a warm-up, the MILP counts the others only: on parts that
    come a cycle apart, all of them (the bound's count too)."""
    s = trace_scenario(folder, [30.0] * 8).with_overrides({"run.warmup_parts": 3})
    out = hindsight(s, budget_s=20.0).summary
    assert (out["parts_upper"], out["parts_optimum"], out["parts_bound"]) == (5, 5, 5)
    k = assemble(s).k
    assert solve(k, [30.0 * (i + 1) for i in range(8)], warmup=0).upper == 8


# --------------------------------------------------------------------------- the command
def test_the_command_writes_the_schedule_and_the_summary(folder: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """``cell hindsight``: schedule.csv part by part (its picks are the optimum's count) and
    summary.csv; the schedule is the same bytes run again."""
    import pandas as pd

    from cell.cli.main import main

    trace = folder / "burst.csv"
    trace.write_text("interarrival_s\n" + "".join(f"{g}\n" for g in BURST))
    args = ["hindsight", "baseline", "--set", "run.parts=10", "--set", f"arrivals.trace_csv={trace}"]
    assert main([*args, "--out", str(tmp_path / "a"), "--budget", "20"]) == 0
    assert main([*args, "--out", str(tmp_path / "b"), "--budget", "20"]) == 0
    summary = pd.read_csv(tmp_path / "a" / "summary.csv")
    schedule = pd.read_csv(tmp_path / "a" / "schedule.csv")
    row = summary.iloc[0]
    assert (row["parts_optimum"], bool(row["exact"]), row["parts_bound"]) == (1, True, 1)
    assert row["budget_s"] == 20.0 and "solve_s" not in summary.columns  # times told, not written
    assert list(schedule["part"]) == list(range(1, 11))
    assert int(schedule["picked"].sum()) == 1 and int(schedule["milp_picked"].sum()) == 1
    for name in ("schedule.csv", "summary.csv"):  # the same scenario and seed: the same files
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


@pytest.mark.parametrize("extra,key", [
    (["--budget", "0"], "--budget"),
    (["--set", "failures.maintenance={every_h: 8, duration_min: 20}"], "failures"),
    (["--set", "run.warmup_parts=auto"], "run.warmup_parts")])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path: Path, extra: list[str],
                                                          key: str,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    from cell.cli.main import main

    out = tmp_path / "out"
    assert main(["hindsight", "baseline", "--set", "run.parts=8", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and key in err[0]
    assert not out.exists()


def test_a_run_too_long_for_the_milp_gives_the_search_against_the_bound(
        folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Past the MILP's size the search's schedule is given, exact only where it reaches the
    bound (here, parts a cycle apart: all of them; the burst: one, the bound counting the one
    belt)."""
    import cell.experiments.hindsight.optimum as hs

    monkeypatch.setattr(hs, "MILP_MAX_PARTS", 5)
    found = hs.hindsight(trace_scenario(folder, [30.0] * 8), budget_s=20.0)
    s = found.summary
    assert (s["milp_status"], s["upper_from"], s["parts_upper"]) == ("too_large", "parts_bound", 8)
    assert s["parts_optimum"] == 8 and s["exact"]
    assert any("too large" in note for note in found.notes)
    found = hs.hindsight(trace_scenario(folder, BURST), budget_s=20.0)  # the bound counts the
    assert (found.summary["parts_optimum"], found.summary["exact"]) == (1, True)  # one belt
