"""The thesis's published figures (King 1984, §7.2; SPEC §8), printed beside ours.

One place for every number the reports and the summary table compare against.
"""

from __future__ import annotations

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

#: The adaptive run (§7.2): IP averaged 1.0214, "within 2.1 percent of the requested
#: cycle time", no parts lost.
ADAPTIVE_IP = 1.0214
ADAPTIVE_CYCLE_PCT = 2.1
ADAPTIVE_PARTS_MISSED = 0

#: §7.2's text: "206 of 500 parts ... a 41.2 percent reduction in throughput".
TEXT_THROUGHPUT_CUT = 0.412
