"""A precision sweep's rounds, whatever ``min`` and ``batch`` are: replications.csv is
assembled from exactly the task files the rounds wrote."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cell.experiments.sweep import load_sweep, run_sweep

MEASURE = "parts_per_hr_wallclock"


def spread_by_point(scenario, seed) -> dict:
    """No spread at ideal cycle 22 (precise after the first round), a lot elsewhere (every
    round, up to ``max``)."""
    sd = 0.0 if scenario.controller.ideal_cycle_s == 22.0 else 5.0
    return {MEASURE: 100.0 + sd * np.random.default_rng(seed).standard_normal()}


def precision_sweep(sweeps, tmp_path, min_n: int, batch: int):
    """3 points; ``max`` 3 rounds past ``min`` less one, so the last round is cut short."""
    return load_sweep(sweeps.write(tmp_path, batch=batch, replications={
        "precision": 0.001, "measure": MEASURE, "min": min_n, "max": min_n + 3 * batch - 1}))


@pytest.mark.parametrize(("min_n", "batch"), [(10, 20), (3, 5), (4, 5), (5, 5)])
def test_a_precision_sweep_finishes_the_same_with_1_and_2_workers(sweeps, tmp_path, min_n,
                                                                   batch):
    sweep = precision_sweep(sweeps, tmp_path, min_n, batch)
    one = run_sweep(sweep, tmp_path / "w1", workers=1, replicate=spread_by_point,
                    progress=False)
    two = run_sweep(sweep, tmp_path / "w2", workers=2, replicate=spread_by_point,
                    progress=False)
    most = min_n + 3 * batch - 1
    assert one.counts == two.counts == {0: min_n, 1: most, 2: most}
    assert one.path.read_bytes() == two.path.read_bytes()
    frame = pd.read_csv(one.path)
    assert list(frame["replication"]) == [*range(min_n), *range(most), *range(most)]
    assert frame.loc[:min_n - 1, MEASURE].eq(100.0).all()


def test_a_half_done_precision_sweep_resumes_to_the_same_bytes(sweeps, tmp_path):
    sweep = precision_sweep(sweeps, tmp_path, 10, 20)
    whole = run_sweep(sweep, tmp_path / "whole", workers=1, replicate=spread_by_point,
                      progress=False)
    killer = sweeps.Interrupt(after=3 * 10 + 20 + 5, of=spread_by_point)  # in round 2
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, tmp_path / "cut", workers=1, replicate=killer, progress=False)
    assert not (tmp_path / "cut" / "replications.csv").exists()
    counter = sweeps.Interrupt(after=10**9, of=spread_by_point)
    resumed = run_sweep(sweep, tmp_path / "cut", workers=1, resume=True,
                        replicate=counter, progress=False)
    assert resumed.tasks_reused == 4  # round 1's 3 tasks of 10, and round 2's first of 20
    assert counter.calls == sum(whole.counts.values()) - 3 * 10 - 20
    assert resumed.counts == whole.counts
    assert resumed.path.read_bytes() == whole.path.read_bytes()
