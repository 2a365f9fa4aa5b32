"""The hindsight optimum's lower side: a schedule that knows the future, run through the real
simulation, so that the plan check vouches for every cycle of it (docs/model.md, "The hindsight
optimum").

:class:`HindsightPolicy` is a plug-in policy handed the feeder's schedule (the trace) and,
optionally, the parts to aim for and when (the MILP's schedule).  It keeps its own copy of the
input belt's schedule (every change is its own, and the feeder's rule is the model's), so at each
decision it knows where every part is and will be.  It then chooses the next part to pick, q:
the next of its targets that it can still reach, or (greedy) the first part it can; the belt's
speed after lift-off w (first from a finite set, :data:`SPEED_STEPS` speeds from the floor to
the ceiling, evenly in 1/v, then refined by bisection), after the cycle w' (the fastest the robot
can follow, the nominal speed or the floor), the cycle's end E (R IV made longer) and, when it
follows a schedule's drops, how much longer R I tracks before lift-off (:data:`HOLDS_S`), so
that every part before q reaches B while the robot is away and q after it is back.  Among those
it takes the plan that brings q to B nearest the target's instant with the drops nearest the
target's (greedy: q soonest).  Whatever it plans, the simulation carries out and counts.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cell.scenario.schema import Scenario
from cell.sim.assembly import AssembledCell
from cell.sim.policies.base import CellConstants, CellView, Plan, Policy
from cell.sim.simulation import SimResult, simulate

#: The belt speeds after lift-off the search tries, floor to ceiling.
SPEED_STEPS = 24
#: A part aimed to reach B while the robot is away (or back) misses the cycle's end by this
#: much at least (s): far above the simulation's rounding (EPS_S, 1e-6 s).
MARGIN_S = 1e-3
#: How much longer than its shortest the search may make R I before lift-off (s), so that the
#: belt keeps its speed longer, when it follows a schedule's drops.
HOLDS_S = (0.0, 1.0, 2.5, 5.0, 8.0)
#: The parts after the one at B the search looks at for the next pick.
LOOK_PARTS = 40


class BeltCopy:
    """The input belt's speed schedule as the policy planned it (:class:`cell.sim.conveyors.Belt`'s
    rule: from t1 run at v1, from t2 at v2, what was planned after t1 dropped)."""

    def __init__(self, v0: float, ts: Sequence[float] = (0.0,), xs: Sequence[float] = (0.0,),
                 vs: Sequence[float] | None = None):
        self.ts, self.xs = list(ts), list(xs)
        self.vs = list(vs) if vs is not None else [v0]

    def travel(self, t: float) -> float:
        k = max(bisect_right(self.ts, t) - 1, 0)
        return self.xs[k] + self.vs[k] * (t - self.ts[k])

    def time_at(self, x: float) -> float:
        k = max(bisect_right(self.xs, x) - 1, 0)
        return self.ts[k] + (x - self.xs[k]) / self.vs[k]

    def planned(self, t1: float, v1: float, t2: float, v2: float) -> BeltCopy:
        """A copy with the plan (t1, v1, t2, v2) made."""
        k = bisect_right(self.ts, t1)
        ts, xs, vs = self.ts[:k], self.xs[:k], self.vs[:k]
        x1 = xs[-1] + vs[-1] * (t1 - ts[-1])
        return BeltCopy(0.0, ts + [t1, t2], xs + [x1, x1 + v1 * (t2 - t1)], vs + [v1, v2])


class Drops:
    """Where the feeder drops each part on a belt schedule (its rule: at its time, or held
    until the belt has carried the last part a part's size clear)."""

    def __init__(self, come_s: Sequence[float], size: float):
        self.come, self.size = list(come_s), size
        self.x: list[float] = []
        """Drop positions of the parts dropped so far (final)."""

    def positions(self, belt: BeltCopy, upto: int, final_before: float) -> list[float]:
        """Drop positions of parts 0 … ``upto`` on ``belt``; those dropped before
        ``final_before`` are kept (the belt's schedule before then is settled)."""
        xs = list(self.x)
        while len(xs) <= upto and len(xs) < len(self.come):
            j = len(xs)
            f = self.come[j]
            x = belt.travel(f)
            if xs and x < xs[-1] + self.size - 1e-9:
                t = belt.time_at(xs[-1] + self.size)
                x = belt.travel(t)
                f = t
            xs.append(x)
            if f < final_before and len(self.x) == j:
                self.x.append(x)
        return xs


@dataclass(frozen=True)
class Targets:
    """A schedule to follow (the MILP's): the parts to pick, when each reaches B (-inf: as soon
    as it can), and, if given, the belt's travel at each drop."""

    picked: Sequence[bool]
    at_b_s: Sequence[float]
    drop_in: Sequence[float] | None = None


class HindsightPolicy(Policy):
    """A policy that knows the trace (``come_s``) and aims for ``targets`` (parts to pick and
    their instants at B; None: greedy, each next part as soon as it can)."""

    name = "hindsight"

    def __init__(self, k: CellConstants, come_s: Sequence[float],
                 targets: Targets | None = None):
        super().__init__(k, None)
        t = k.timing
        self.followed = t.fastest_followed(max(k.input_max, k.v_nom), k.output_max)[0]
        self.belt = BeltCopy(k.v_nom)
        self.drops = Drops(come_s, k.part_size)
        self.targets = targets
        lo, hi = min(k.input_min, k.v_nom), max(k.input_max, k.v_nom)
        self.speeds = sorted({float(1.0 / u) for u in np.linspace(1.0 / hi, 1.0 / lo, SPEED_STEPS)})
        self.after = sorted({self.followed, min(k.v_nom, self.followed), lo})
        self.r2, self.r4 = t.r2_min_s, t.r4_min_s
        self.r3 = t.r3_time(k.u_nom)

    def _aims(self, p: int) -> list[tuple[int, float]]:
        """The parts to try for next, with the instant to aim each at (-inf: soonest)."""
        n = len(self.drops.come)
        later = range(p + 1, min(n, p + 1 + LOOK_PARTS))
        if self.targets is None:
            return [(q, -math.inf) for q in later]
        picked, at_b = self.targets.picked, self.targets.at_b_s
        return [(q, at_b[q]) for q in later if picked[q]] + [(q, -math.inf) for q in later]

    def _off(self, xs: list[float], now: float, arrive: float, at: float) -> float:
        """How far a plan is from the targets (in of belt): the next pick's instant at B, and
        the drops before it, against the schedule followed; the instant alone without one."""
        if at == -math.inf:
            return arrive
        off = abs(arrive - at) * self.k.v_nom
        drop_in = self.targets.drop_in if self.targets is not None else None
        if drop_in is not None:
            come = self.drops.come
            off += sum(abs(xs[j] - drop_in[j]) for j in range(len(xs)) if now < come[j] <= arrive)
        return off

    def _arrival(self, p: int, now: float, lo: float, w: float, end: float, w_next: float,
                 q: int) -> tuple[float, float, list[float]]:
        """When parts q - 1 (or -inf) and q reach B with the belt at w from LO and at w_next
        from ``end``, and where the parts up to q are dropped."""
        belt = self.belt.planned(lo, w, end, w_next)
        xs = self.drops.positions(belt, q, now)
        before = belt.time_at(xs[q - 1] + self.k.input_length) if q > p + 1 else -math.inf
        return before, belt.time_at(xs[q] + self.k.input_length), xs

    def plan(self, view: CellView) -> Plan:
        p, now = view.part, view.now  # type: ignore[attr-defined]
        k, v = self.k, view.input_speed()
        r1a, r1b = k.timing.r1_time(v)
        r3a, r3b = self.r3
        aim, length = k.lookahead_margin_s, k.input_length
        follow = self.targets is not None and self.targets.drop_in is not None
        best: tuple[float, float, float, float, int, float, float] | None = None
        for q, at in self._aims(p):
            for hold in (HOLDS_S if follow and at > -math.inf else (0.0,)):
                lo = now + r1a + hold
                e_min = lo + r1b + self.r2 + r3a + r3b + self.r4
                for w in self.speeds:
                    fast = self.belt.planned(lo, w, math.inf, w)
                    xs = self.drops.positions(fast, q, now)
                    end = e_min if q == p + 1 else \
                        max(e_min, fast.time_at(xs[q - 1] + length) + MARGIN_S)
                    for w_next in self.after:
                        _, arrive, xs = self._arrival(p, now, lo, w, end + aim, w_next, q)
                        if arrive < end + aim + MARGIN_S:
                            continue
                        score = self._off(xs, now, arrive, at)
                        if best is None or score < best[0]:
                            best = (score, w, end, w_next, q, at, hold)
            if best is not None:
                break
        hold = 0.0 if best is None else best[6]
        lo, e_min = now + r1a + hold, now + r1a + hold + r1b + self.r2 + r3a + r3b + self.r4
        if best is None:
            w, end, w_next = v, e_min, self.followed
        else:
            score, w, end, w_next, q, at, _ = best
            better = self._refine(p, now, lo, w, end, w_next, q, max(at, end + aim + MARGIN_S))
            _, arrive, xs = self._arrival(p, now, lo, better, end + aim, w_next, q)
            if self._off(xs, now, arrive, at) <= score:
                w = better
        self.belt = self.belt.planned(lo, w, end + aim, w_next)
        self.drops.positions(self.belt, p + 1, now)
        to_g = r1a + hold + r1b + self.r2
        return Plan(r1_pre=r1a + hold, r1_post=r1b, r2=self.r2, r3_pre=r3a, r3_post=r3b,
                    r4=self.r4 + (end - e_min), input_speed=v, input_after_lo=w,
                    input_next=w_next, output_to_g=k.u_nom, to_g=to_g,
                    cycle=to_g + r3a + r3b + self.r4 + (end - e_min))

    def _refine(self, p: int, now: float, lo: float, w: float, end: float, w_next: float, q: int,
                goal: float) -> float:
        """The belt speed after LO, between the floor and the ceiling, that brings part q to B
        nearest ``goal`` and no sooner, the parts before it still past B by ``end`` (bisection:
        a faster belt brings each part sooner); ``w`` if none does better."""
        aim = self.k.lookahead_margin_s

        def ok(speed: float) -> bool:
            before, arrive, _ = self._arrival(p, now, lo, speed, end + aim, w_next, q)
            return before < end and arrive >= goal

        if not ok(w):
            return w
        slow, fast = w, self.speeds[-1]
        if ok(fast):
            return fast
        for _ in range(40):  # ok(slow), not ok(fast)
            mid = 0.5 * (slow + fast)
            slow, fast = (mid, fast) if ok(mid) else (slow, mid)
        return slow


def run_schedule(scenario: Scenario, cell: AssembledCell, come_s: Sequence[float], seed: Any,
                 targets: Targets | None = None) -> SimResult:
    """The hindsight policy's run through the simulation (its plans checked like any other's)."""
    policy = HindsightPolicy(cell.k, come_s, targets)
    return simulate(AssembledCell(scenario, cell.timing, cell.k, policy), seed)
