"""What a scenario's policy is built from and the policy built: the cell's constants (the
nominal cycle split into regimes, belts the robot can follow) and the policy checked."""

from __future__ import annotations

from typing import Any

from cell.plumbing.errors import CellError, ScenarioError
from cell.scenario import registry
from cell.scenario.arrivals import mean_interarrival
from cell.scenario.schema import Scenario
from cell.sim.physics_checks import SPEED_KEYS, thesis, with_key
from cell.sim.policies.base import CellConstants, Policy
from cell.sim.robot import RobotTiming
from cell.sim.timing_cache import robot_timing


def constants(s: Scenario, timing: RobotTiming) -> CellConstants:
    """The policies' constants; a cell that cannot run its nominal cycle is an error."""
    b, c = s.belts, s.controller
    for belt, where, most in (("input", "LO", timing.input_track_max_in_s),
                              ("output", "TD", timing.output_track_max_in_s)):
        speed = getattr(b, f"{belt}_nominal_in_s")
        if speed > most:
            key, value = _tracking_blame(s, belt, speed)
            speed_key = f"belts.{belt}_nominal_in_s"
            change = "" if key == speed_key else f" (with this {key}); set {speed_key} to " \
                f"at most {most:.4f}, or change {key}"
            raise ScenarioError(s.source, key, value,
                                f"the robot can follow the {belt} belt ({speed:g} in/s) down to "
                                f"{where} at no more than {most:.4f} in/s{change}")
    t = timing
    r1a, r1b = t.r1_time(b.input_nominal_in_s)
    r3a, r3b = t.r3_time(b.output_nominal_in_s)
    mean = mean_interarrival(s.arrivals, s.base_dir)
    cycle, source = (c.nominal_cycle_s, "scenario") if c.nominal_cycle_s is not None else \
        (mean, "arrivals")
    # The nominal split (docs/model.md): R IV at the base's nominal rate, R II the rest of
    # the cycle; a cycle too short for that takes R IV down toward its peak-rate time,
    # and one shorter than the robot's fastest is the fastest.
    r4 = max(t.r4_nominal_s, t.r4_min_s)
    r2 = cycle - r1a - r1b - r3a - r3b - r4
    if r2 < t.r2_min_s:
        r2 = t.r2_min_s
        r4 = cycle - r1a - r1b - r3a - r3b - r2
        if r4 < t.r4_min_s:
            r4, source = t.r4_min_s, "fastest"
            cycle = r1a + r1b + r2 + r3a + r3b + r4
    length = b.input_length_in if b.input_length_in is not None else \
        b.input_nominal_in_s * cycle * 2
    return CellConstants(
        timing=t, v_nom=b.input_nominal_in_s, u_nom=b.output_nominal_in_s,
        cycle_nom=cycle, input_max=min(b.input_max_in_s, 1e9),
        output_max=b.output_max_in_s, spacing=b.spacing_in, tol=b.spacing_tol_in,
        input_length=length, r1_pre_nom=r1a, r1_post_nom=r1b, r3_pre_nom=r3a,
        r3_post_nom=r3b, r4_nom=r4, r2_nom=r2, r1_nom=r1a + r1b,
        input_min=b.input_min_in_s, output_min=b.output_min_in_s, part_size=s.part.size_in,
        input_absorb=_absorbable(t, b.input_nominal_in_s, r1a + r1b + (r2 - t.r2_min_s)),
        mean_interarrival_s=mean, nominal_from=source,
        lookahead_margin_s=lookahead_margin(s))


def lookahead_margin(s: Scenario) -> float:
    """``sensor.margin_s``, or its default: 0 for the ideal look-ahead; three standard
    deviations of a sensor's error, in time at the nominal input speed."""
    m = s.sensor
    if m.margin_s is not None:
        return float(m.margin_s)
    if m.lookahead == "ideal":
        return 0.0
    return 3.0 * m.noise_sd_in / s.belts.input_nominal_in_s


def _absorbable(t: RobotTiming, v_nom: float, r1_most_s: float) -> float:
    """The slowest belt speed at which R I (B → F, tracking) takes at most ``r1_most_s``:
    R I only lengthens as the belt slows, so bisect on the speed (to 1e-9 relative)."""
    def r1(v: float) -> float:
        return sum(t.r1_time(v))

    if r1(v_nom) >= r1_most_s:
        return v_nom
    lo, hi = v_nom * 1e-6, v_nom
    if r1(lo) <= r1_most_s:
        return lo
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if r1(mid) <= r1_most_s else (mid, hi)
    return hi


def _tracking_blame(s: Scenario, belt: str, speed: float) -> tuple[str, Any]:
    """The belt's speed, unless a changed motor or load key alone makes it untrackable."""
    for key in SPEED_KEYS[1:-1]:
        if s.get(key) == thesis().get(key):
            continue
        trial = with_key(s, key, thesis().get(key))
        if trial is None:
            continue
        t = robot_timing(trial)
        most = t.input_track_max_in_s if belt == "input" else t.output_track_max_in_s
        if speed <= most:
            return key, s.get(key)
    return f"belts.{belt}_nominal_in_s", speed


def nominal_cycle(s: Scenario) -> float:
    """The ideal cycle the controller aims at: ``controller.nominal_cycle_s``, else the
    arrivals' mean (or the robot's fastest cycle if the arrivals come faster)."""
    return constants(s, robot_timing(s)).cycle_nom


def make_policy(s: Scenario, k: CellConstants) -> Policy:
    """The scenario's policy, its every plan checked (:mod:`cell.sim.policies.check`)."""
    from cell.sim.policies.check import check_policy

    name = s.controller.policy
    cls = registry.load(name, s.source)
    try:
        policy = cls(k, s.controller, s.source)
    except CellError:
        raise
    except Exception as exc:  # noqa: BLE001 - a plug-in's failure, named
        raise registry.PluginError.of(name, "could not be built", exc) from exc
    return check_policy(policy, name, k)

