"""``cell compare``'s verdict: each line a sentence that reads the right way round, A the
subject of A - B, as report.md says it."""

from __future__ import annotations

import pandas as pd
import pytest

from cell.experiments.sweep.spec import comparison
from cell.reporting.compare_judgement import verdict
from cell.reporting.experiment.text import sentence
from cell.reporting.formatting import HEADLINES
from cell.scenario.run_length import RunLength
from cell.scenario.schema import load_scenario
from tests.prose import in_order

#: A (non_adaptive) against B (fitted): A is worse on every measure, B better.
MEANS = {"parts_delivered": (341.1, 500.0), "parts_missed": (158.9, 0.0),
         "parts_per_hr_wallclock": (108.0, 159.0), "actual_cycle_wallclock_s": (33.0, 20.79),
         "ip_wallclock": (0.70, 0.99), "spacing_outside_tol": (330.0, 0.0)}
#: (mean, half-width) of A - B.
DIFFS = {"parts_delivered": (-158.9, 2.4), "parts_missed": (158.9, 2.4),
         "parts_per_hr_wallclock": (-51.0, 1.2), "actual_cycle_wallclock_s": (12.21, 0.26),
         "ip_wallclock": (-0.29, 0.02), "spacing_outside_tol": (330.0, 1.1)}
SAYS = {
    "Parts delivered": "fitted better: non_adaptive delivers 158.9 ± 2.4 parts fewer than "
                       "fitted per 500-part run (interval excludes 0)",
    "Parts lost (wall clock)": "fitted better: non_adaptive loses 158.9 ± 2.4 parts more than "
                               "fitted per 500-part run (interval excludes 0)",
    "Parts per hour (wall clock)": "fitted better: non_adaptive delivers 51.0 ± 1.2 parts/hr "
                                   "fewer than fitted on the wall clock (interval excludes 0)",
    "Actual cycle (wall clock, s)": "fitted better: non_adaptive runs a wall-clock actual cycle "
                                    "12.21 ± 0.26 s longer than fitted (interval excludes 0)",
    "IP (wall clock, eq. 5.1)": "fitted better (nearer 1 is better): non_adaptive reaches a wall-clock IP "
                                "0.290 ± 0.020 lower than fitted (interval excludes 0)",
    "Spacings outside 45 ± 0.25 in": "fitted better: non_adaptive leaves 330.0 ± 1.1 more "
                                     "spacings outside 45 ± 0.25 in than fitted per 500-part "
                                     "run (interval excludes 0)",
}


def tables(diffs: dict[str, tuple[float, float]], sd: float = 5.0):
    summary = pd.DataFrame([
        {"scenario": s, "policy": p, "measure": m, "n": 30, "mean": pair[i], "sd": 1.0,
         "ci_low": pair[i] - 1, "ci_high": pair[i] + 1, "run_p2_5": 0, "run_p97_5": 1}
        for i, (s, p) in enumerate((("non_adaptive", "non-adaptive"), ("fitted", "adaptive")))
        for m, pair in MEANS.items()])
    differences = pd.DataFrame([
        {"scenario": "non_adaptive", "policy": "non-adaptive", "versus": "fitted",
         "measure": m, "n": 30, "mean": d, "sd": sd, "ci_low": d - h, "ci_high": d + h,
         "p_value": 0.01} for m, (d, h) in diffs.items()])
    return summary, differences


@pytest.fixture(scope="module")
def sweep():
    a = load_scenario("non_adaptive")
    return comparison(a, load_scenario("baseline"), ("non_adaptive", "fitted"), 30, 1)


def lines_of(text: str) -> dict[str, str]:
    """Each headline's verdict, without the means said after it (issue 24: 'means A against
    B') and without the overall line."""
    titles = {h.title for h in HEADLINES}
    out = {line[2:].split("  ")[0]: line.split("  ", 2)[2].strip().split("; means ")[0]
           for line in text.splitlines()[1:] if line.startswith("  ")}
    return {k: v for k, v in out.items() if k in titles}


def test_every_headline_reads_with_a_as_its_subject(sweep):
    assert lines_of(verdict(*tables(DIFFS), sweep)) == SAYS
    assert {h.title for h in HEADLINES} == set(SAYS)


def test_the_verdict_says_what_report_md_says(sweep):
    """The same words as report.md's sentence for the same difference, up to the interval's
    wording (the verdict's 'than fitted' is the report's 'than fitted' too)."""
    said = lines_of(verdict(*tables(DIFFS), sweep))
    _, differences = tables(DIFFS)
    for h in HEADLINES:
        row = differences[differences["measure"] == h.column].iloc[0]
        reported = sentence(h, row, "non_adaptive", "fitted", RunLength(500, "part"), 0.95)
        assert said[h.title].split(": ", 1)[1].split(" (interval")[0] == \
            reported.split(" (95 % CI")[0]


def test_a_difference_in_every_replication_and_none_at_all(sweep):
    flat = tables({"parts_delivered": (-158.0, 0.0), "parts_missed": (0.0, 0.0)}, sd=0.0)
    said = lines_of(verdict(*flat, sweep))
    delivered, lost = said["Parts delivered"], said["Parts lost (wall clock)"]
    assert in_order(delivered, "fitted better:", "158 parts fewer", "per 500-part run",
                    "in every replication") and "±" not in delivered  # sd 0: no interval
    assert in_order(lost, "neither:", "equal in every replication")


DELIVERED = ("fitted better: non_adaptive delivers 158.9 ± 2.4 parts fewer than fitted{} "
             "(interval excludes 0)")
APART = "not compared: a count, over different windows ({}); compare the rates"


@pytest.mark.parametrize(("a_set", "b_set", "header", "delivered"), [
    ({"run.hours": 2}, {"run.hours": 2}, "of 2 hours,", DELIVERED.format(" per 2-hour run")),
    ({"run.parts": 1}, {"run.parts": 1}, "of 1 part,", DELIVERED.format(" per 1-part run")),
    ({"run.hours": 0.5}, {}, "of 0.5 hours and 500 parts,",
     APART.format("run length 0.5 hours against 500 parts")),
    ({"run.hours": 1}, {"run.hours": 2}, "of 1 and 2 hours,",
     APART.format("run length 1 hour against 2 hours")),
    ({"run.parts": 300}, {}, "of 300 and 500 parts,", APART.format("run.parts 300 against 500")),
])
def test_the_verdict_names_the_runs_length_in_parts_or_hours(a_set, b_set, header, delivered):
    """A run given in hours is said to be so ('per 2-hour run', not the 500 parts of the
    run.parts it leaves at its default), and runs of different lengths, in hours or parts,
    have their counts left uncompared."""
    sides = comparison(load_scenario("non_adaptive", a_set), load_scenario("baseline", b_set),
                       ("non_adaptive", "fitted"), 30, 1)
    text = verdict(*tables(DIFFS), sides)
    assert f"30 replications {header} seed 1," in text.splitlines()[0]
    assert lines_of(text)["Parts delivered"] == delivered


def test_a_run_length_in_words():
    assert [str(RunLength(1, "part")), str(RunLength(1_000_000, "part")), str(RunLength(0.5, "hour")),
            str(RunLength(4000.0, "hour"))] == ["1 part", "1000000 parts", "0.5 hours", "4000 hours"]
    assert RunLength(8.0, "hour").run == "8-hour run"
