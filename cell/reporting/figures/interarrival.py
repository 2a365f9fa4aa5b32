"""The parts supply: Fig. 13 and 14 (thesis §6.2 d, eq. 6.8-6.9)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import scipy.stats
from matplotlib.figure import Figure
from numpy.typing import NDArray

from cell.reporting.figures.style import new_figure, save
from cell.scenario.arrivals import parameters
from cell.scenario.schema import Scenario


def distribution(s: Scenario) -> Any:
    """The scenario's frozen inter-arrival distribution (eq. 6.9 by default; by ``params``
    or by ``mean_s`` and ``cv``, as the feeder draws from it); None for a trace."""
    if s.arrivals.trace_csv is not None:
        return None
    return getattr(scipy.stats, s.arrivals.distribution)(**parameters(s.arrivals))


def draws(s: Scenario, n: int) -> NDArray[np.float64]:
    """The first n inter-arrival times the simulation feeds (inverse cdf, eq. 6.9;
    the feeder's own stream of ``run.seed``)."""
    from cell.scenario.arrivals import interarrival_times

    return interarrival_times(s.arrivals, n, s.run.seed, s.base_dir)


def _times(n: int) -> str:
    return f"{n} inter-arrival time" + ("s" if n > 1 else "")


def _params_note(s: Scenario, x: NDArray[np.float64]) -> str:
    d = distribution(s)
    seen = (f"{x.size} draws: mean {x.mean():.3f} s, sd {x.std(ddof=1):.3f} s" if x.size > 1
            else f"1 draw: {x[0]:.3f} s")  # one draw has no sample sd
    if d is None:
        return f"the trace {s.arrivals.trace_csv}, replayed in order; {seen}"
    p = ", ".join(f"{k} = {v:.4f}" for k, v in parameters(s.arrivals).items())
    return f"{s.arrivals.distribution}({p}): mean {d.mean():.3f} s, sd {d.std():.3f} s; {seen}"


#: Titles' names of the families most used for arrivals; any other goes by its scipy name.
FAMILY_NAMES = {"weibull_min": "Weibull", "gamma": "Gamma", "lognorm": "Lognormal",
                "expon": "Exponential", "norm": "Normal"}
#: What Fig. 13 and 14 draw of a trace, which has no distribution: its data only.
TRACE_CURVES = {"pdf": "Histogram", "cdf": "Empirical cdf"}


def caption(s: Scenario, curve: str) -> str:
    """Fig. 13's (``curve`` "pdf") or 14's ("cdf") caption, after what is drawn: the
    family's curve (the thesis's "Weibull pdf of the Inter-arrival Times" for eq. 6.9), or a
    trace's histogram or empirical cdf."""
    if s.arrivals.trace_csv is not None:
        return f"{TRACE_CURVES[curve]} of the Inter-arrival Times (trace)"
    family = s.arrivals.distribution
    return f"{FAMILY_NAMES.get(family, family)} {curve} of the Inter-arrival Times"


def _cited(s: Scenario, equation: str) -> str:
    """A legend's citation of ``equation`` (6.8, the pdf; 6.9, the inverse cdf), which are
    the thesis's Weibull's: for a Weibull only, nothing for another family."""
    return f" (eq. {equation})" if s.arrivals.distribution == "weibull_min" else ""


def _grid(s: Scenario, x: NDArray[np.float64]) -> NDArray[np.float64]:
    d = distribution(s)
    lo, hi = float(x.min()), float(x.max())
    if d is not None:
        lo, hi = min(float(d.ppf(1e-4)), lo), max(float(d.ppf(1 - 1e-4)), hi)
    return np.linspace(lo - 0.5, hi + 0.5, 600)


#: Fig. 13's histogram has this many bins, or one a draw if there are fewer draws.
BINS = 30
#: Fewer draws than this get no histogram in Fig. 13 (a bar or two would tower over the pdf):
#: each draw is marked on the axis instead.
MIN_HISTOGRAM_DRAWS = 5


def _draws_drawn(ax: Any, s: Scenario, x: NDArray[np.float64]) -> float:
    """Draw Fig. 13's draws: a histogram, or marks on the axis below
    :data:`MIN_HISTOGRAM_DRAWS`; return the histogram's tallest bar (0 for marks)."""
    label = f"the {_times(x.size)} of the run (seed {s.run.seed})"
    if x.size < MIN_HISTOGRAM_DRAWS:
        ax.plot(x, np.zeros_like(x), "|", ms=16, mew=2.2, color="#3182bd", clip_on=False,
                label=f"{label}:\ntoo few for a histogram, each marked on the axis")
        return 0.0
    heights, _, _ = ax.hist(x, bins=min(BINS, x.size), density=True, color="#9ecae1",
                            edgecolor="white", label=label)
    return float(heights.max())


def fig13_figure(s: Scenario, x: NDArray[np.float64]) -> Figure:
    """Fig. 13, the draws' histogram under the distribution's pdf (not saved)."""
    fig, ax = new_figure(13, caption(s, "pdf"))
    d = distribution(s)
    t = _grid(s, x)
    top = _draws_drawn(ax, s, x)
    if d is not None:
        ax.plot(t, d.pdf(t), color="black", label=f"pdf{_cited(s, '6.8')}")
        ax.axvline(d.mean(), color="#d62728", ls="--", lw=1.2, label=f"mean {d.mean():.4f} s")
        loc = parameters(s.arrivals).get("loc")
        if loc is not None:
            ax.axvline(loc, color="0.4", ls=":", lw=1.2, label=f"location {loc:g} s")
        top = max(top, float(d.pdf(t).max()))
    ax.set_xlabel("inter-arrival time T (s)")
    ax.set_ylabel("probability density (1/s)")
    ax.set_ylim(0, 1.45 * top if top > 0 else 1.0)  # a trace's few draws: no density to show
    ax.legend(loc="upper left")
    ax.set_title(_params_note(s, x), loc="left", fontsize=8.5)
    return fig


def fig13_pdf(s: Scenario, x: NDArray[np.float64], out: Path) -> Path:
    return save(fig13_figure(s, x), out)


def fig14_figure(s: Scenario, x: NDArray[np.float64]) -> Figure:
    """Fig. 14, the draws' empirical cdf under the distribution's cdf (not saved)."""
    fig, ax = new_figure(14, caption(s, "cdf"))
    d = distribution(s)
    t = _grid(s, x)
    xs = np.sort(x)
    ax.step(xs, np.arange(1, xs.size + 1) / xs.size, where="post", color="#6baed6", lw=2.2,
            label=f"empirical cdf of the run's {x.size} draw{'s' if x.size > 1 else ''}")
    if d is not None:
        ax.plot(t, d.cdf(t), color="black", lw=1.3, label="cdf F(T)")
        u = 0.5
        tu = float(d.ppf(u))
        ax.plot([t[0], tu, tu], [u, u, 0], color="#d62728", ls="--", lw=1.1,
                label=f"inverse cdf{_cited(s, '6.9')}: u = {u} → T = {tu:.4f} s")
        ks = scipy.stats.kstest(x, d.cdf)
        title = (f"T = F⁻¹(u) with u ~ U(0, 1); Kolmogorov-Smirnov D = {ks.statistic:.3f}, "
                 f"p = {ks.pvalue:.2f}")
    else:
        title = f"the trace {s.arrivals.trace_csv}, replayed in order: no distribution to draw"
    ax.set_xlabel("inter-arrival time T (s)")
    ax.set_ylabel("cumulative probability u")
    ax.set_ylim(0, 1.02)
    ax.set_xlim(t[0], t[-1])
    ax.legend(loc="lower right")
    ax.set_title(title, loc="left", fontsize=9)
    return fig


def fig14_cdf(s: Scenario, x: NDArray[np.float64], out: Path) -> Path:
    return save(fig14_figure(s, x), out)
