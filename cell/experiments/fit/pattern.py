"""Does a log of arrivals have a pattern: a trend, a rate that changes with the time of day (or
of shift), successive gaps that are correlated?  (``cell fit``, before any iid fit.)

Three statistics of the log, in its order:

- **trend**: Laplace's, the mean of the arrival times against the middle of the log's span;
  when the log spans two or more periods counted over, the mean of the index of the whole
  period each arrival falls in against the middle one (so that a rate changing within each
  period is no trend); shown as Laplace's z;
- **time of day**: Pearson's chi-square of the counts of arrivals by hour of a period (a
  shift, a day), each hour's expected count from the time the log spends in it (a log need
  not hold whole periods); with no period given, the largest over 8 and 24 hours (each as its
  chi-square p-value) among those the log spans at least twice;
- **correlation**: the lag-1 autocorrelation of successive gaps.

Each p-value is a permutation test's: under the null hypothesis the gaps are independent and
identically distributed, so every order of them is equally likely; the statistic of the log
is ranked among those of :data:`PERMUTATIONS` random orders of the same gaps (fewer for a long
log, :func:`orders`; seeded: the
same log gives the same p-values), p = (1 + those at least as large) / (1 + permutations).
That holds exactly whatever the gaps' distribution (the chi-square's own p-value assumes a
Poisson process, and would alarm far too often on the thesis's near-regular Weibull), with
no asymptotics.  The three p-values are corrected by Holm's method, so the chance that an
iid log is said to have any pattern is at most :data:`LEVEL` (5 %; with three tests near
independent it is about 1 − (1 − 0.05 / 3)³ = 4.9 %).  1,200 orders (the log's and 1,199 random
ones) make α/3 and α/2 whole multiples of 1/1,200, so each permutation test's own level is
exactly its threshold.

When the time-of-day test rejects, :meth:`Pattern.profile` is the rate profile the counts
estimate (relative rates by hour of the period, as ``arrivals.profile`` takes them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.scenario.rate_profile import Pieces
from cell.scenario.sections import RateProfile

#: The false-alarm rate of the combined decision (Holm over the tests run).
LEVEL = 0.05
#: Random orders of the gaps each statistic is ranked among; 1 + this is a multiple of 60,
#: so that LEVEL / 3 and LEVEL / 2 are whole multiples of the p-values' step.  Fewer for a
#: long log (:func:`orders`): no fewer than 119, the gaps times the orders at most :data:`WORK`.
PERMUTATIONS = 1199
WORK = 3_000_000
#: A longer log is tested on its first this many gaps (the work stays bounded: seconds).
MAX_TESTED = 20_000
#: Periods tried when none is given (a shift, a day), in hours.
CANDIDATE_PERIODS_H = (8.0, 24.0)
#: Periods the log must span for an inferred period to be tried (one, for a period given).
MIN_SPANS = 2.0
_SEED = 1984
_CHUNK = 400


@dataclass(frozen=True)
class Clock:
    """A period (h) and where one starts on the log's clock (h after its midnight, or after
    its 0 s), and whether they were inferred."""

    period_h: float
    start_h: float
    inferred: bool

    @property
    def pieces(self) -> int:
        """Pieces of the period counted over: its hours (at least 2)."""
        return max(2, round(self.period_h))


@dataclass(frozen=True)
class Finding:
    """One test: its name, the statistic as shown, its permutation p-value, and whether Holm's
    method rejects it at :data:`LEVEL`."""

    name: str
    shown: str
    p_value: float
    rejected: bool = False


@dataclass(frozen=True)
class Pattern:
    """What the tests found in a log."""

    findings: tuple[Finding, ...]
    clock: Clock | None
    """The period counted over (None: the log is too short for a time-of-day test)."""
    rates: tuple[float, ...] | None
    """Relative rate in each piece of the period (counts over time spent; mean 1)."""
    run_start_h: float
    """Where in the period the log's first arrival lies, h."""
    not_run: str = ""

    @property
    def found(self) -> bool:
        return any(f.rejected for f in self.findings)

    @property
    def by_time(self) -> bool:
        """The time-of-day test rejects: the rate changes over the period."""
        return any(f.rejected and f.name == "time of day" for f in self.findings)

    def lines(self) -> list[str]:
        """What was found, in one line (and one on what is written, for ``cell fit``)."""
        said = "; ".join(f"{f.shown} (p = {_p(f.p_value)}{', found' if f.rejected else ''})"
                         for f in self.findings)
        verdict = "pattern found" if self.found else "no pattern found"
        return [f"{verdict} (Holm over {len(self.findings)} permutation tests, false-alarm rate "
                f"at most {LEVEL:.0%}): {said}" + (f"; {self.not_run}" if self.not_run else "")]

    def profile(self) -> RateProfile | None:
        """The ``arrivals.profile`` the counts estimate (None without a clock)."""
        if self.clock is None or self.rates is None:
            return None
        return RateProfile(period_h=float(self.clock.period_h), rates=list(self.rates),
                           run_start_h=self.run_start_h)


def _p(p: float) -> str:
    return f"{p:.2g}"


def holm(p_values: Sequence[float], level: float = LEVEL) -> list[bool]:
    """Holm's step-down rejections: the i-th smallest p-value is compared with level / (m − i)
    until one is not below it."""
    order = np.argsort(p_values, kind="stable")
    m = len(p_values)
    out = [False] * m
    for i, j in enumerate(order):
        if not p_values[j] <= level / (m - i) * (1 + 1e-12):
            break
        out[j] = True
    return out


def exposure(phase_s: NDArray[np.float64], span_s: NDArray[np.float64], period_s: float,
             pieces: int) -> NDArray[np.float64]:
    """Seconds windows of ``span_s`` starting ``phase_s`` into a period spend in each of its
    ``pieces`` equal pieces: a row a window."""
    width = period_s / pieces
    phase, span = np.atleast_1d(phase_s)[:, None], np.atleast_1d(span_s)[:, None]
    whole = np.floor(span / period_s)
    rest = span - whole * period_s
    edges = np.arange(2 * pieces + 1) * width
    overlap = np.clip(np.minimum(phase + rest, edges[1:]) - np.maximum(phase, edges[:-1]), 0.0, None)
    return np.asarray(whole * width + overlap[:, :pieces] + overlap[:, pieces:], dtype=float)


@dataclass(frozen=True)
class _Log:
    """Where a log's left-out gaps (stoppages) lie in it: they keep their places when the
    other gaps are put in another order."""

    kept: NDArray[np.bool_]
    out_at: NDArray[np.int64]
    out_s: NDArray[np.float64]

    @classmethod
    def of(cls, gaps: NDArray[np.float64], kept: NDArray[np.bool_] | None) -> _Log:
        k = np.ones(gaps.size, dtype=bool) if kept is None else np.asarray(kept, dtype=bool)
        out = np.flatnonzero(~k)
        return cls(k, out, gaps[out])


@dataclass(frozen=True)
class _Bins:
    """The counting of one clock: its pieces, and where in the period the log's first arrival
    lies."""

    clock: Clock
    phase_s: float

    @classmethod
    def of(cls, clock: Clock, first_h: float) -> _Bins:
        return cls(clock, ((first_h - clock.start_h) * 3600.0) % (clock.period_h * 3600.0))

    def counts(self, times: NDArray[np.float64], log: _Log) -> tuple[NDArray[np.float64],
                                                                   NDArray[np.float64]]:
        """Arrivals that end a kept gap in each piece, and the time the kept gaps spend in each,
        a row a log (``times``: its arrival times from the first)."""
        period = self.clock.period_h * 3600.0
        k = self.clock.pieces
        ends = times[:, 1:][:, log.kept]
        piece = np.minimum(((ends + self.phase_s) % period // (period / k)).astype(np.int64), k - 1)
        rows = np.arange(times.shape[0])[:, None] * k
        counts = np.bincount((rows + piece).ravel(), minlength=times.shape[0] * k) \
            .reshape(times.shape[0], k).astype(float)
        time_in = exposure(np.array([self.phase_s]), times[:1, -1], period, k)
        for at, length in zip(log.out_at, log.out_s):
            time_in = time_in - exposure((times[:, at] + self.phase_s) % period,
                                         np.full(times.shape[0], length), period, k)
        return counts, time_in

    def log_p(self, times: NDArray[np.float64], log: _Log) -> NDArray[np.float64]:
        """−log of the chi-square p-value of each row's counts (large: far from flat)."""
        from scipy import stats

        counts, time_in = self.counts(times, log)
        expected = counts.sum(axis=1, keepdims=True) * time_in / time_in.sum(axis=1, keepdims=True)
        keep = expected[0] > 0
        x2 = ((counts - expected) ** 2 / np.where(expected > 0, expected, 1.0))[:, keep].sum(axis=1)
        return np.asarray(-stats.chi2.logsf(x2, keep.sum() - 1), dtype=float)


def trend_period(span_s: float, bins: Sequence[_Bins]) -> float | None:
    """The period the trend is counted in (s): the longest counted over when the log spans
    two of them or more (whole periods: a rate changing within each is then no trend); None:
    the trend is over the log's span."""
    periods = [b.clock.period_h * 3600.0 for b in bins if span_s >= 2 * b.clock.period_h * 3600.0]
    return max(periods) if periods else None


def laplace(times: NDArray[np.float64], period: float | None) -> NDArray[np.float64]:
    """Laplace's z of each row of arrival times (from the first arrival): over the log's span,
    (mean − T/2) / (T / √(12 m)) over the m arrivals after the first and before the last; or,
    by whole ``period``s, the mean index of the period each of the m arrivals in the K whole
    periods falls in, against (K + 1) / 2, over √((K² − 1) / (12 m))."""
    span = times[:, -1:]
    if period is None:
        inner = times[:, 1:-1]
        m = max(inner.shape[1], 1)
        return np.asarray((inner.mean(axis=1) - span[:, 0] / 2) / (span[:, 0] / math.sqrt(12 * m)),
                          dtype=float)
    k = math.floor(float(span[0, 0]) / period)
    index = times // period + 1
    inside = (times > 0) & (index <= k)
    m = np.maximum(inside.sum(axis=1), 1)
    mean = np.where(inside, index, 0.0).sum(axis=1) / m
    return np.asarray((mean - (k + 1) / 2) / np.sqrt((k * k - 1) / (12 * m)), dtype=float)


def _times(gaps: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.concatenate([np.zeros((gaps.shape[0], 1)), np.cumsum(gaps, axis=1)], axis=1)


def _statistics(gaps: NDArray[np.float64], log: _Log, bins: Sequence[_Bins]) -> NDArray[np.float64]:
    """Each row's (|trend|, time of day, |lag-1 correlation|): a row of ``gaps`` a log; the
    trend and the correlation of the kept gaps (the flow, stoppages cut out), the time of day
    on the log's clock."""
    flow = gaps[:, log.kept]
    flow_times = _times(flow)
    trend = np.abs(laplace(flow_times, trend_period(float(flow_times[0, -1]), bins)))
    centred = flow - flow.mean(axis=1, keepdims=True)
    corr = np.abs((centred[:, 1:] * centred[:, :-1]).sum(axis=1) / (centred ** 2).sum(axis=1))
    times = _times(gaps)
    tod = np.max([b.log_p(times, log) for b in bins], axis=0) if bins else np.zeros(gaps.shape[0])
    return np.stack([trend, tod, corr], axis=1)


def clocks(span_s: float, first_h: float, period_h: float | None,
           start_h: float | None) -> tuple[list[Clock], str]:
    """The clocks to count over, and why there is none ("" when there is one): the period
    given (if the log spans one), or each of :data:`CANDIDATE_PERIODS_H` it spans twice; a
    period starts at ``start_h``, or at the whole hour the log begins in."""
    start = start_h if start_h is not None else math.floor(first_h)
    if period_h is not None:
        if span_s < period_h * 3600.0:
            return [], f"no time-of-day test: the log spans {span_s / 3600:.3g} h, less than " \
                       f"one {period_h:g}-hour period"
        return [Clock(period_h, start, False)], ""
    tried = [Clock(p, start, True) for p in CANDIDATE_PERIODS_H
             if span_s >= MIN_SPANS * p * 3600.0]
    why = "" if tried else (f"no time-of-day test: the log spans {span_s / 3600:.3g} h, less than "
                            f"two {CANDIDATE_PERIODS_H[0]:g}-hour periods (--period-h H tests one)")
    return tried, why


def orders(n: int) -> int:
    """Random orders for a log of ``n`` gaps: :data:`PERMUTATIONS`, fewer (in steps of 60)
    where ``n`` times them would pass :data:`WORK`, at least 119."""
    return max(120, min(PERMUTATIONS + 1, 60 * (WORK // (60 * max(n, 1))))) - 1


def find_pattern(gaps: Sequence[float], first_h: float = 0.0, period_h: float | None = None,
                 start_h: float | None = None, kept: Sequence[bool] | None = None,
                 permutations: int | None = None, level: float = LEVEL) -> Pattern:
    """Test a log's gaps, in order (the first arrival ``first_h`` hours into its clock), for a
    trend, a time-of-day pattern and correlated gaps (see the module's docstring); ``kept``:
    the gaps fitted (None: all), the others (stoppages) staying where they are; the first
    :data:`MAX_TESTED` gaps of a longer log; ``permutations``: by default :func:`orders`."""
    x = np.asarray(gaps, dtype=float)
    mask = None if kept is None else np.asarray(kept, dtype=bool)
    cut = f"tested on the first {MAX_TESTED:,} of the {x.size:,} gaps" if x.size > MAX_TESTED else ""
    x, mask = x[:MAX_TESTED], None if mask is None else mask[:MAX_TESTED]
    permutations = orders(x.size) if permutations is None else permutations
    log = _Log.of(x, mask)
    flow = x[log.kept]
    tried, why = clocks(float(x.sum()), first_h, period_h, start_h)
    why = "; ".join(w for w in (why, cut) if w)
    bins = [_Bins.of(c, first_h) for c in tried]
    observed = _statistics(x[None, :], log, bins)[0]
    beaten = np.zeros(3)
    rng = np.random.default_rng(_SEED)
    done = 0
    while done < permutations:
        m = min(_CHUNK, permutations - done)
        shuffled = np.array(np.broadcast_to(x, (m, x.size)))
        shuffled[:, log.kept] = rng.permuted(np.broadcast_to(flow, (m, flow.size)), axis=1)
        beaten += (_statistics(shuffled, log, bins) >= observed * (1 - 1e-12)).sum(axis=0)
        done += m
    p = (1.0 + beaten) / (1.0 + permutations)
    flow_times = _times(flow[None, :])
    period = trend_period(float(flow_times[0, -1]), bins)
    z = float(laplace(flow_times, period)[0])
    centred = flow - flow.mean()
    r1 = float((centred[1:] * centred[:-1]).sum() / (centred ** 2).sum())
    over = f" by whole {period / 3600:g}-hour periods" if period is not None else ""
    shown = [("trend", f"trend: Laplace z = {z:+.2f}{over}", p[0])]
    times = _times(x[None, :])
    chosen = max(bins, key=lambda b: float(b.log_p(times, log)[0])) if bins else None
    if chosen is not None:
        c = chosen.clock
        counts, time_in = (v[0] for v in chosen.counts(times, log))
        expected = counts.sum() * time_in / time_in.sum()
        x2 = float(((counts - expected) ** 2 / expected)[expected > 0].sum())
        how = "inferred" if c.inferred and start_h is None else "given"
        shown.append(("time of day", f"counts by hour of a {c.period_h:g}-hour period starting at "
                      f"{_hhmm(c.start_h)} ({how}): chi-square {x2:.1f}, {c.pieces - 1} df", p[1]))
    shown.append(("correlation", f"lag-1 correlation of gaps {r1:+.3f}", p[2]))
    rejected = holm([s[2] for s in shown], level)
    findings = tuple(Finding(n, s, float(q), r) for (n, s, q), r in zip(shown, rejected))
    if chosen is None:
        return Pattern(findings, None, None, 0.0, why)
    relative = counts / time_in / (counts.sum() / time_in.sum())  # each piece spanned
    rounded = tuple(float(f"{v:.3g}") for v in relative)
    start = round(chosen.phase_s / 3600.0, 4)
    return Pattern(findings, chosen.clock, rounded, start if start < chosen.clock.period_h else 0.0, why)


def _hhmm(hours: float) -> str:
    minutes = round(hours * 60)
    return f"{minutes // 60:02d}:{minutes % 60:02d}"


def operational_gaps(gaps: Sequence[float], profile: RateProfile) -> NDArray[np.float64]:
    """A log's gaps in operational time under ``profile`` (the log's first arrival at its
    ``run_start_h``): the differences of Λ of the arrival times, which a scenario's base
    distribution draws (:mod:`cell.scenario.rate_profile`)."""
    times = np.concatenate([[0.0], np.cumsum(np.asarray(gaps, dtype=float))])
    return np.diff(Pieces.of(profile).operational(times))


def profile_yaml(profile: RateProfile) -> str:
    """The ``profile:`` line of an ``arrivals:`` block, as a scenario reads it back."""
    rates = ", ".join(f"{r:g}" for r in profile.rates)
    return (f"  profile: {{period_h: {profile.period_h:g}, rates: [{rates}], "
            f"run_start_h: {profile.run_start_h:g}}}\n")
