"""report.md's reading of how single runs scatter: counts read as whole numbers, as their
tables show them, and a rare count is not 'scattered widely'."""

from __future__ import annotations

import pandas as pd
import pytest

from cell.experiments.stats import PAIRED_KEYS, summarise
from cell.reporting.experiment.explain import reading
from cell.reporting.experiment.text import cell
from cell.reporting.formatting import HEADLINES
from tests.prose import in_order

KEY = "belts.output_nominal_in_s"
SPACINGS = next(h for h in HEADLINES if h.column == "spacing_outside_tol")
CYCLE = next(h for h in HEADLINES if h.column == "actual_cycle_wallclock_s")


def scatter(sweeps, tmp_path, runs: list[float], h=SPACINGS, whole: bool = True) -> str:
    """The reading of ``h`` for one adaptive point whose runs gave ``runs``, and its table
    cell: ``cell ¦ reading``."""
    from cell.experiments.sweep import load_sweep

    sweep = load_sweep(sweeps.write(tmp_path, grid={KEY: [2.5]}, policies=["adaptive"]))
    row = {KEY: 2.5, "policy": "adaptive", "measure": h.column, **summarise(runs)}
    differences = pd.DataFrame(columns=[KEY, "policy", "versus", "measure", *PAIRED_KEYS])
    text = reading(pd.DataFrame([row]), differences, sweep, [KEY], [h],
                   {h.column} if whole else ())
    said = [t.removeprefix("- ") for t in text]  # the Reading's bullets (issue 24)
    return cell(row, whole) + " ¦ " + " ".join(t for t in said if t.startswith("**"))


def test_a_count_that_is_0_or_1_does_not_scatter_widely(sweeps, tmp_path):
    """One run in 20 with one spacing outside: 0.05 ± 0.10 [0–1]; nothing to add."""
    assert scatter(sweeps, tmp_path, [0] * 19 + [1]) == "0.05 ± 0.10 [0–1] ¦ "


def test_a_count_that_is_0_in_nearly_every_run_says_the_few_others_make_the_mean(sweeps,
                                                                                 tmp_path):
    table, said = scatter(sweeps, tmp_path, [0] * 197 + [1] * 3).split(" ¦ ")
    mean = table.split(" [")[0]  # the table's cell: the mean 3/200 and its interval
    assert table == "0.015 ± 0.017 [0–0]" and said.startswith("**Spacings outside")
    assert in_order(said, f"Adaptive at {KEY} = 2.5:", "0 in 95 % of single runs",
                    f"the mean, {mean},", "few others") and "scatters" not in said


def test_a_count_reads_its_range_as_its_table_does(sweeps, tmp_path):
    """Runs 0 to 3: the 97.5 % point 2.5 of the runs is shown '2' (rounded, as the table's
    cell), never a fraction of a count."""
    runs = [0] * 14 + [1, 1, 2, 2, 3, 3]
    table, said = scatter(sweeps, tmp_path, runs).split(" ¦ ")
    lo, hi = table.split("[")[1].rstrip("]").split("–")
    assert f"95 % of single runs {lo} to {hi};" in said and "scatters widely" in said
    assert "." not in lo + hi


@pytest.mark.parametrize(("runs", "shown"), [([20.0, 21.0, 60.0, 20.5], "20 to 57"),
                                             ([0.1, 0.9, 0.2, 0.7], "0.11 to 0.89")])
def test_a_measure_that_is_not_a_count_reads_its_range_as_its_table_does(sweeps, tmp_path,
                                                                        runs, shown):
    """To the interval's precision, as the table: a half-width of 31 s gives whole seconds."""
    table, said = scatter(sweeps, tmp_path, runs, CYCLE, whole=False).split(" ¦ ")
    assert f"[{shown.replace(' to ', '–')}]" in table
    assert in_order(said, "scatters widely", f"(95 % of single runs {shown}; mean")
