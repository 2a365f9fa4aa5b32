"""The hindsight optimum's upper side: a MILP over one trace, solved with HiGHS
(:func:`scipy.optimize.milp`); docs/model.md, "The hindsight optimum".

Every event of the input belt is a point (belt travel, instant): part i's drop (x_i, T_i) and its
arrival at B (x_i + L, B_i).  A belt whose speed stays within its floor and ceiling passes through
a set of such points exactly when any two of them, taken in order of travel, are at least the
travel over the ceiling and at most the travel over the floor apart in time.  The order of a
drop and an earlier part's arrival at B is a binary (fixed where the parts' windows settle it).
The feeder drops part i at its arrival a_i, or, held, the instant the belt has carried the part
before a part's size clear (a binary says which).  Until the first pick the belt runs at its
nominal speed (nobody has changed it).  A part picked is tracked from B to LO (4 in of belt) at
one slowness u (s/in), no slower than the floor and no faster than the tracking limit, and the
next pick is at least the cycle a plan may have at that speed later (what a cycle may take: R I
at the belt's pace, convex in u, so written as its tangents; R III at the output belt's
nominal speed from G; R II and R IV at the motors' peak).  Any other part may be let go (a cycle
may be made as long as the policy likes).

This is a relaxation of the model in two ways: the belt may change speed at any instant after
lift-off here, where the controller changes it only at lift-off and at the cycle's end; and an
event within a pick's 4 in from B to LO is held to the McCormick envelope of travel times
slowness, not to one speed exactly.  So its optimum is at least every controller's count; a
schedule run through the simulation that reaches it proves it the optimum
(:mod:`cell.experiments.hindsight.search`).  Every run of a controller is one of its points,
and every point keeps the windows, the cycle and the one belt's distances of
:mod:`cell.sim.bound` (its SLACK and HOLD_IN within the bound's allowances), so its optimum is
at most ``parts_bound``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import coo_array

if TYPE_CHECKING:
    from cell.sim.policies.base import CellConstants

#: How far past a part's size clear a held part may be dropped (in): the feeder's wait ends
#: at least EPS_S (1e-6 s) on, at up to 12 in/s.
HOLD_IN = 1e-4
#: Slack on the physics' equalities (in, s): the simulation's own roundings (EPS_S 1e-6 s on
#: the belt, 1e-9 in on the feeder's clearance) are below it, so every run stays a point.
SLACK = 1e-5


def check_cycle_s(k: CellConstants) -> float:
    """The shortest B → B cycle a plan may have (:mod:`cell.sim.policies.check`'s floors):
    R I at the fastest input belt the robot can follow, R III at the output belt's nominal
    speed (the controller sets it so at G), R II and R IV at the motors' peak."""
    t = k.timing
    followed, _ = t.fastest_followed(max(k.input_max, k.v_nom), k.output_max)
    return float(sum(t.shortest_parts(followed, k.u_nom)))


@dataclass
class MilpResult:
    """What the solver found for one trace."""

    status: str
    """``optimal`` (proved), ``time_limit`` (stopped: ``upper`` is its dual bound) or
    ``failed`` (no answer: ``upper`` is None)."""
    upper: int | None
    """The most parts any schedule could deliver (after the warm-up), as proved."""
    picked: list[bool] = field(default_factory=list)
    """The solver's best schedule: part i picked (empty if none)."""
    at_b_s: list[float] = field(default_factory=list)
    """Its instants at which each part reaches B."""
    drop_in: list[float] = field(default_factory=list)
    """Its belt travel (in) at each part's drop."""
    count: int = 0
    """Its parts picked after the warm-up."""
    solve_s: float = 0.0
    binaries: int = 0


class _Model:
    """Variables with bounds, and rows ``sum(coef * var) + const >= 0`` that hold when some
    binaries take given values (big-M from the variables' bounds)."""

    def __init__(self) -> None:
        self.lb: list[float] = []
        self.ub: list[float] = []
        self.integer: list[int] = []
        self.rows: list[tuple[dict[int, float], float]] = []

    def var(self, lb: float, ub: float, integer: bool = False) -> int:
        self.lb.append(lb)
        self.ub.append(ub)
        self.integer.append(int(integer))
        return len(self.lb) - 1

    def low(self, expr: dict[int, float], const: float) -> float:
        return const + sum(c * (self.lb[v] if c > 0 else self.ub[v]) for v, c in expr.items())

    def geq(self, expr: dict[int, float], const: float,
            when: tuple[tuple[int, int], ...] = ()) -> None:
        """``expr + const >= 0``, or only when each (binary, value) of ``when`` holds."""
        expr = dict(expr)
        if when:
            m = max(0.0, -self.low(expr, const)) + 1.0
            for b, value in when:  # off by (1 - b) or b: expr + M * off >= 0
                if value:
                    const += m
                    expr[b] = expr.get(b, 0.0) - m
                else:
                    expr[b] = expr.get(b, 0.0) + m
        self.rows.append((expr, const))

    def between(self, expr: dict[int, float], lo: float, hi: float,
                when: tuple[tuple[int, int], ...] = ()) -> None:
        """``lo <= expr <= hi`` (under ``when``)."""
        self.geq(expr, -lo, when)
        self.geq({v: -c for v, c in expr.items()}, hi, when)


def _cycle_lines(k: CellConstants, u_lo: float, u_hi: float,
                 points: int = 16) -> tuple[float, list[tuple[float, float]]]:
    """The cycle's floor as R I's (B → LO, LO → F) at belt slowness u plus the rest: R I is a
    sum of max(length u, motor floor) over its moves, convex in u, so it is at least each of its
    tangents (a + b u, the slope taken on the right: a subgradient) at ``points`` slownesses."""
    t = k.timing
    rest = t.r2_min_s + sum(t.r3_time(k.u_nom)) + t.r4_min_s

    def r1(u: float) -> float:
        return float(sum(t.r1_time(1.0 / u)))

    lines = []
    for at in np.linspace(u_lo, u_hi, points).tolist():
        h = 1e-7 * at
        b = (r1(at + h) - r1(at)) / h
        lines.append((r1(at) - b * at - 1e-9, b))
    return rest, lines


def _windows(k: CellConstants, come: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each part's latest drop D_i and latest arrival at B (:mod:`cell.sim.bound`'s windows)."""
    vlo = min(k.input_min, k.v_nom)
    latest = np.empty_like(come)
    last = -math.inf
    for i, a in enumerate(come.tolist()):
        last = max(a, last + k.part_size / vlo)
        latest[i] = last
    return latest, latest + k.input_length / vlo


class _Trace:
    """The MILP of one trace: its variables (per part: drop travel x, drop instant T, instant at
    B, picked y, tracking slowness u) and the rows of the model's rules."""

    When = tuple[tuple[int, int], ...]

    def __init__(self, k: CellConstants, come: np.ndarray):
        self.k, self.come, n = k, come, come.size
        self.vlo, self.vhi, self.v0 = min(k.input_min, k.v_nom), max(k.input_max, k.v_nom), k.v_nom
        self.L, self.size = k.input_length, k.part_size
        self.d_late, self.b_late = _windows(k, come)
        self.followed = k.timing.fastest_followed(self.vhi, k.output_max)[0]
        self.lo_in = k.timing.r1_pre.length_in
        m = self.m = _Model()
        x0, L, vhi = self.v0 * come[0], self.L, self.vhi
        self.x = [m.var(x0 + self.size * i - SLACK, x0 + vhi * (self.d_late[i] - come[0]) + SLACK)
                  for i in range(n)]
        self.T = [m.var(come[i], self.d_late[i] + SLACK) for i in range(n)]
        self.B = [m.var(come[i] + L / vhi - SLACK, self.b_late[i] + SLACK) for i in range(n)]
        self.y = [m.var(0, 1, True) for _ in range(n)]
        # the belt's slowness (s/in) from B to LO, were the part picked: at most the tracking limit
        self.u = [m.var(1.0 / self.followed, 1.0 / min(self.vlo, self.followed)) for _ in range(n)]
        first_b = come[0] + L / self.v0
        m.between({self.u[0]: 1.0}, 1.0 / self.v0, 1.0 / self.v0)  # the first at nominal speed
        m.between({self.x[0]: 1.0}, x0, x0)
        m.between({self.T[0]: 1.0}, come[0], come[0])
        m.between({self.B[0]: 1.0}, first_b, first_b)
        m.geq({self.y[0]: 1.0}, -1.0)

    def slopes(self, s2: dict[int, float], t2: dict[int, float], when: When = (),
               ds: float = 0.0) -> None:
        """Travel ``s2 + ds`` >= 0 and time ``t2`` within it over the ceiling and the floor."""
        m, vhi, vlo = self.m, self.vhi, self.vlo
        m.geq(s2, ds + SLACK, when)
        e = {**t2}
        for v, c in s2.items():
            e[v] = e.get(v, 0.0) - c / vhi
        m.geq(e, -ds / vhi + SLACK, when)
        e = {v: -c for v, c in t2.items()}
        for v, c in s2.items():
            e[v] = e.get(v, 0.0) + c / vlo
        m.geq(e, ds / vlo + SLACK, when)

    def feeder(self) -> None:
        """Each part's drop and arrival at B on the belt; the feeder's rule (a binary a part)."""
        x, T, B, m, size = self.x, self.T, self.B, self.m, self.size
        for i in range(self.come.size):
            self.slopes({}, {B[i]: 1.0, T[i]: -1.0}, ds=self.L)  # its own drop to B
            if i:
                self.slopes({x[i]: 1.0, x[i - 1]: -1.0}, {T[i]: 1.0, T[i - 1]: -1.0})
                m.geq({x[i]: 1.0, x[i - 1]: -1.0}, -size + SLACK)
                self.slopes({x[i]: 1.0, x[i - 1]: -1.0}, {B[i]: 1.0, B[i - 1]: -1.0})
                held = m.var(0, 1, True)  # dropped on arrival, or held until the belt is clear
                m.geq({T[i]: -1.0}, self.come[i] + SLACK, ((held, 0),))
                m.geq({x[i]: -1.0, x[i - 1]: 1.0}, size + HOLD_IN, ((held, 1),))

    def tracked(self, p: int, s_e: dict[int, float], s_const: float, t_e: int,
                after: When = ()) -> None:
        """An event at travel ``s_e + s_const`` and instant ``t_e``, after part p reaches B
        (under ``after``): with p picked, the belt's first ``lo_in`` beyond B (to LO) at its
        slowness u_p."""
        m, u, B, lo_in = self.m, self.u, self.B, self.lo_in
        d = {**s_e, self.x[p]: s_e.get(self.x[p], 0.0) - 1.0}  # its travel beyond B: d + d0
        d0 = s_const - self.L
        inside = m.var(0, 1, True)
        m.geq({v: -c for v, c in d.items()}, lo_in - d0 + SLACK, ((inside, 1),))
        m.geq(d, d0 - lo_in + SLACK, ((inside, 0),))
        # inside: t_e - B_p = (d + d0) u_p, held to its McCormick envelope (d + d0 in
        # [0, lo_in], u_p in [u_lo, u_hi])
        u_lo, u_hi = m.lb[u[p]], m.ub[u[p]]
        for a_d, a_u, c0, sign in ((u_lo, 0.0, 0.0, 1.0), (u_hi, lo_in, -lo_in * u_hi, 1.0),
                                   (u_lo, lo_in, -lo_in * u_lo, -1.0), (u_hi, 0.0, 0.0, -1.0)):
            # sign * (t_e - B_p - a_d (d + d0) - a_u u_p - c0) >= 0
            e = {t_e: sign, B[p]: -sign, u[p]: -sign * a_u}
            for v, c in d.items():
                e[v] = e.get(v, 0.0) - sign * a_d * c
            m.geq(e, sign * (-a_d * d0 - c0) + SLACK, ((self.y[p], 1), (inside, 1), *after))
        # beyond LO: the first lo_in at slowness u_p, the rest at the ceiling at most
        e = {t_e: 1.0, B[p]: -1.0, u[p]: -lo_in}
        for v, c in d.items():
            e[v] = e.get(v, 0.0) - c / self.vhi
        m.geq(e, -(d0 - lo_in) / self.vhi + SLACK, ((self.y[p], 1), (inside, 0)))

    def orders(self) -> None:
        """Each drop against each earlier part's arrival at B: before or after it (a binary
        where the windows leave it open); before the first pick, the belt at nominal."""
        x, T, B, m, come, L = self.x, self.T, self.B, self.m, self.come, self.L
        n, v0 = come.size, self.v0
        for i in range(n):
            for q in range(i + 1, min(n, i + 1 + int(self.lo_in // self.size))):
                self.tracked(i, {x[q]: 1.0}, L, B[q])  # parts close behind it, reaching B
            for j in range(i + 1, n):
                before = {x[i]: 1.0, x[j]: -1.0}, {B[i]: 1.0, T[j]: -1.0}
                after = {x[j]: 1.0, x[i]: -1.0}, {T[j]: 1.0, B[i]: -1.0}
                if come[j] >= self.b_late[i] + SLACK:  # after it (and so every later drop)
                    self.slopes(*after, ds=-L)
                    self.tracked(i, {x[j]: 1.0}, 0.0, T[j])
                    break
                if self.d_late[j] <= come[i] + L / self.vhi - SLACK:
                    self.slopes(*before, ds=L)
                    if i == 0:
                        m.between({x[j]: 1.0, T[j]: -v0}, -SLACK, SLACK)
                    continue
                o = m.var(0, 1, True)
                self.slopes(*before, when=((o, 1),), ds=L)
                self.slopes(*after, when=((o, 0),), ds=-L)
                self.tracked(i, {x[j]: 1.0}, 0.0, T[j], ((o, 0),))
                if i == 0:  # before the first pick the belt runs at its nominal speed
                    m.between({x[j]: 1.0, T[j]: -v0}, -SLACK, SLACK, ((o, 1),))

    def picks(self) -> None:
        """Two picks a cycle apart, R I's at the belt's pace from B (its tangents)."""
        B, u, y, come = self.B, self.u, self.y, self.come
        cyc = check_cycle_s(self.k) - SLACK
        rest, lines = _cycle_lines(self.k, self.m.lb[u[0]], self.m.ub[u[0]])
        for p in range(come.size):
            for q in range(p + 1, come.size):
                if come[q] + self.L / self.vhi - self.b_late[p] >= cyc:
                    break
                for a, b in lines:  # B_q - B_p >= rest + a + b u_p
                    self.m.geq({B[q]: 1.0, B[p]: -1.0, u[p]: -b}, -(rest + a) + SLACK,
                               ((y[p], 1), (y[q], 1)))


def solve(k: CellConstants, come_s: list[float] | np.ndarray, warmup: int = 0,
          time_limit_s: float = 60.0) -> MilpResult:
    """The relaxation's optimum for parts coming at ``come_s`` (the feeder's schedule), counted
    from part ``warmup`` on."""
    started = time.perf_counter()
    come = np.asarray(come_s, dtype=float)
    if come.size == 0:
        return MilpResult("optimal", 0)
    trace = _Trace(k, come)
    trace.feeder()
    trace.orders()
    trace.picks()
    return _solve(trace.m, trace.y, trace.B, trace.x, warmup, time_limit_s, started)


def _solve(m: _Model, y: list[int], B: list[int], x: list[int], warmup: int, time_limit_s: float,
           started: float) -> MilpResult:
    nv = len(m.lb)
    rows, cols, vals, lows = [], [], [], []
    for r, (expr, const) in enumerate(m.rows):
        for v, coef in expr.items():
            if coef:
                rows.append(r)
                cols.append(v)
                vals.append(coef)
        lows.append(-const)
    a = coo_array((vals, (rows, cols)), shape=(len(m.rows), nv)).tocsr()
    c = np.zeros(nv)
    c[y[warmup:]] = -1.0
    res = milp(c, constraints=LinearConstraint(a, np.array(lows), np.inf),
               integrality=np.array(m.integer), bounds=Bounds(np.array(m.lb), np.array(m.ub)),
               options={"time_limit": max(time_limit_s, 0.01), "mip_rel_gap": 0.0})
    out = MilpResult("failed", None, binaries=sum(m.integer),
                     solve_s=time.perf_counter() - started)
    dual = getattr(res, "mip_dual_bound", None)
    dual = math.nan if dual is None else float(dual)
    if res.status == 0:
        out.status = "optimal"
    elif res.status == 1 and math.isfinite(dual):
        out.status = "time_limit"
    else:
        return out
    if res.x is not None:
        picked = [bool(res.x[v] > 0.5) for v in y]
        out.picked, out.at_b_s = picked, [float(res.x[v]) for v in B]
        out.drop_in = [float(res.x[v]) for v in x]
        out.count = sum(picked[warmup:])
    out.upper = out.count if out.status == "optimal" else int(math.floor(-dual + 1e-6))
    return out
