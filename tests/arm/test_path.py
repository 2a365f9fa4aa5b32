"""The transfer path against the thesis's geometry (§4.1-4.2, Fig. 8-9) and docs/model.md."""

import numpy as np
import pytest

from cell.arm.kinematics import Arm, forward, tool_centre
from cell.arm.path import CellGeometry, build_path
from cell.arm.transforms import trans
from cell.scenario.schema import default_scenario
from cell.sim.scenario_values import geometry_of

G = CellGeometry()
P = build_path(G)
BASE = np.array([-8.0, 8.0])


def chord_polyline(radius, angle, n):
    """Length of an arc of ``angle`` divided into n equal chords."""
    return 2 * radius * n * np.sin(angle / (2 * n))


def test_460_points_four_regimes():
    assert P.n_points == 460  # §4.2: 460 points, 459 moves
    counts = np.bincount(P.regime[1:], minlength=5)[1:]
    assert counts.tolist() == [96, 117, 96, 150]


def test_regime_ends_are_the_thesis_points():
    g_idx = 96 + 117
    k_idx = g_idx + 96
    np.testing.assert_allclose(P.xyz_in[[0, 96, g_idx, k_idx, 459]],
                               [[-16, 0, 3], [-8, 0, 3], [0, 8, 3], [0, 16, 3], [-16, 0, 3]],
                               atol=1e-12)


def test_tracking_follows_the_belt_centrelines():
    r1 = P.xyz_in[: 97]
    r3 = P.xyz_in[96 + 117: 96 + 117 + 97]
    np.testing.assert_allclose(r1[:, 1], 0.0, atol=1e-12)  # input belt: y = 0
    np.testing.assert_allclose(r3[:, 0], 0.0, atol=1e-12)  # output belt: x = 0
    assert np.all(np.diff(r1[:, 0]) > 0) and np.all(np.diff(r3[:, 1]) > 0)


def test_lo_and_td_are_the_dips_bottoms_mid_window():
    np.testing.assert_allclose(P.xyz_in[P.lo], [-12, 0, 1.0], atol=1e-12)
    np.testing.assert_allclose(P.xyz_in[P.td], [0, 12, 1.0], atol=1e-12)
    assert P.xyz_in[:97, 2].min() == pytest.approx(1.0)
    assert P.events[P.lo] == "LO" and P.events[P.td] == "TD"
    assert (P.events != "").sum() == 2


def test_dips_are_clamped_splines():
    """Zero slope at the window's ends (clamped end tangents, §4.2) and C1 through LO."""
    x, z = P.xyz_in[:97, 0], P.xyz_in[:97, 2]
    slope = np.diff(z) / np.diff(x)
    h = x[1] - x[0]
    assert abs(slope[0]) < 2 * h and abs(slope[-1]) < 2 * h  # O(h) from a zero end slope
    assert np.max(np.abs(np.diff(slope))) < 0.1  # no kinks
    assert np.all(z <= 3.0 + 1e-12) and np.all(z >= 1.0 - 1e-12)


def test_arcs_lie_on_circles_about_the_base_axis():
    r2 = P.xyz_in[96: 96 + 118]
    r4 = P.xyz_in[96 + 117 + 96:]
    np.testing.assert_allclose(np.hypot(*(r2[:, :2] - BASE).T), 8.0, atol=1e-12)
    np.testing.assert_allclose(np.hypot(*(r4[:, :2] - BASE).T), 8 * np.sqrt(2), atol=1e-12)
    np.testing.assert_allclose(r2[:, 2], 3.0)
    np.testing.assert_allclose(r4[:, 2], 3.0)


def test_regime_lengths_closed_forms():
    """docs/model.md: R II 12.566 in (arc), R IV 35.5424 in (150 chords of the 35.5431 in arc)."""
    ell = P.move_in
    r2 = ell[P.regime == 2].sum()
    r4 = ell[P.regime == 4].sum()
    assert r2 == pytest.approx(chord_polyline(8.0, np.pi / 2, 117), rel=1e-12)
    assert r2 == pytest.approx(12.566, abs=2e-3)
    assert r4 == pytest.approx(chord_polyline(8 * np.sqrt(2), np.pi, 150), rel=1e-12)
    assert r4 == pytest.approx(35.5424, abs=1e-4)


def test_every_point_is_reached_inside_the_joint_ranges():
    lim = Arm().limits_rad
    assert np.all(P.q_rad >= lim[:, 0] - 1e-9) and np.all(P.q_rad <= lim[:, 1] + 1e-9)
    np.testing.assert_allclose(tool_centre(P.q_rad, P.opening_in, G.placement, G.arm, G.hand),
                               P.xyz_in, atol=1e-9)


def test_base_angles_span_the_whole_range():
    """docs/model.md: B at -90°, F at -45°, G at +45°, K at +90°."""
    g_idx = 96 + 117
    np.testing.assert_allclose(np.degrees(P.q_rad[[0, 96, g_idx, g_idx + 96], 0]),
                               [-90, -45, 45, 90], atol=1e-9)


def _hand_frames():
    """Z T5 E: the hand's frame in the global frame (the hand length does not rotate it)."""
    return G.placement.frame() @ forward(P.q_rad) @ trans(0, 0, 1.0)


def test_hand_points_down_and_the_part_turns_90_degrees():
    """PG: approach along the part's -z, orientation along its -y (eq. 6.4); the part is
    turned +90° during R II (eq. 6.5) and the hand turned back during R IV."""
    frames = _hand_frames()
    np.testing.assert_allclose(frames[:, :3, 2], np.tile([0, 0, -1.0], (460, 1)), atol=1e-9)
    o = frames[:, :3, 1]
    np.testing.assert_allclose(o[:97], np.tile([0, -1.0, 0], (97, 1)), atol=1e-9)  # R I
    r3 = slice(96 + 117, 96 + 117 + 97)
    np.testing.assert_allclose(o[r3], np.tile([1.0, 0, 0], (97, 1)), atol=1e-9)  # R III
    np.testing.assert_allclose(o[-1], [0, -1.0, 0], atol=1e-9)  # back by B


def test_r2_moves_only_the_base_and_r4_the_base_and_roll():
    """§4.2: R II is base rotation only; R IV the base and the hand roll."""
    dq = np.diff(P.q_rad, axis=0)
    r2 = P.regime[1:] == 2
    r4 = P.regime[1:] == 4
    np.testing.assert_allclose(dq[r2][:, 1:], 0.0, atol=1e-9)
    np.testing.assert_allclose(dq[r4][:, 1:4], 0.0, atol=1e-9)
    assert np.degrees(dq[r4][:, 4].sum()) == pytest.approx(-90.0)
    assert np.degrees(dq[r4][:, 0].sum()) == pytest.approx(-180.0)


def test_load_and_finger_opening_between_lo_and_td():
    idx = np.arange(P.n_points)
    held = (idx > P.lo) & (idx <= P.td)
    assert np.all(P.load_oz[held] == 4.0) and np.all(P.load_oz[~held] == 0.0)
    grip = (idx >= P.lo) & (idx <= P.td)
    assert np.all(P.opening_in[grip] == 2.0) and np.all(P.opening_in[~grip] == 2.5)


def test_moves_and_positions_come_from_the_scenario():
    s = default_scenario().with_overrides({"path.moves.R1": 40, "path.lo_from_bot_in": 2.0,
                                           "path.pick_height_in": 1.5})
    p = build_path(geometry_of(s))
    assert p.n_points == 460 - 56
    np.testing.assert_allclose(p.xyz_in[p.lo], [-14, 0, 1.5], atol=1e-12)
