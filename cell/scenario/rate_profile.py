"""Arrivals whose rate changes over a repeating period: ``arrivals.profile``.

A profile gives relative rates, piecewise constant over a period (``period_h``): in equal
pieces, or in pieces that start at ``starts_h``.  The rates are normalised so that their
time-weighted mean over the period is 1, so the arrivals' long-run mean inter-arrival time
stays the base distribution's mean (and with it the nominal cycle and the offered load).

The arrivals are drawn by time-scaling with the integrated rate (rate inversion).  The
base distribution's inter-arrival times, one uniform a part from the feeder's stream as
without a profile, are laid end to end in *operational time*, S_k = T_1 + … + T_k; the
part comes at t_k = Λ⁻¹(S_k), where Λ(t) = ∫₀ᵗ m(x) dx is the cumulative relative rate
from the run's start.  With an exponential base that is exactly the non-homogeneous Poisson
process of rate m(t) / mean (Çinlar's time change); with any other renewal distribution the
gaps keep their shape in operational time and their mean follows the profile: about
mean / m(t) where the rate is m(t).  One uniform a part, in order, so the parts of a run
with a profile are its parts without one, moved in time (common random numbers hold
between policies and between profiles); thinning would draw a varying number of uniforms a
part and lose that.

The profile's clock is time from the run's start; ``run_start_h`` says which hour of the
period the run starts at.  A calendar could drive the same pieces by hour of shift, of day
or of week: only the clock that :meth:`Pieces.arrival_times` counts from would change.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from cell.plumbing.errors import ScenarioError

SECONDS_PER_HOUR = 3600.0
#: Pieces a profile may have (an hour's pieces over a year's period: 8,784).
MAX_PIECES = 10_000


class ProfileSpec(Protocol):
    """What the supply needs of ``arrivals.profile``."""

    @property
    def period_h(self) -> float: ...
    @property
    def rates(self) -> Sequence[float]: ...
    @property
    def starts_h(self) -> Sequence[float] | None: ...
    @property
    def run_start_h(self) -> float: ...


@dataclass(frozen=True)
class Pieces:
    """A profile's pieces over one period, in seconds, with their normalised rates."""

    period_s: float
    starts_s: NDArray[np.float64]
    """Where each piece starts in the period; the first at 0."""
    rates: NDArray[np.float64]
    """Each piece's rate relative to the mean: time-weighted mean 1 over the period."""
    phase_s: float
    """Where in the period the run starts."""

    @classmethod
    def of(cls, profile: ProfileSpec) -> Pieces:
        """The pieces of a checked profile (:func:`check_profile`)."""
        period = float(profile.period_h) * SECONDS_PER_HOUR
        n = len(profile.rates)
        starts = np.asarray(profile.starts_h, dtype=float) * SECONDS_PER_HOUR \
            if profile.starts_h is not None else np.arange(n, dtype=float) * (period / n)
        raw = np.asarray(profile.rates, dtype=float)
        lengths = np.diff(np.append(starts, period))
        rates = raw / (float(np.dot(raw, lengths)) / period)
        return cls(period, starts, rates, float(profile.run_start_h) * SECONDS_PER_HOUR)

    @property
    def lengths_s(self) -> NDArray[np.float64]:
        return np.diff(np.append(self.starts_s, self.period_s))

    @property
    def _cumulative(self) -> NDArray[np.float64]:
        """Operational time at each piece's start, and at the period's end (its last entry)."""
        return np.concatenate(([0.0], np.cumsum(self.rates * self.lengths_s)))

    def operational(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Λ(t): operational time from the run's start to ``t`` s after it."""
        return self._from_period_start(np.asarray(t, dtype=float) + self.phase_s) - \
            float(self._from_period_start(np.array([self.phase_s]))[0])

    def arrival_times(self, operational: NDArray[np.float64]) -> NDArray[np.float64]:
        """Λ⁻¹: the times from the run's start at which ``operational`` time is reached."""
        k_cum = self._cumulative
        whole = float(k_cum[-1])
        y = np.asarray(operational, dtype=float) + \
            float(self._from_period_start(np.array([self.phase_s]))[0])
        periods = np.floor(y / whole)
        rest = y - periods * whole
        i = np.clip(np.searchsorted(k_cum, rest, side="right") - 1, 0, self.rates.size - 1)
        x = periods * self.period_s + self.starts_s[i] + (rest - k_cum[i]) / self.rates[i]
        return x - self.phase_s

    def rate_at(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """The relative rate ``t`` s after the run's start."""
        within = np.mod(np.asarray(t, dtype=float) + self.phase_s, self.period_s)
        return self.rates[np.searchsorted(self.starts_s, within, side="right") - 1]

    def _from_period_start(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        k_cum = self._cumulative
        periods = np.floor(x / self.period_s)
        within = x - periods * self.period_s
        i = np.clip(np.searchsorted(self.starts_s, within, side="right") - 1, 0, self.rates.size - 1)
        return periods * k_cum[-1] + k_cum[i] + (within - self.starts_s[i]) * self.rates[i]


def scaled_gaps(gaps: NDArray[np.float64], profile: ProfileSpec) -> NDArray[np.float64]:
    """Inter-arrival times drawn in operational time (``gaps``), as the run's gaps under the
    profile: the differences of Λ⁻¹ of their running sums (≥ 0; the first from the start)."""
    times = Pieces.of(profile).arrival_times(np.cumsum(gaps))
    return np.maximum(np.diff(times, prepend=0.0), 0.0)


def describe(profile: ProfileSpec) -> str:
    """How far the rate moves, over what period (for the line saying the arrivals are not
    stationary)."""
    p = Pieces.of(profile)
    start = f", the run starting at hour {profile.run_start_h:g} of it" if profile.run_start_h else ""
    return (f"the rate runs from {p.rates.min():.3g} to "
            f"{p.rates.max():.3g} times its mean in {p.rates.size} pieces of each "
            f"{profile.period_h:g}-hour period{start}; the mean inter-arrival time is the long run's")


def check_profile(profile: ProfileSpec, trace: str | None, file: object) -> None:
    """Refuse a profile with a trace, without rates, or whose pieces do not cover its period
    (the first not at 0, starts not increasing, one at or beyond the period's end); a run
    starting beyond the period.  (Rates not > 0 the schema refuses.)"""
    key = "arrivals.profile"
    if trace is not None:
        raise ScenarioError(file, key, _shown(profile), "a trace (arrivals.trace_csv) is replayed "
                            "as logged, its times already varying as they did: give a trace or a "
                            "profile, not both")
    rates, period = list(profile.rates), float(profile.period_h)
    if not rates or len(rates) > MAX_PIECES:
        raise ScenarioError(file, f"{key}.rates", rates,
                            f"give between 1 and {MAX_PIECES:,} relative rates")
    if not profile.run_start_h < period:
        raise ScenarioError(file, f"{key}.run_start_h", profile.run_start_h,
                            f"must be less than arrivals.profile.period_h ({period:g})")
    starts = profile.starts_h
    if starts is None:
        return
    starts = list(starts)
    if len(starts) != len(rates):
        raise ScenarioError(file, f"{key}.starts_h", starts, f"give one start a rate: "
                            f"{len(rates)} rates, {len(starts)} starts")
    if starts[0] != 0:
        raise ScenarioError(file, f"{key}.starts_h[0]", starts[0], "the first piece must start "
                            "at 0, so that the pieces cover the period")
    for i in range(1, len(starts)):
        if not starts[i] > starts[i - 1]:
            raise ScenarioError(file, f"{key}.starts_h[{i}]", starts[i],
                                f"must be after the piece before it ({starts[i - 1]:g})")
    if not starts[-1] < period:
        raise ScenarioError(file, f"{key}.starts_h[{len(starts) - 1}]", starts[-1],
                            f"must be less than arrivals.profile.period_h ({period:g}): every "
                            "piece lies within the period")


def _shown(profile: ProfileSpec) -> dict[str, object]:
    return {"period_h": profile.period_h, "rates": list(profile.rates)}
