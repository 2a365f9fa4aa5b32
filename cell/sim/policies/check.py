"""Every plan checked at the boundary: what a policy returns, before the cell acts on it.

A policy (built in or a plug-in) answers :meth:`~cell.sim.policies.base.Policy.plan` with the
regime times and belt speeds of one cycle.  :func:`checked` wraps that method, where the
policy is built (:func:`cell.sim.policy_setup.make_policy`), so that each plan must obey the same
physics the built-in policies do before the controller uses it:

* every regime time finite and no shorter than the motors allow (the floors of
  :class:`~cell.sim.robot.RobotTiming`: each segment's ``floor_s``, R II's and R IV's fastest);
* every belt speed finite and within the belt's floor and ceiling (``belts.input_min_in_s``
  .. ``belts.input_max_in_s``, the output belt's likewise; the input belt after the cycle
  also within the speed the robot can track);
* the cycle consistent with its parts: ``to_g`` = R I + R II and ``cycle`` = ``to_g`` +
  R III + R IV;
* ``limits`` a set of the known limit bits, ``steers_belts`` a boolean.

The plan is read by attribute name only (``plan.r1_pre``, ``plan.cycle``...), so any
record with those fields passes.  A bad plan stops the run with one line naming the
policy and the first bad value (:class:`PolicyError`, exit 2); so does a policy whose
``plan`` raises.  A policy that returns the very plan it returned last time (the
non-adaptive robot's one cycle) is not checked again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
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
#: No regime time is this long (a year): a finite time is below it.
MAX_S = 3.2e7

_ALL_LIMITS = 0
for _bit in LIMIT_BIT.values():
    _ALL_LIMITS |= _bit

#: The plan's regime-time fields, in order.
TIMES = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")
#: Its belt-speed fields.
SPEEDS = ("input_speed", "input_after_lo", "input_next", "output_to_g")


class PolicyError(CellError):
    """A policy returned a plan the cell cannot carry out, or failed to give one."""


def _bounds(k: Any) -> dict[str, tuple[float, float]]:
    """Each numeric field's (lowest, highest) allowed value for constants ``k``."""
    t = k.timing
    inf = math.inf
    top_in = max(k.input_max, k.v_nom)
    return {
        "r1_pre": (t.r1_pre.floor_s, inf), "r1_post": (t.r1_post.floor_s, inf),
        "r2": (t.r2_min_s, inf), "r3_pre": (t.r3_pre.floor_s, inf),
        "r3_post": (t.r3_post.floor_s, inf), "r4": (t.r4_min_s, inf),
        "input_speed": (min(k.input_min, k.v_nom), max(top_in, t.input_track_max_in_s)),
        "input_after_lo": (min(k.input_min, k.v_nom), top_in),
        "input_next": (min(k.input_min, k.v_nom),
                       max(min(top_in, t.input_track_max_in_s), k.input_absorb)),
        "output_to_g": (min(k.output_min, k.u_nom), max(k.output_max, k.u_nom)),
    }


def _near(a: float, b: float) -> bool:
    return abs(a - b) <= SUM_S


def problem(plan: Any, bounds: dict[str, tuple[float, float]]) -> str | None:
    """What is wrong with ``plan`` (the first bad value, as a phrase), or None."""
    values: dict[str, float] = {}
    for name, (lo, hi) in bounds.items():
        try:
            v = getattr(plan, name)
        except AttributeError:
            return f"the plan has no field {name!r}"
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return f"{name} = {one_line(repr(v), 60)}: not a number"
        v = float(v)
        if not math.isfinite(v):
            return f"{name} = {v}: not finite"
        unit = "s" if name in TIMES else "in/s"
        if v < lo - ABS - REL * abs(lo):
            what = "the motors' fastest" if name in TIMES else "the belt's floor"
            return f"{name} = {v:.6g} {unit}: below {what}, {lo:.6g} {unit}"
        if v > hi + ABS + REL * abs(hi):
            return f"{name} = {v:.6g} {unit}: above the belt's ceiling, {hi:.6g} {unit}"
        values[name] = v
    for name in ("to_g", "cycle", "limits", "steers_belts"):
        if not hasattr(plan, name):
            return f"the plan has no field {name!r}"
    to_g, cycle = plan.to_g, plan.cycle
    for name, v in (("to_g", to_g), ("cycle", cycle)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            return f"{name} = {one_line(repr(v), 60)}: not a finite number"
    r12 = values["r1_pre"] + values["r1_post"] + values["r2"]
    if not _near(to_g, r12):
        return f"to_g = {to_g:.6g} s: not R I + R II = {r12:.6g} s"
    whole = to_g + values["r3_pre"] + values["r3_post"] + values["r4"]
    if not _near(cycle, whole):
        return f"cycle = {cycle:.6g} s: not its regimes' sum, {whole:.6g} s"
    limits = plan.limits
    if isinstance(limits, bool) or not isinstance(limits, int) or limits < 0 \
            or limits & ~_ALL_LIMITS:
        return f"limits = {one_line(repr(limits), 60)}: not a set of the known limit bits"
    if not isinstance(plan.steers_belts, bool):
        return f"steers_belts = {one_line(repr(plan.steers_belts), 60)}: not true or false"
    return None


def checked(plan: Callable[[Any], Any], name: str, k: Any) -> Callable[[Any], Any]:
    """``plan`` (a policy's bound method) with each result checked (see the module).

    The check is one expression over the plan's fields, read by name, with the slack baked
    into the bounds: NaN fails every comparison, and with every regime time at or above its
    floor a finite cycle below :data:`MAX_S` makes each of them finite.  A plan it does not
    pass goes to :func:`problem` for the message (and passes after all if that finds
    nothing).  A plan that is the very object passed last time is not checked again.

    For speed: the plan's fields read one by one (each a slot read the interpreter
    specialises), not gathered with ``operator.attrgetter`` and unpacked.  ``make bench``'s
    ``parts_per_s_adaptive_5k``, interleaved on one machine (2 shared cores, best of 7):
    the check costs about 3 % of the adaptive run this way, 6-7 % gathered (the fixed
    cycle's one plan is checked once)."""
    bounds = _bounds(k)
    (a1, _), (a2, _), (a3, _), (a4, _), (a5, _), (a6, _), (c1, d1), (c2, d2), (c3, d3), \
        (c4, d4) = [(lo - ABS - REL * abs(lo), hi + ABS + REL * abs(hi))
                    for lo, hi in bounds.values()]
    bad_bits, top, eps = ~_ALL_LIMITS, MAX_S, SUM_S
    last: list[Any] = [None]  # the plan passed last
    integer, boolean = int, bool

    def plan_checked(view: Any) -> Any:
        try:
            p = plan(view)
        except CellError:
            raise
        except Exception as exc:  # noqa: BLE001 - a plug-in's failure, named
            raise PolicyError(f"policy {name!r}: its plan failed: {type(exc).__name__}: "
                              f"{one_line(str(exc), 200)}") from exc
        if p is last[0]:
            return p
        try:
            r1a, r1b, r2, r3a, r3b, r4 = p.r1_pre, p.r1_post, p.r2, p.r3_pre, p.r3_post, p.r4
            to_g, cycle, limits = p.to_g, p.cycle, p.limits
            if (a1 <= r1a and a2 <= r1b and a3 <= r2 and a4 <= r3a and a5 <= r3b and a6 <= r4
                    and c1 <= p.input_speed <= d1 and c2 <= p.input_after_lo <= d2
                    and c3 <= p.input_next <= d3 and c4 <= p.output_to_g <= d4
                    and -eps <= to_g - (r1a + r1b + r2) <= eps
                    and -eps <= cycle - (to_g + r3a + r3b + r4) <= eps
                    and cycle < top and limits.__class__ is integer and not limits & bad_bits
                    and p.steers_belts.__class__ is boolean):
                last[0] = p
                return p
        except Exception:  # noqa: BLE001, S110 - a field missing or not a number: said below
            pass
        why = problem(p, bounds)
        if why is not None:
            raise PolicyError(f"policy {name!r} planned {why}")
        last[0] = p
        return p

    return plan_checked


def check_policy(policy: Any, name: str, k: Any) -> Any:
    """``policy`` with its :meth:`plan` checked against constants ``k``: the instance's own
    attribute, so the controller, which reads ``policy.plan``, gets the checked one (a
    policy that cannot take the attribute is wrapped instead)."""
    plan = getattr(policy, "plan", None)
    if not callable(plan):
        raise PolicyError(f"policy {name!r}: has no plan method")
    wrapped = checked(plan, name, k)
    try:
        policy.plan = wrapped
    except (AttributeError, TypeError):
        return _Checked(policy, wrapped)
    return policy


class _Checked:
    """A policy that would not take a checked ``plan`` of its own: everything else its own."""

    def __init__(self, policy: Any, plan: Callable[[Any], Any]):
        self._policy, self.plan = policy, plan

    def __getattr__(self, attr: str) -> Any:
        return getattr(self._policy, attr)
