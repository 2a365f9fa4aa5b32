"""MICROBOT kinematics against the thesis's equations (§3, §6.1) and docs/model.md."""

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from cell.arm.kinematics import (
    GRASP,
    Arm,
    Hand,
    Placement,
    a_matrix,
    arm_target,
    forward,
    hand_length,
    inverse_kinematics,
    tool_centre,
)
from cell.arm.transforms import rot, trans
from cell.plumbing.errors import UnreachableError

ARM = Arm()
CELL = Placement()
HAND = Hand()


def eq_3_14(q, l2=7.0, l3=7.0):
    """T5 written out element by element as the thesis prints it (eq. 3.13-3.14)."""
    t1, t2, t3, t4, t5 = q
    c1, s1, c5, s5 = np.cos(t1), np.sin(t1), np.cos(t5), np.sin(t5)
    c234, s234 = np.cos(t2 + t3 + t4), np.sin(t2 + t3 + t4)
    c23, s23, c2, s2 = np.cos(t2 + t3), np.sin(t2 + t3), np.cos(t2), np.sin(t2)
    return np.array([
        [c1 * c234 * c5 - s1 * s5, -c1 * c234 * s5 - s1 * c5, -c1 * s234, c1 * (c23 * l3 + c2 * l2)],
        [s1 * c234 * c5 + c1 * s5, -s1 * c234 * s5 + c1 * c5, -s1 * s234, s1 * (c23 * l3 + c2 * l2)],
        [s234 * c5, -s234 * s5, c234, s23 * l3 + s2 * l2],
        [0, 0, 0, 1]])


def test_a_matrix_is_eq_3_1_product():
    th, d, a, al = 0.3, 1.5, 2.5, -0.7
    expected = rot("z", th) @ trans(0, 0, d) @ trans(a, 0, 0) @ rot("x", al)
    np.testing.assert_allclose(a_matrix(th, d, a, al), expected, atol=1e-15)


def test_a1_and_a4_match_eq_3_3_and_3_6():
    th = 0.4
    c, s = np.cos(th), np.sin(th)
    np.testing.assert_allclose(a_matrix(th, 0, 0, np.pi / 2),
                               [[c, 0, s, 0], [s, 0, -c, 0], [0, 1, 0, 0], [0, 0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(a_matrix(th, 0, 0, -np.pi / 2),
                               [[c, 0, -s, 0], [s, 0, c, 0], [0, -1, 0, 0], [0, 0, 0, 1]], atol=1e-15)


def in_range_q():
    lim = np.degrees(ARM.limits_rad)
    return st.tuples(*(st.floats(float(lo), float(hi)) for lo, hi in lim)).map(np.radians)


@given(in_range_q())
def test_forward_is_eq_3_14(q_deg):
    np.testing.assert_allclose(forward(q_deg), eq_3_14(q_deg), atol=1e-12)


def test_forward_vectorised():
    rng = np.random.default_rng(0)
    lim = ARM.limits_rad
    q = lim[:, 0] + rng.random((50, 5)) * (lim[:, 1] - lim[:, 0])
    batch = forward(q)
    assert batch.shape == (50, 4, 4)
    for i in range(0, 50, 7):
        np.testing.assert_allclose(batch[i], eq_3_14(q[i]), atol=1e-12)


def _regular(q):
    """Away from the IK's singular sets: wrist on the base axis, arm fully stretched."""
    t1, t2, t3 = q[0], q[1], q[2]
    r = 7 * np.cos(t2 + t3) + 7 * np.cos(t2)
    return abs(r) > 1e-3 and t3 < -1e-4 and abs(abs(t1) - np.pi / 2) > 1e-6


@settings(max_examples=400)
@given(in_range_q())
def test_ik_recovers_q_over_the_joint_ranges(q):
    """IK(FK(q)) = q within 1e-9 rad, away from the singular sets."""
    assume(_regular(q))
    back = inverse_kinematics(forward(q))
    np.testing.assert_allclose(back[:4], q[:4], atol=1e-9)
    # θ5's range is a whole turn: -180° and +180° are the same joint angle
    assert abs(np.angle(np.exp(1j * (back[4] - q[4])))) < 1e-9


@settings(max_examples=200)
@given(in_range_q())
# the wrist just behind the base axis with θ1 at the end of its range: the other θ1 branch
# is at the other end of the range, but would need θ4 outside its own (found by hypothesis)
@example(np.radians((90.0, -17.0, -147.0, -34.0, 0.0)))
def test_fk_of_ik_is_the_pose(q):
    t2, t3 = q[1], q[2]
    assume(abs(7 * np.cos(t2 + t3) + 7 * np.cos(t2)) > 1e-3)  # θ1 undefined on the base axis
    t = forward(q)
    np.testing.assert_allclose(forward(inverse_kinematics(t)), t, atol=1e-9)


def test_ik_out_of_reach_names_the_point():
    t = trans(20.0, 0, 0) @ rot("x", np.pi)
    with pytest.raises(UnreachableError, match=r"out of reach.*reaches 0.0000 to 14.0000"):
        inverse_kinematics(t)


def test_ik_outside_joint_range_names_the_joint():
    # wrist point reachable but behind-below: the base would need more than ±90°
    t = trans(-3.0, -9.0, 0.0) @ rot("x", np.pi)
    with pytest.raises(UnreachableError, match=r"theta\d .*outside its range"):
        inverse_kinematics(t, label=lambda i: "test point")


def test_ik_never_clamps_a_range_violation():
    q = np.radians([10.0, 30.0, -60.0, -100.0, 0.0])
    narrow = Arm(limits=tuple(map(tuple, np.radians(
        [[-90, 90], [-35, 144], [-149, 0], [-95, 0], [-180, 180]]))))
    with pytest.raises(UnreachableError, match="theta4"):
        inverse_kinematics(forward(q), narrow)


def test_placement_eq_6_1():
    z = CELL.frame()
    h = np.sqrt(0.5)
    np.testing.assert_allclose(z, [[h, h, 0, -8], [-h, h, 0, 8], [0, 0, 1, 7.68], [0, 0, 0, 1]],
                               atol=1e-15)


def test_hand_length_eq_6_2_holding_a_cube():
    # docs/model.md: holding a 2.0 in cube, w11 = 3.5498 in
    assert hand_length(2.0, HAND) == pytest.approx(3.5498, abs=5e-5)
    # at G = G0 the linkage is straight: L1 + L2
    assert hand_length(1.52, HAND) == pytest.approx(1.884 + 1.700)


def test_grasp_eq_6_4():
    np.testing.assert_allclose(GRASP, np.diag([1.0, -1, -1, 1]), atol=1e-15)


def test_thesis_points_in_the_robot_frame_give_the_base_angles():
    """docs/model.md: B at θ1 = -90°, F at -45°, G at +45°, K at +90°."""
    pts = np.array([[-16, 0, 3], [-8, 0, 3], [0, 8, 3], [0, 16, 3]], dtype=float)
    q = inverse_kinematics(arm_target(pts, 0.0, 2.0, CELL, HAND))
    np.testing.assert_allclose(np.degrees(q[:, 0]), [-90, -45, 45, 90], atol=1e-9)


@given(st.floats(-15, -9), st.floats(-1, 1), st.floats(1, 4), st.floats(0, np.pi / 2))
def test_transformation_equation_round_trip(x, y, z, phi):
    """Z T5 E = P PG (eq. 6.6): solving eq. 6.7 and going forward lands on the point."""
    xyz = np.array([x, y, z])
    q = inverse_kinematics(arm_target(xyz, phi, 2.0, CELL, HAND))
    np.testing.assert_allclose(tool_centre(q, 2.0, CELL, ARM, HAND), xyz, atol=1e-9)
    full = CELL.frame() @ forward(q) @ trans(0, 0, hand_length(2.0, HAND))
    np.testing.assert_allclose(full[:3, 2], [0, 0, -1], atol=1e-9)  # approach straight down
