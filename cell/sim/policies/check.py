"""Every plan checked at the boundary: what a policy returns, before the cell acts on it.

A policy (built in or a plug-in) answers :meth:`~cell.sim.policies.base.Policy.plan` with the
regime times and belt speeds of one cycle.  The controller checks each plan the moment it
gets it (:class:`PlanCheck`, the one check, whatever the policy), so that each plan must obey the
same physics the built-in policies do before the cell acts on it:

* every regime time finite and no shorter than what a cycle may take
  (:meth:`~cell.sim.robot.RobotTiming.shortest_parts`, the one statement of it, which the
  bound on any controller reads too: :mod:`cell.sim.bound`): R I at the pace of the input belt
  the part reached B on (``input_speed``) from B to F, R III at the pace of the output belt
  from G to K (nominal: the controller sets it so at G), each move floored by the motors; R II
  and R IV at least their fastest;
* every belt speed finite and within the belt's floor and ceiling (``belts.input_min_in_s``
  .. ``belts.input_max_in_s``, the output belt's likewise); the input belt at the pick
  (``input_speed``) and after the cycle (``input_next``) also no faster than the robot can
  follow (the tracking limit: 4.3693 in/s in the thesis's cell);
* the cycle consistent with its parts: ``to_g`` = R I + R II and ``cycle`` = ``to_g`` +
  R III + R IV;
* ``limits`` a set of the known limit bits, ``steers_belts`` a boolean;
* a plan that steers the belts says when the output belt drops to its floor
  (``output_floor_at``, from the cycle's start): at or after the touch-down, or inf.

A number is an int or a float (a boolean in a numeric field is read as its 0 or 1, as the
controller's comparisons read it; an integer beyond the floats' range is an infinity).
tests/robust/test_plan_check_agrees.py checks that :meth:`PlanCheck.passes`' comparisons and
:func:`problem`'s wording agree on any plan.

The plan is read by attribute name only (``plan.r1_pre``, ``plan.cycle``...), so any
record with those fields passes.  A bad plan stops the run with one line naming the
policy and the first bad value (:class:`PolicyError`, exit 2); so does a policy whose
``plan`` raises.  A policy that returns the very plan it returned last time (the
non-adaptive robot's one cycle) is not checked again.

"""

from __future__ import annotations

import math
from typing import Any

from cell.plumbing.errors import CellError, one_line
from cell.sim.records import LIMIT_BIT

#: Relative slack on every comparison (the policies' sums are rounded like any float's).
REL = 1e-9
#: Absolute slack, s or in/s.
ABS = 1e-9
#: How far a sum may be off its parts (s): far above the rounding of any sum of times below
#: :data:`MAX_S` (a few ns), far below anything the cell could tell.
SUM_S = 1e-6
#: The sums' lowest allowed offset.
SUM_LO = -SUM_S  # speed: docs/performance.md#plan-check
#: No regime time is this long (a year): a finite time is below it.
MAX_S = 3.2e7

#: The limit bits a plan may carry: what held its belts and motors (and its spacing wait).  What
#: became of the part (let go, off spacing, held at the feeder, lost, scrapped, the buffer full)
#: is the cell's to record, not a plan's to claim: a plan claiming it would miscount the run.
PLAN_LIMITS = 0
for _name in ("input_floor", "input_ceiling", "input_tracking", "output_floor", "output_ceiling",
              "r2_peak", "r4_peak", "spacing_wait", "spacing_unforeseen"):
    PLAN_LIMITS |= LIMIT_BIT[_name]

#: The plan's regime-time fields, in order.
TIMES = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")
#: Its belt-speed fields.
SPEEDS = ("input_speed", "input_after_lo", "input_next", "output_to_g")


class PolicyError(CellError):
    """A policy returned a plan the cell cannot carry out, or failed to give one."""


def _bounds(k: Any) -> dict[str, tuple[float, float]]:
    """Each numeric field's (lowest, highest) allowed value for constants ``k``, whatever the
    plan's other fields: R I's floors here are at the fastest input belt the robot can follow
    (:func:`tracking_floors` ties them to the plan's own ``input_speed``), R III's at the output
    belt's nominal speed, which it runs at from G."""
    t = k.timing
    inf = math.inf
    top_in = max(k.input_max, k.v_nom)
    followed, _ = t.fastest_followed(top_in, k.output_max)
    r1a, r1b, r2, r3a, r3b, r4 = t.shortest_parts(followed, k.u_nom)
    return {
        "r1_pre": (r1a, inf), "r1_post": (r1b, inf), "r2": (r2, inf), "r3_pre": (r3a, inf),
        "r3_post": (r3b, inf), "r4": (r4, inf),
        "input_speed": (min(k.input_min, k.v_nom), followed),
        "input_after_lo": (min(k.input_min, k.v_nom), top_in),
        "input_next": (min(k.input_min, k.v_nom), max(followed, k.input_absorb)),
        "output_to_g": (min(k.output_min, k.u_nom), max(k.output_max, k.u_nom)),
    }


def tracking_floors(k: Any) -> Any:
    """What R I may take at the input belt's speed v: (B → LO, LO → F), the shortest at that
    belt's pace (:meth:`~cell.sim.robot.RobotTiming.shortest_parts`' first two)."""
    return k.timing.r1_time


#: What each regime time's lowest bound is, for a message.
_FLOOR_WORDS = {"r1_pre": "its shortest at the fastest input belt the robot can follow",
                "r1_post": "its shortest at the fastest input belt the robot can follow",
                "r2": "the motors' fastest", "r4": "the motors' fastest",
                "r3_pre": "its shortest following the output belt at its nominal speed",
                "r3_post": "its shortest following the output belt at its nominal speed"}


def _float(v: float) -> float:
    """``v`` as a float; an integer beyond the floats' range is an infinity of its sign."""
    try:
        return float(v)
    except OverflowError:
        return math.inf if v > 0 else -math.inf


def _shown(v: Any) -> str:
    """``v`` for a message: an integer too long to print whole is named by its size."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) >= 10**60:
        return f"an integer of {len(str(abs(v))) if abs(v) < 10**4000 else 'over 4000'} digits"
    return one_line(repr(v), 60)


def _near(a: float, b: float) -> bool:
    return abs(a - b) <= SUM_S


def problem(plan: Any, k: Any) -> str | None:
    """What is wrong with ``plan`` for constants ``k`` (the first bad value, as a phrase), or
    None."""
    values: dict[str, float] = {}
    for name, (lo, hi) in _bounds(k).items():
        try:
            v = getattr(plan, name)
        except AttributeError:
            return f"the plan has no field {name!r}"
        if not isinstance(v, (int, float)):  # an int or a float (a boolean is its 0 or 1)
            return f"{name} = {one_line(repr(v), 60)}: not a number"
        given, v = v, _float(v)
        if not math.isfinite(v):
            return f"{name} = {_shown(given) if isinstance(given, int) else v}: not finite"
        unit = "s" if name in TIMES else "in/s"
        if v < lo - ABS - REL * abs(lo):
            what = _FLOOR_WORDS[name] if name in TIMES else "the belt's floor"
            return f"{name} = {v:.6g} {unit}: below {what}, {lo:.6g} {unit}"
        if v > hi + ABS + REL * abs(hi):
            what = "the fastest the robot can follow" if name in ("input_speed", "input_next") \
                else "the belt's ceiling"
            return f"{name} = {v:.6g} {unit}: above {what}, {hi:.6g} {unit}"
        values[name] = v
    speed = values["input_speed"]
    for name, lo in zip(("r1_pre", "r1_post"), tracking_floors(k)(speed)):
        if values[name] < lo - ABS - REL * abs(lo):
            return f"{name} = {values[name]:.6g} s: below its shortest at the input belt's " \
                f"{speed:.6g} in/s, {lo:.6g} s"
    for name in ("to_g", "cycle", "limits", "steers_belts"):
        if not hasattr(plan, name):
            return f"the plan has no field {name!r}"
    to_g, cycle = plan.to_g, plan.cycle
    for name, v in (("to_g", to_g), ("cycle", cycle)):
        if not isinstance(v, (int, float)) or not math.isfinite(_float(v)):
            return f"{name} = {_shown(v)}: not a finite number"
    to_g, cycle = _float(to_g), _float(cycle)
    r12 = values["r1_pre"] + values["r1_post"] + values["r2"]
    if not _near(to_g, r12):
        return f"to_g = {to_g:.6g} s: not R I + R II = {r12:.6g} s"
    whole = to_g + values["r3_pre"] + values["r3_post"] + values["r4"]
    if not _near(cycle, whole):
        return f"cycle = {cycle:.6g} s: not its regimes' sum, {whole:.6g} s"
    limits = plan.limits
    if isinstance(limits, bool) or not isinstance(limits, int) or limits < 0 \
            or limits & ~PLAN_LIMITS:
        return f"limits = {one_line(repr(limits), 60)}: not a set of a plan's limit bits"
    if not isinstance(plan.steers_belts, bool):
        return f"steers_belts = {one_line(repr(plan.steers_belts), 60)}: not true or false"
    return _floor_problem(plan, to_g + values["r3_pre"]) if plan.steers_belts else None


def _floor_problem(plan: Any, td: float) -> str | None:
    """What is wrong with a belt-steering plan's ``output_floor_at`` (when, from the start of
    the cycle, the output belt drops to its floor; inf: not planned): it must be at or after
    the touch-down ``td``."""
    if not hasattr(plan, "output_floor_at"):
        return "the plan has no field 'output_floor_at' (inf: no floor planned)"
    v = plan.output_floor_at
    if not isinstance(v, (int, float)) or math.isnan(_float(v)):
        return f"output_floor_at = {one_line(repr(v), 60)}: not a number"
    if _float(v) < td - SUM_S:
        return f"output_floor_at = {_float(v):.6g} s: before the touch-down, {td:.6g} s"
    return None


def plan_bounds(k: Any) -> tuple[float, ...]:
    """The check's bounds for constants ``k``, the slack baked in: the six regime times'
    floors (R I before and after LO, R II, R III before and after TD, R IV), then each belt
    speed's floor and ceiling (:data:`SPEEDS`' order).  R I's floors at the plan's own input
    speed are :func:`tracking_floors`' (the slack baked in as here: ``lo - ABS - REL * lo``)."""
    out: list[float] = []
    for name, (lo, hi) in _bounds(k).items():
        out.append(lo - ABS - REL * abs(lo))
        if name in SPEEDS:
            out.append(hi + ABS + REL * abs(hi))
    return tuple(out)


class PlanCheck:
    """The check every plan passes before the cell acts on it (the controller's, for any
    policy), for constants ``k`` and the policy's ``name``: :meth:`passes`."""

    __slots__ = ("k", "name", "bounds", "r1_floors")

    def __init__(self, k: Any, name: str):
        self.k, self.name = k, name
        self.bounds = plan_bounds(k)
        """:func:`plan_bounds` of ``k``."""
        t = k.timing
        self.r1_floors = (t.r1_pre.time, t.r1_post.time)
        """R I's floors (B → LO, LO → F) at an input belt speed, one function each: the two
        of :meth:`~cell.sim.robot.RobotTiming.r1_time` (:func:`tracking_floors`)."""

    def passes(self, plan: Any) -> None:
        """Returns if ``plan`` obeys the physics above, else raises :class:`PolicyError`
        naming its first bad value (:func:`problem`).

        The fields are read by name and compared once each, the slack baked into the bounds
        (NaN fails every comparison; with every regime time at or above its floor, a finite
        cycle below :data:`MAX_S` makes each of them finite); only a plan that fails goes to
        :func:`problem` for the message."""
        a1, a2, a3, a4, a5, a6, c1, d1, c2, d2, c3, d3, c4, d4 = self.bounds
        try:
            r1a, r1b, r2, r3a, r3b, r4 = \
                plan.r1_pre, plan.r1_post, plan.r2, plan.r3_pre, plan.r3_post, plan.r4
            v, w, w_next, u = plan.input_speed, plan.input_after_lo, plan.input_next, \
                plan.output_to_g
            to_g, cycle, limits, steers = plan.to_g, plan.cycle, plan.limits, plan.steers_belts
            off_g, off_b = to_g - (r1a + r1b + r2), cycle - (to_g + r3a + r3b + r4)
            floor_at = plan.output_floor_at if steers else math.inf  # at or after TD
            if (a1 <= r1a and a2 <= r1b and a3 <= r2 and a4 <= r3a and a5 <= r3b and a6 <= r4
                    and c1 <= v <= d1 and c2 <= w <= d2 and c3 <= w_next <= d3 and c4 <= u <= d4
                    and SUM_LO <= off_g <= SUM_S and SUM_LO <= off_b <= SUM_S and cycle < MAX_S
                    and limits.__class__ is int and not limits & ~PLAN_LIMITS
                    and steers.__class__ is bool and floor_at >= to_g + r3a - SUM_S):
                pre, post = self.r1_floors  # R I at the pace of the belt it picks from
                f = pre(v)  # (v checked above): at the floor, or within its slack
                if f <= r1a or f - ABS - REL * f <= r1a:  # speed: docs/performance.md#plan-check
                    f = post(v)
                    if f <= r1b or f - ABS - REL * f <= r1b:
                        return
        except Exception:  # noqa: BLE001, S110 - a field missing or not a number: said below
            pass
        refuse(plan, self.name, self.k)


def plan_failed(name: str, exc: Exception) -> PolicyError:
    """The error of a policy whose ``plan`` raised."""
    return PolicyError(f"policy {name!r}: its plan failed: {type(exc).__name__}: "
                       f"{one_line(str(exc), 200)}")


def refuse(plan: Any, name: str, k: Any) -> None:
    """Raise :class:`PolicyError` naming the first bad value of a plan :class:`PlanCheck`'s
    comparisons did not pass (and return if :func:`problem` finds nothing after all)."""
    why = problem(plan, k)
    if why is not None:
        raise PolicyError(f"policy {name!r} planned {why}")


def check_policy(policy: Any, name: str, k: Any) -> Any:
    """``policy``, refused unless it has a ``plan`` method (its plans are checked by the
    controller, each before the cell acts on it: :class:`cell.sim.controller.Controller`)."""
    plan = getattr(policy, "plan", None)
    if not callable(plan):
        raise PolicyError(f"policy {name!r}: has no plan method")
    return policy
