"""KN (cell.experiments.kn) against its guarantee on synthetic normal systems with known means.

Kim & Nelson (2001), Theorem 1: if the best mean is at least δ above every other, KN
selects it with probability at least 1 - α.  The slippage configuration (every other
system exactly δ below the best) is the least favourable one, so it is the hard test.
"""

from __future__ import annotations

import numpy as np
import pytest

from cell.experiments.kn import (
    FlatFirstStage,
    NotANumber,
    eta,
    first_stage_df,
    h_squared,
    kn,
    pair_variances,
    screen,
)
from cell.experiments.kn_check import macro_pcs, poisson_draw

K, DELTA, SIGMA, N0, PCS = 5, 0.5, 1.0, 10, 0.95
MACRO = 1000


def _macro_pcs(means: np.ndarray, rho: float, n_max: int, seed: int) -> tuple[float, int]:
    """KN run on MACRO independent problems at once (pure numpy, pre-drawn observations,
    which is the same as drawing them when asked); returns the share that chose system 0
    and how many stopped at the budget with more than one left."""
    rng = np.random.default_rng(seed)
    k = len(means)
    common = rng.standard_normal((MACRO, n_max, 1))  # common random numbers: correlation rho
    own = rng.standard_normal((MACRO, n_max, k))
    x = means + SIGMA * (np.sqrt(rho) * common + np.sqrt(1 - rho) * own)
    s2 = pair_variances(x[:, :N0])
    h2 = h_squared(k, 1 - PCS, N0)
    alive = np.ones((MACRO, k), dtype=bool)
    sums = np.cumsum(x, axis=1)
    for r in range(N0, n_max + 1):
        alive = screen(sums[:, r - 1] / r, s2, alive, r, h2, DELTA)
        if (alive.sum(axis=1) == 1).all():
            break
    single = alive.sum(axis=1) == 1
    return float((single & alive[:, 0]).mean()), int((~single).sum())


@pytest.mark.parametrize("rho", [0.0, 0.6])
def test_kn_picks_the_best_in_the_slippage_configuration(rho: float) -> None:
    means = np.array([DELTA] + [0.0] * (K - 1))
    share, unfinished = _macro_pcs(means, rho, n_max=400, seed=23 + int(10 * rho))
    assert unfinished == 0
    assert share >= PCS, share


def test_kn_driver_matches_the_vectorised_screen_and_minimises() -> None:
    rng = np.random.default_rng(5)
    means = np.array([3.0, 2.0, 2.5, 0.0])  # minimise: system 3 is the best by 2
    draws = means + rng.standard_normal((500, 4))
    asked: list[tuple[list[int], int]] = []

    def sample(systems, r):
        asked.append((list(systems), r))
        return draws[r, list(systems)]

    sel = kn(sample, 4, delta=0.5, pcs=0.95, n0=10, maximize=False, max_n=500)
    assert sel.best == 3 and sel.survivors == (3,)
    assert asked[0] == ([0, 1, 2, 3], 0)  # the first stage: every system, replication 0
    assert all(3 in systems for systems, _ in asked)  # the survivor is sampled to the end
    assert sel.counts[3] == max(sel.counts) and min(sel.counts) >= 10
    # a replication once asked of a system is never asked again (no repeats, no gaps)
    for i in range(4):
        rs = [r for systems, r in asked if i in systems]
        assert rs == list(range(len(rs)))


def test_a_first_stage_that_never_varies_is_refused() -> None:
    """Two systems equal replication by replication (a count that common random numbers
    make equal): S² = 0 would make KN eliminate on the first difference; refused, naming
    the pair, before any replication past the first stage."""
    asked: list[int] = []

    def sample(systems, r):
        asked.append(r)
        return [0.0, 0.0, float(r % 3)][:len(systems)]

    with pytest.raises(FlatFirstStage) as caught:
        kn(sample, 3, delta=1.0, n0=5, max_n=50)
    assert (caught.value.i, caught.value.l, caught.value.n0) == (0, 1, 5)
    assert max(asked) == 4


def test_first_stage_degrees_of_freedom() -> None:
    """A measure that varies continuously keeps KN's n0 - 1; a count whose pair difference
    departs from its usual value in m replications is worth 2 m (a Poisson count's relative
    variance 1/m against a χ²_ν/ν's 2/ν); never varying, 0."""
    rng = np.random.default_rng(3)
    assert int(first_stage_df(rng.standard_normal((10, 4)))) == 9
    count = np.zeros((10, 3))
    count[4, 1] = 1.0  # system 1 misses a part in one replication
    count[[2, 7], 2] = 1.0  # system 2 in two others
    # pair (0, 1): one departure, so 2; (0, 2): two; (1, 2): three
    assert int(first_stage_df(count)) == 2
    count[4, 1] = 0.0
    assert int(first_stage_df(count)) == 0  # systems 0 and 1 never differ
    assert int(first_stage_df(np.array([[0.0, 1.0], [1.0, 0.0]]))) == 1  # n0 = 2: n0 - 1


@pytest.mark.parametrize("n0", [3, 10])
def test_kn_keeps_its_probability_on_a_rare_count(n0: int) -> None:
    """Parts missed, mostly 0 (Poisson means 0.1 for the best, 0.35 for three others, δ =
    0.25: the slippage configuration): over 1,000 problems KN with the first-stage rule
    chooses the best at least as often as asked (within its standard error), where the
    same screening that takes every first stage at face value does not."""
    draw = poisson_draw([0.1, 0.35, 0.35, 0.35], MACRO, seed=40 + n0)
    ruled = macro_pcs(draw, 0, 0.25, n0, PCS, maximize=False)
    assert ruled.decided >= 100 and ruled.pcs >= PCS - ruled.se, ruled
    if n0 == 10:  # (n0 = 3 without the rule takes seconds; make kn-check has it)
        plain = macro_pcs(draw, 0, 0.25, n0, PCS, maximize=False, rule=False)
        assert plain.refused == 0 and plain.pcs + plain.se < PCS, plain


def test_kn_refuses_what_it_cannot_compare() -> None:
    with pytest.raises(NotANumber) as caught:
        kn(lambda systems, r: [1.0, float("nan")][:len(systems)], 2, delta=1.0, n0=3)
    assert (caught.value.i, caught.value.r) == (1, 0)
    for delta in (float("inf"), float("nan"), 0.0):
        with pytest.raises(ValueError):
            kn(lambda systems, r: [float(r), 2.0 * r], 2, delta=delta, n0=3)


def test_eta_closed_form() -> None:
    # k = 2, alpha = 0.05, n0 = 2: 0.5 * ((0.1)^(-2) - 1) = 49.5
    assert eta(2, 0.05, 2) == pytest.approx(49.5)
    assert h_squared(2, 0.05, 2) == pytest.approx(99.0)
    with pytest.raises(ValueError):
        eta(1, 0.05, 10)


def test_sweep_select_best_continues_the_sweeps_streams(tmp_path, capsys) -> None:
    """The fixed-cycle robot loses fewer parts at a shorter cycle (Table 7.1): KN over a
    sweep's two cycles picks the shorter; without --delta nothing runs."""
    from pathlib import Path

    import pandas as pd

    from cell.cli.main import main

    base = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"
    sweep = tmp_path / "s.yaml"
    sweep.write_text(f"base: {base}\nset: {{run.parts: 60}}\npolicies: [non-adaptive]\n"
                     "grid: {controller.ideal_cycle_s: [20.1, 22.5872]}\nreplications: 3\nseed: 2\n")
    out = tmp_path / "out"
    assert main(["sweep", str(sweep), "--out", str(out), "--select-best", "parts_missed"]) == 2
    assert "--delta" in capsys.readouterr().err and not out.exists()
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "1",
                 "--select-best", "parts_missed", "--delta", "1"]) == 0
    sel = pd.read_csv(out / "selection.csv")
    chosen = sel[sel["verdict"] == "chosen"]
    assert len(chosen) == 1 and "20.1" in chosen["point"].iloc[0]
    assert (sel["replications"] >= 3).all()
    assert "KN (Kim & Nelson 2001) chose" in capsys.readouterr().out
