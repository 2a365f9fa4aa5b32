"""A shift calendar (``calendar:``; cell.scenario.calendar_section, cell.sim.calendar): no part
arrives and nothing moves outside working time, every equipment's states tile the run with
``off_shift`` exactly where the calendar (rebuilt here with datetime) has no work, availability
on the ``working`` clock is MTBF / (MTBF + MTTR) over working time, run.days / run.weeks end
where the calendar says, and bad calendars are refused in one line."""

from __future__ import annotations

import datetime as dt
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.scenario.schema import default_scenario
from cell.sim.simulation import simulate
from tests.refusals import refused_in_one_line

DAYS = ("mon", "tue", "wed", "thu", "fri", "sat", "sun")
START = "2027-01-04T06:00"  # a Monday
TWO_SHIFTS = {"start": START, "days": list(DAYS[:5]),
              "shifts": [["06:00", "14:00"], ["14:00", "22:00"]],
              "breaks": [["10:00", "10:15"], ["18:00", "18:15"]]}


def hhmm(minutes: int) -> str:
    return f"{minutes // 60 % 24:02d}:{minutes % 60:02d}"


def working_spans(cal: dict, end_s: float) -> list[tuple[float, float]]:
    """The calendar's working time on the run's clock, day by day with datetime (an
    implementation apart from the model's week arithmetic): each working day's shifts, a
    shift ending at or before its start ending the next day, less the breaks."""
    start = dt.datetime.fromisoformat(cal["start"])
    spans = []
    day = dt.datetime.combine(start.date(), dt.time()) - dt.timedelta(days=1)
    while (day - start).total_seconds() < end_s:
        if DAYS[day.weekday()] in cal["days"]:
            for a, b in cal["shifts"]:
                s = day + dt.timedelta(hours=int(a[:2]), minutes=int(a[3:]))
                e = day + dt.timedelta(hours=int(b[:2]), minutes=int(b[3:]))
                if e <= s:
                    e += dt.timedelta(days=1)
                cuts = []
                for c, d in cal.get("breaks", []):
                    for shift_day in (day, day + dt.timedelta(days=1)):
                        bs = shift_day + dt.timedelta(hours=int(c[:2]), minutes=int(c[3:]))
                        be = shift_day + dt.timedelta(hours=int(d[:2]), minutes=int(d[3:]))
                        if be <= bs:
                            be += dt.timedelta(days=1)
                        if s <= bs and be <= e:
                            cuts.append((bs, be))
                pieces = [(s, e)]
                for bs, be in cuts:
                    pieces = [q for x, y in pieces for q in ((x, min(y, bs)), (max(x, be), y))
                              if q[1] > q[0]]
                spans += [((x - start).total_seconds(), (y - start).total_seconds())
                          for x, y in pieces]
        day += dt.timedelta(days=1)
    spans = sorted((max(a, 0.0), min(b, end_s)) for a, b in spans if b > 0 and a < end_s)
    merged: list[tuple[float, float]] = []
    for a, b in spans:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def inside(t: np.ndarray, spans: list[tuple[float, float]]) -> np.ndarray:
    s = np.array([a for a, _ in spans])
    e = np.array([b for _, b in spans])
    k = np.searchsorted(s, t, side="right") - 1
    return (k >= 0) & (t <= e[np.maximum(k, 0)] + 1e-6)


@st.composite
def calendars(draw) -> dict:
    """A week a user may write: some working days, one to three shifts at quarter hours
    (a night shift crossing midnight among them), a break inside some."""
    n = draw(st.integers(1, 3))
    cuts = sorted(draw(st.lists(st.integers(0, 95), min_size=2 * n, max_size=2 * n,
                                unique=True)))
    turn = draw(st.integers(0, 95))  # the clock turned: shifts may cross midnight
    shifts, breaks = [], []
    for i in range(n):
        a, b = cuts[2 * i] * 15 + turn * 15, cuts[2 * i + 1] * 15 + turn * 15
        shifts.append([hhmm(a), hhmm(b)])
        if b - a >= 45 and draw(st.booleans()):
            c = draw(st.integers(a + 15, b - 30))
            breaks.append([hhmm(c), hhmm(c + 15)])
    days = draw(st.lists(st.sampled_from(DAYS), min_size=1, max_size=7, unique=True))
    start = dt.datetime(2027, 1, 4) + dt.timedelta(minutes=15 * draw(st.integers(0, 7 * 96 - 1)))
    return {"start": start.isoformat(timespec="minutes"), "days": days, "shifts": shifts,
            "breaks": breaks}


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cal=calendars())
@example(cal={"start": "2027-01-04T00:00", "days": ["mon"], "shifts": [["23:45", "00:30"]],
              "breaks": [["00:00", "00:15"]]})  # a night shift's break after midnight, on a day off
def test_nothing_comes_or_moves_off_shift_and_the_states_tile_the_run(cal):
    """No part comes (is due from the feeder) and no part is picked or set down outside
    working time; every equipment's states tile [0, end] and are ``off_shift`` exactly where
    the calendar has no work."""
    s = default_scenario().with_overrides({
        "calendar": cal, "run.parts": 150,
        "arrivals": {"distribution": "expon", "mean_s": 60.0, "cv": 1.0},
        "failures": {"input_belt": {"time_to_failure": {"distribution": "expon", "mean_h": 2},
                                    "time_to_repair": {"distribution": "expon", "mean_h": 0.2},
                                    "clock": "calendar"}}})
    r = simulate(s, 3)
    end = r.summary.sim_end_s
    work = working_spans(cal, end)
    parts = r.parts
    due = np.cumsum(parts["interarrival_s"].to_numpy())
    assert inside(due, work).all()
    for column in ("pick_s", "touchdown_s"):
        t = parts[column].to_numpy()
        assert inside(t[np.isfinite(t)], work).all()
    off = [(a, b) for a, b in zip([0.0] + [e for _, e in work], [s_ for s_, _ in work] + [end])
           if b - a > 1e-6]
    for equipment, rows in r.timelines.items():
        edges = [(a, b) for _, a, b in rows]
        assert edges[0][0] == 0.0 and edges[-1][1] == pytest.approx(end)
        assert all(b1 == pytest.approx(a2) for (_, b1), (a2, _) in zip(edges, edges[1:]))
        shown = [(a, b) for state, a, b in rows if state == "off_shift"]
        assert len(shown) == len(off), equipment
        np.testing.assert_allclose(np.array(shown), np.array(off), atol=1e-6)


MTBF_H, MTTR_H = 2.0, 0.5


@pytest.fixture(scope="module")
def working_clock_run():
    """16 weeks of two shifts with breaks; the robot fails on the working clock and is
    repaired in working time (exponential both); parts come slowly (they do not matter)."""
    s = default_scenario().with_overrides({
        "calendar": TWO_SHIFTS, "run.weeks": 16,
        "arrivals": {"distribution": "expon", "mean_s": 900.0, "cv": 1.0},
        "failures": {"robot": {"time_to_failure": {"distribution": "expon", "mean_h": MTBF_H},
                               "time_to_repair": {"distribution": "expon", "mean_h": MTTR_H},
                               "clock": "working"}}})
    return simulate(s, 11)


def test_availability_on_the_working_clock_is_mtbf_over_mtbf_plus_mttr(working_clock_run):
    """Up and repair times both counted in working time alternate as a renewal process there,
    so the share of working time up is MTBF / (MTBF + MTTR) = 0.8; its standard error over T
    working hours with exponential times is sqrt(2 MTBF² MTTR² / ((MTBF + MTTR)³ T)), 0.010
    at T = 1,240 h: within 4 of them.  (Counted on the calendar clock instead, the robot
    would fail 168 / 77.5 times as often per working hour: 0.65.)"""
    r = working_clock_run.summary
    t_h = 16 * 5 * 15.5
    assert r.planned_time_s == pytest.approx(t_h * 3600.0)
    a = MTBF_H / (MTBF_H + MTTR_H)
    se = math.sqrt(2 * MTBF_H ** 2 * MTTR_H ** 2 / ((MTBF_H + MTTR_H) ** 3 * t_h))
    assert abs((1.0 - r.loss_downtime) - a) < 4 * se
    n = r.robot_failures  # observed MTBF and MTTR count working time: the drawn means
    assert abs(r.mtbf_observed_s / 3600.0 - MTBF_H) < 4 * MTBF_H / math.sqrt(n)
    assert abs(r.mttr_observed_s / 3600.0 - MTTR_H) < 4 * MTTR_H / math.sqrt(n)


def test_run_days_and_weeks_end_where_the_calendar_says():
    """run.days: 5 from Monday 06:00 ends Friday 22:00 (the fifth working day's last shift);
    run.weeks: 1 a week later, to the second (datetime's arithmetic)."""
    start = dt.datetime.fromisoformat(START)
    for length, end in (({"days": 5}, dt.datetime(2027, 1, 8, 22)),
                        ({"weeks": 1}, dt.datetime(2027, 1, 11, 6))):
        s = default_scenario().with_overrides({
            "calendar": TWO_SHIFTS, "run": length,
            "arrivals": {"distribution": "expon", "mean_s": 1800.0, "cv": 1.0}})
        assert simulate(s, 1).summary.sim_end_s == (end - start).total_seconds()


def test_parts_csv_has_arrival_time_only_with_a_calendar(tmp_path: Path):
    """parts.csv's ``arrival_time`` is the calendar's start plus ``arrival_s``; states.csv is
    written, failures.csv only with failures."""
    import pandas as pd

    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"calendar": TWO_SHIFTS, "run": {"parts": 40}}))
    assert main(["run", str(path), "--out", str(tmp_path / "a")]) == 0
    parts = pd.read_csv(tmp_path / "a" / "parts.csv")
    stamps = pd.to_datetime(parts["arrival_time"])
    back = (stamps - pd.Timestamp(START)).dt.total_seconds()
    np.testing.assert_allclose(back, parts["arrival_s"], atol=1e-3)
    assert (tmp_path / "a" / "states.csv").is_file()  # off_shift shown; nothing failed:
    assert not (tmp_path / "a" / "failures.csv").exists()  # no failures.csv
    assert main(["run", "baseline", "--set", "run.parts=40", "--out", str(tmp_path / "b")]) == 0
    assert "arrival_time" not in pd.read_csv(tmp_path / "b" / "parts.csv").columns


@pytest.mark.parametrize("change, key, value", [
    ({"shifts": [["06:00", "14:00"], ["13:00", "21:00"]]}, "calendar.shifts[1]", "['13:00'"),
    ({"shifts": [["22:00", "06:00"], ["05:00", "13:00"]]}, "calendar.shifts[1]", "['05:00'"),
    ({"breaks": [["14:30", "14:45"]], "shifts": [["06:00", "14:00"]]}, "calendar.breaks[0]",
     "['14:30'"),
    ({"breaks": [["13:50", "14:10"]], "shifts": [["06:00", "14:00"]]}, "calendar.breaks[0]",
     "['13:50'"),
    ({"shifts": [["06:00", "06:00"]]}, "calendar.shifts[0]", "['06:00'"),
    ({"shifts": [["06:00", "25:00"]]}, "calendar.shifts[0][1]", "'25:00'"),
    ({"days": []}, "calendar.days", "[]"),
    ({"shifts": [], "breaks": []}, "calendar.shifts", "[]"),
    ({"shifts": [["06:00", "07:00"]], "breaks": [["06:00", "07:00"]]}, "calendar.breaks",
     "[['06:00'"),
    ({"start": "monday"}, "calendar.start", "'monday'"),
])
def test_a_bad_calendar_is_one_line_naming_file_key_and_value(capsys, tmp_path: Path, change,
                                                              key, value):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump({"calendar": {**TWO_SHIFTS, **change}}))
    out = tmp_path / "out"
    refused_in_one_line(capsys, ["run", str(scenario), "--out", str(out)], scenario, key, value, out)


def test_a_night_shift_crossing_midnight_is_working_time():
    """["22:00", "06:00"] on Monday is eight hours of work, from Monday 22:00 to Tuesday 06:00."""
    cal = {"start": "2027-01-04T00:00", "days": ["mon"], "shifts": [["22:00", "06:00"]]}
    s = default_scenario().with_overrides({
        "calendar": cal, "run.days": 1,
        "arrivals": {"distribution": "expon", "mean_s": 600.0, "cv": 1.0}})
    r = simulate(s, 2).summary
    assert r.sim_end_s == 30 * 3600.0
    assert r.planned_time_s == 8 * 3600.0


@pytest.mark.parametrize("overrides, key", [
    ({"failures.robot": {"time_to_failure": {"mean_h": 9}, "time_to_repair": {"mean_h": 1},
                         "clock": "working"}}, "failures.robot.clock"),
    ({"run": {"days": 3}}, "run.days"),
])
def test_what_counts_working_time_needs_a_calendar(capsys, tmp_path: Path, overrides, key):
    scenario = tmp_path / "s.yaml"
    raw: dict = {}
    for k, v in overrides.items():
        where = raw
        *path, last = k.split(".")
        for p in path:
            where = where.setdefault(p, {})
        where[last] = v
    scenario.write_text(yaml.safe_dump(raw))
    assert main(["run", str(scenario), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.startswith(f"cell: error: {scenario}: {key} = ")


def test_a_profile_under_a_calendar_follows_the_working_hour_of_the_shift():
    """A profile of period 7.75 h (a shift's working time), 1.2 for its first two hours and 1
    after, counts working hours: of Poisson arrivals over 20 weeks, the share coming in a
    shift's first two working hours is 1.2 × 2 / (1.2 × 2 + 5.75) = 0.294, breaks and nights
    notwithstanding (binomial, within 4.5 standard errors); and none comes off shift."""
    from cell.scenario.calendar_section import working_week
    from cell.sim.horizon import run_arrivals

    s = default_scenario().with_overrides({
        "calendar": TWO_SHIFTS, "run.weeks": 20,
        "arrivals": {"distribution": "expon", "mean_s": 120.0, "cv": 1.0,
                     "profile": {"period_h": 7.75, "rates": [1.2, 1.0], "starts_h": [0, 2]}}})
    gaps, n, _ = run_arrivals(s, 5)
    t = np.cumsum(gaps[:n])
    assert inside(t, working_spans(TWO_SHIFTS, t[-1] + 1)).all()
    hour_of_shift = np.mod(working_week(s.calendar).measure(t) / 3600.0, 7.75)
    share = np.mean(hour_of_shift < 2.0)
    p = 2.4 / (2.4 + 5.75)
    assert abs(share - p) < 4.5 * math.sqrt(p * (1 - p) / n)


def test_maintenance_off_shift_waits_for_a_time_off_it_fits_in():
    """Planned stops of 60 min every 20 h with ``off_shift``: each starts while the cell stands
    for a night or a weekend (not a quarter-hour break) and ends before work resumes, so the
    planned busy time is the whole working time; the adaptive robot, nearly always mid-cycle
    at a shift's end, is maintained where it stands."""
    s = default_scenario().with_overrides({
        "calendar": TWO_SHIFTS, "run.weeks": 2,
        "failures": {"maintenance": {"every_h": 20, "duration_min": 60, "off_shift": True}}})
    r = simulate(s, 4, keep_parts=False, keep_belts=False)
    work = working_spans(TWO_SHIFTS, r.summary.sim_end_s)
    stops = [(a, b) for name, cause, a, b, _ in r.stop_rows if cause == "maintenance"]
    assert len(stops) >= 10
    for a, b in stops:
        assert not any(s_ < a < e_ - 1e-6 for s_, e_ in work)  # off shift
        nxt = min([s_ for s_, _ in work if s_ > a] or [np.inf])
        assert b <= nxt + 1e-6  # done before work resumes: not in a quarter-hour break
    assert r.summary.planned_time_s == pytest.approx(2 * 5 * 15.5 * 3600.0)


def crew_time(spans: list[tuple[float, float]], a: float, b: float) -> float:
    return sum(max(0.0, min(e, b) - max(s_, a)) for s_, e in spans)


def test_a_repair_takes_its_time_in_the_crews_hours():
    """A crew on the first shift only (06:00-14:00 less its break): every repair ends in the
    crew's hours, a failure in the second shift waits for the next morning, and the crew's
    time from a failure to its repair (datetime's calendar) averages the drawn mean repair time,
    MTTR = 0.5 h (exponential, unlimited crews: no wait for a crew; within 4 standard errors)."""
    s = default_scenario().with_overrides({
        "calendar": TWO_SHIFTS, "run.weeks": 12,
        "arrivals": {"distribution": "expon", "mean_s": 900.0, "cv": 1.0},
        "failures": {"robot": {"time_to_failure": {"distribution": "expon", "mean_h": 3},
                               "time_to_repair": {"distribution": "expon", "mean_h": 0.5},
                               "clock": "working"},
                     "repair": {"hours": [["06:00", "14:00"]]}}})
    r = simulate(s, 8, keep_parts=False, keep_belts=False)
    end = r.summary.sim_end_s
    crew = working_spans({**TWO_SHIFTS, "shifts": [["06:00", "14:00"]]}, end)
    done = [(a, b) for name, _, a, b, _ in r.stop_rows if name == "robot" and b < end]
    assert inside(np.array([b for _, b in done]), crew).all()
    late = [(a, b) for a, b in done if not inside(np.array([a]), crew)[0]]
    assert late and all(b - a > 8 * 3600.0 for a, b in late)  # waited overnight at least
    hours = np.array([crew_time(crew, a, b) for a, b in done]) / 3600.0
    assert abs(hours.mean() - 0.5) < 4 * 0.5 / math.sqrt(hours.size)


def test_two_run_lengths_are_refused(capsys, tmp_path: Path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump({"calendar": TWO_SHIFTS, "run": {"days": 2, "weeks": 1}}))
    assert main(["run", str(scenario), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"cell: error: {scenario}: run.days = 2") and "run.weeks" in err
    assert not (tmp_path / "out").exists()


def test_states_and_failures_carry_the_calendars_timestamps(tmp_path: Path):
    """Under a calendar states.csv and failures.csv give each row's ends as timestamps too:
    ``from_time`` / ``to_time`` are the start plus ``from_s`` / ``to_s``; without one, neither."""
    import pandas as pd

    failing = {"robot": {"time_to_failure": {"distribution": "expon", "mean_h": 2},
                         "time_to_repair": {"distribution": "expon", "mean_h": 0.5}}}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"calendar": TWO_SHIFTS, "run": {"days": 2},
                                    "failures": failing}))
    assert main(["run", str(path), "--out", str(tmp_path / "a")]) == 0
    for name in ("states.csv", "failures.csv"):
        rows = pd.read_csv(tmp_path / "a" / name)
        assert len(rows) > 0, name
        for end in ("from", "to"):
            back = (pd.to_datetime(rows[f"{end}_time"]) - pd.Timestamp(START)).dt.total_seconds()
            np.testing.assert_allclose(back, rows[f"{end}_s"], atol=1e-3)
    plain = tmp_path / "p.yaml"
    plain.write_text(yaml.safe_dump({"run": {"hours": 20}, "failures": failing}))
    assert main(["run", str(plain), "--out", str(tmp_path / "b")]) == 0
    for name in ("states.csv", "failures.csv"):
        assert "from_time" not in pd.read_csv(tmp_path / "b" / name).columns
