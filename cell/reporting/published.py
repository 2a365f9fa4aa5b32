"""The thesis's published figures (King 1984, §7.2; docs/accounting.md), printed beside ours.

One place for every number the reports and the summary table compare against.
:data:`PUBLISHED` holds them by policy: what §7.2 printed for each, as data, so a
report routes by it rather than by policy names.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

#: Table 7.1, non-adaptive, robot cycle shortened in R IV: ideal cycle (s) ->
#: (actual cycle s, parts missed, parts/hr, Vavg R IV in/s, IP).
TABLE_7_1: dict[float, tuple[float, float, float, float, float]] = {
    22.5872: (54.1660, 206, 66.4624, 3.5594, 0.3901),
    22.0000: (35.6057, 113, 101.1074, 3.7818, 0.4388),
    21.5000: (29.0548, 64, 123.9039, 3.9943, 0.4655),
    21.0000: (25.8622, 35, 139.1995, 4.2321, 0.4817),
    20.5000: (23.8200, 14, 151.1336, 4.5000, 0.4933),
    20.0907: (23.0209, 5, 156.3796, 4.7459, 0.4984),
}
#: Table 7.1's first column, in the thesis's order.
TABLE_7_1_CYCLES: tuple[float, ...] = tuple(TABLE_7_1)
#: Table 7.1's other columns, by the measure names of the reports.
TABLE_7_1_MEASURES = ("actual_cycle_s", "parts_missed", "parts_per_hr", "vavg_r4_in_s", "ip")

#: The adaptive run (§7.2): IP averaged 1.0214, "within 2.1 percent of the requested
#: cycle time"; no parts lost is implied (§7.2 blames the non-adaptive robot's 206 on "its
#: inability to adapt"), not stated.
ADAPTIVE_IP = 1.0214
ADAPTIVE_CYCLE_PCT = 2.1
ADAPTIVE_PARTS_MISSED = 0

#: §7.2's text: "206 of 500 parts ... a 41.2 percent reduction in throughput".
TEXT_THROUGHPUT_CUT = 0.412


@dataclass(frozen=True)
class Published:
    """What §7.2 printed for one policy, all in the thesis's own accounting.

    ``by_cycle``: ideal cycle (s) -> measure -> value, one row per robot cycle the
    thesis ran (Table 7.1); ``any_cycle``: measure -> value for a policy the thesis
    ran once, at its nominal cycle (the adaptive run).  ``summary`` is the one line
    the thesis's text gives about the policy.
    """

    by_cycle: Mapping[float, Mapping[str, float]]
    any_cycle: Mapping[str, float]
    summary: str

    def value(self, cycle: float, measure: str) -> float | None:
        """The published figure for ``measure`` at ``cycle`` (to 5e-5 s), or None."""
        for c, row in self.by_cycle.items():
            if abs(c - cycle) < 5e-5:
                return row.get(measure)
        return self.any_cycle.get(measure)


#: Policy -> what the thesis published for it.
PUBLISHED: Mapping[str, Published] = MappingProxyType({
    "non-adaptive": Published(
        by_cycle={c: dict(zip(TABLE_7_1_MEASURES, (float(v) for v in row), strict=True))
                  for c, row in TABLE_7_1.items()},
        any_cycle={},
        summary="Table 7.1: the robot cycle shortened in R IV, six cycles"),
    "adaptive": Published(
        by_cycle={},
        any_cycle={"ip": ADAPTIVE_IP, "parts_missed": float(ADAPTIVE_PARTS_MISSED)},
        summary=f"IP {ADAPTIVE_IP}, within {ADAPTIVE_CYCLE_PCT} % of the requested cycle, "
                "no parts lost (implied)"),
})
