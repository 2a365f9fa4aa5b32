"""Gaps far out of the body of the data: a line's stoppages among the gaps between parts.

A log of part times holds the line's stoppages too (a jam, a break, a shift change): a few
gaps of minutes among gaps of seconds.  Fitted with the rest they stretch the data's sd and
drag every family's tail, and the fit then stands for neither the flow nor the stoppages.
:func:`far_out` finds them by Tukey's rule for far-out values (beyond Q3 + 3 IQR, the
outer fence of a box plot); :func:`leave_out` removes the gaps beyond a bound (``--max-gap S``,
or the fence itself with ``--drop-outliers``) and says what it removed, for the written
block's comment.  A stoppage is better modelled as such (a failure of the line, the
scenario's ``failures:``) than as a long gap between parts.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

#: The fence is Q3 + FENCE × IQR (Tukey's outer fence: "far out").
FENCE = 3.0
#: Far-out gaps are flagged when they are at most this share of the gaps: stoppages are
#: rare, and a fifth of the gaps beyond the fence (a line whose gaps are 12 s and every fifth
#: 60 s: IQR 0) are part of how the line runs, not out of it.
FLAG_SHARE = 0.05


class Tail(NamedTuple):
    """The gaps beyond ``limit`` seconds: how many of ``n``, the least and largest, their sum."""

    limit: float
    found: int
    n: int
    least: float
    largest: float
    total: float
    share: float
    """Their sum as a fraction of the sum of all the gaps (of the time the log spans)."""

    def sizes(self) -> str:
        """'612.3 to 3590 s, 1.23e+04 s in all (31% of the time)'; the one gap's size for one."""
        if self.found == 1:
            span = f"{self.largest:.4g} s"
        elif self.least < self.largest:
            span = f"{self.least:.4g} to {self.largest:.4g} s, {self.total:.4g} s in all"
        else:
            span = f"each {self.largest:.4g} s, {self.total:.4g} s in all"
        return f"{span} ({self.share:.0%} of the time)"


def fence(x: NDArray[np.float64]) -> float:
    """Q3 + :data:`FENCE` × IQR of ``x`` (numpy's default, linear, quantiles)."""
    q1, q3 = (float(v) for v in np.percentile(x, [25.0, 75.0]))
    return q3 + FENCE * (q3 - q1)


def beyond(x: NDArray[np.float64], limit: float) -> Tail:
    """The gaps of ``x`` longer than ``limit``."""
    far = x[x > limit]
    whole = float(x.sum())
    total = float(far.sum())
    return Tail(limit, int(far.size), int(x.size), float(far.min()) if far.size else 0.0,
                float(far.max()) if far.size else 0.0, total, total / whole if whole > 0 else 0.0)


def far_out(x: NDArray[np.float64]) -> Tail:
    """The gaps beyond Q3 + 3 IQR (:func:`fence`)."""
    return beyond(x, fence(x))


def flagged(tail: Tail) -> bool:
    """Whether ``tail`` is worth a warning: some gaps, and at most :data:`FLAG_SHARE` of them."""
    return 0 < tail.found <= FLAG_SHARE * tail.n


def flag(tail: Tail, noun: str = "gaps") -> str:
    """The warning for far-out gaps (when :func:`flagged`), and the two ways to leave them out."""
    return (f"{tail.found} of {tail.n} {noun} lie far out of the body of the data, beyond Q3 + 3 IQR "
            f"= {tail.limit:.4g} s: {tail.sizes()}; they are fitted with the rest. If they are "
            f"stoppages, leave them out with --max-gap S or --drop-outliers (and model them as "
            f"failures:)")


def leave_out(x: NDArray[np.float64], limit: float, how: str) -> tuple[NDArray[np.float64], str]:
    """The gaps of ``x`` no longer than ``limit``, and what was left out (for the written
    block's comment; "" when nothing was): ``how`` names the option that asked."""
    tail = beyond(x, limit)
    kept = x[x <= limit]
    if not tail.found:
        return kept, ""
    return kept, (f"left out: {tail.found} of {tail.n} gaps longer than {limit:.4g} s ({how}): "
                  f"{tail.sizes()}; the fit is of the other {kept.size}")
