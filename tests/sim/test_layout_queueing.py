"""The buffer and a second robot downstream against queueing theory's closed forms
(docs/layout.md).  The fixed-cycle robot under Poisson arrivals is a single server whose
service is exactly its cycle C: with no buffer it is the one-server loss system (Erlang's loss
formula, c = 1); with N places at the gate it is the M/D/1/N+1 queue, whose loss fraction
comes from the Markov chain embedded at its departures (Gross & Harris, *Fundamentals of
Queueing Theory*, 3rd ed. 1998, §5.1.8 "M/G/1/K"; built here with numpy, independently of the
model); and two identical fixed-cycle robots one behind the other on the input line lose the
two-server loss system's fraction (Erlang B, c = 2: the loss of M/G/c/c depends on the service
only through its mean, and on the order in which free servers are tried not at all).

Each configuration is one run of 16,000 parts; its loss fraction's 95 % confidence interval,
from 16 batch means of 1,000 parts, is narrower than ±0.01, and the closed form lies within
its 99 % interval.  Three loads, each shared by the configurations that use it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate

CYCLE_S = 22.5872
LOADS = (0.5, 0.9, 1.4)  # offered load rho = lambda C
PARTS, BATCHES = 16_000, 16


def erlang_b(c: int, a: float) -> float:
    """Erlang's loss formula for c servers and offered load a (the stable recursion)."""
    b = 1.0
    for k in range(1, c + 1):
        b = a * b / (k + a * b)
    return b


def md1k_loss(rho: float, k: int) -> float:
    """The loss fraction of M/D/1/K (K places in the system, the one in service included):
    the departure-epoch chain on 0 … K-1 left behind, its stationary pi, then the arrivals'
    view P(loss) = 1 - 1 / (pi_0 + rho)."""
    if k == 1:
        return rho / (1.0 + rho)
    a = stats.poisson.pmf(np.arange(k), rho)  # arrivals during one service
    p = np.zeros((k, k))
    for i in range(k):
        start = max(i - 1, 0)  # after a departure leaving i, the next leaves i - 1 + arrivals
        for j in range(start, k - 1):
            p[i, j] = a[j - start]
        p[i, k - 1] = 1.0 - p[i, :k - 1].sum()
    w, v = np.linalg.eig(p.T)
    pi = np.real(v[:, np.argmin(np.abs(w - 1.0))])
    pi /= pi.sum()
    return 1.0 - 1.0 / (pi[0] + rho)


def test_the_chain_agrees_with_erlang_at_one_place():
    """M/D/1/1 is Erlang's one-server loss system; and more places lose less."""
    for rho in LOADS:
        assert md1k_loss(rho, 1) == pytest.approx(erlang_b(1, rho), rel=1e-12)
        losses = [md1k_loss(rho, k) for k in (1, 2, 3, 4)]
        assert losses == sorted(losses, reverse=True)


def _scenario(rho: float, sets: dict) -> object:
    return load_scenario("baseline", {
        "run.parts": PARTS, "controller.policy": "non-adaptive", "part.size_in": 1.0,
        "controller.nominal_cycle_s": CYCLE_S, "controller.ideal_cycle_s": CYCLE_S,
        "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": CYCLE_S / rho}},
        **sets})


CONFIGS = {  # name -> (the scenario's layout, the closed form at load rho)
    "no buffer": ({}, lambda rho: erlang_b(1, rho)),
    "1 place": ({"buffer": {"places": 1}}, lambda rho: md1k_loss(rho, 2)),
    "3 places": ({"buffer": {"places": 3, "pitch_in": 2.5}}, lambda rho: md1k_loss(rho, 4)),
    "two robots": ({"stations": [{"name": "catcher", "placement": "downstream",
                                  "offset_in": 40.0}]}, lambda rho: erlang_b(2, rho)),
}


@pytest.fixture(scope="module")
def losses() -> dict[tuple[str, float], tuple[float, float, float]]:
    """(mean, 95 % half-width, 99 % half-width) of each configuration's loss fraction."""
    out = {}
    for name, (sets, _) in CONFIGS.items():
        for i, rho in enumerate(LOADS):
            missed, cycles = [], set()

            def seen(row, missed=missed, cycles=cycles):  # noqa: ANN001, ANN202
                missed.append(row.missed)
                if row.picked:
                    cycles.add(round(row.motion_cycle_s, 9))
            simulate(_scenario(rho, {**sets, "run.seed": 7 + i}), keep_parts=False,
                     keep_belts=False, on_part=seen)
            assert cycles == {CYCLE_S}  # the server's service: exactly the fixed cycle
            lost = np.asarray(missed, dtype=float)
            batch = lost.reshape(BATCHES, -1).mean(axis=1)
            se = batch.std(ddof=1) / math.sqrt(BATCHES)
            out[name, rho] = (batch.mean(), stats.t.ppf(0.975, BATCHES - 1) * se,
                              stats.t.ppf(0.995, BATCHES - 1) * se)
    return out


@pytest.mark.parametrize("name", list(CONFIGS))
def test_loss_fraction_is_the_closed_forms(losses, name):
    exact_of = CONFIGS[name][1]
    for rho in LOADS:
        mean, half95, half99 = losses[name, rho]
        exact = exact_of(rho)
        assert half95 < 0.01, (name, rho, half95)
        assert abs(mean - exact) < half99, (name, rho, mean, exact, half99)
