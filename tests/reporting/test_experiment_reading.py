"""report.md's reading along one numeric key, for a sweep of one policy (no comparison to
give an effect, so the trend is its effect): figures as the tables show them."""

from __future__ import annotations

import numpy as np
import pandas as pd

from cell.experiments.stats import PAIRED_KEYS, summarise
from cell.experiments.sweep import load_sweep
from cell.reporting.experiment.explain import reading
from cell.reporting.formatting import HEADLINES
from tests.prose import in_order

KEY = "belts.output_nominal_in_s"


def trend(sweeps, tmp_path, runs: dict[float, list[float]]) -> str:
    """The reading of parts delivered for one policy over KEY, from its runs at each value."""
    sweep = load_sweep(sweeps.write(tmp_path, grid={KEY: list(runs)}, policies=["adaptive"]))
    summary = pd.DataFrame([{KEY: v, "policy": "adaptive", "measure": "parts_delivered",
                             **summarise(x)} for v, x in runs.items()])
    differences = pd.DataFrame(columns=[KEY, "policy", "versus", "measure", *PAIRED_KEYS])
    (text,) = [t for t in reading(summary, differences, sweep, [KEY], HEADLINES[:1])
               if t.startswith("- **")]
    return text


def test_a_measure_with_no_variation_reads_as_the_table_shows_it(sweeps, tmp_path):
    """Every run delivers all 60 parts at both ends: '60', as the table's '60 (no
    variation)', and 'does not move', not 'goes from 60.0000 ... to 60.0000'."""
    text = trend(sweeps, tmp_path, {2.0: [60] * 4, 2.5: [60] * 4})
    assert in_order(text, "Adaptive does not move", "(60 at all 2 points)")
    assert "60.0000" not in text and "goes from" not in text


def test_a_measure_that_moves_reads_from_one_end_to_the_other(sweeps, tmp_path):
    low, high = [40, 42, 41, 43], [50, 52, 51, 53]
    text = trend(sweeps, tmp_path, {2.0: low, 2.5: high})
    assert in_order(text, "Adaptive goes from", f"{np.mean(low):.1f} at {KEY} = 2",
                    f"to {np.mean(high):.1f} at 2.5.")
    assert "does not move" not in text


def test_an_end_without_a_value_is_passed_over_not_read_as_nan(sweeps, tmp_path):
    """No run at the first value gives the measure (runs too short for a rate): the reading
    goes from the first value that has one, and prints no 'nan'."""
    text = trend(sweeps, tmp_path, {1.5: [float("nan")] * 4, 2.0: [40, 42, 41, 43],
                                    2.5: [50, 52, 51, 53]})
    assert in_order(text, "Adaptive goes from", f"41.5 at {KEY} = 2", "to 51.5 at 2.5.")
    assert "nan" not in text


def test_one_replication_at_an_end_takes_the_other_end_s_precision(sweeps, tmp_path):
    """A single value has no interval: both ends are shown to the precision of the one
    interval there is (one decimal for 51.5 ± 2.1), whichever end lacks it."""
    one, four = [41.0], [50, 52, 51, 53]
    assert in_order(trend(sweeps, tmp_path, {2.0: one, 2.5: four}), "Adaptive goes from",
                    f"41.0 at {KEY} = 2", "to 51.5 at 2.5.")
    assert in_order(trend(sweeps, tmp_path, {2.0: four, 2.5: one}), "Adaptive goes from",
                    f"51.5 at {KEY} = 2", "to 41.0 at 2.5.")
