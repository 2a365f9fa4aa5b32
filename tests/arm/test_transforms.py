"""Homogeneous transforms against the thesis's worked examples (§2.2, eq. 2.9-2.25)."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from cell.arm.transforms import inverse, rot, trans

angles = st.floats(-2 * np.pi, 2 * np.pi, allow_nan=False)
offsets = st.floats(-50, 50, allow_nan=False)


def test_rot_z_90_of_p_eq_2_9():
    p = np.array([5, 2, 6, 1.0])
    np.testing.assert_allclose(rot("z", np.pi / 2) @ p, [-2, 5, 6, 1], atol=1e-15)


def test_rot_x_90_after_rot_z_eq_2_11_and_2_15():
    p = np.array([5, 2, 6, 1.0])
    q = rot("z", np.pi / 2) @ p
    np.testing.assert_allclose(rot("x", np.pi / 2) @ q, [-2, -6, 5, 1], atol=1e-15)
    compound = rot("x", np.pi / 2) @ rot("z", np.pi / 2)  # eq. 2.14
    np.testing.assert_allclose(compound, [[0, -1, 0, 0], [0, 0, -1, 0], [1, 0, 0, 0],
                                          [0, 0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(compound @ p, [-2, -6, 5, 1], atol=1e-15)


EQ_2_20 = np.array([[0, 1, 0, 3], [0, 0, 1, 5], [1, 0, 0, 10], [0, 0, 0, 1]], dtype=float)
EQ_2_23 = np.array([[0, 0, 1, -10], [1, 0, 0, -3], [0, 1, 0, -5], [0, 0, 0, 1]], dtype=float)


def test_inverse_of_eq_2_20_is_eq_2_23():
    """eq. 2.23 as printed (eq. 2.22 has scan typos, docs/model.md) is the inverse of eq. 2.20."""
    np.testing.assert_allclose(inverse(EQ_2_20), EQ_2_23, atol=1e-15)
    np.testing.assert_allclose(EQ_2_23 @ EQ_2_20, np.eye(4), atol=1e-15)


def test_eq_2_19_erratum():
    """Thesis erratum: eq. 2.19 says Trans(3,5,10) Rot(x,-90) Rot(z,90), but with the
    thesis's own Rot (eq. 2.5, 2.7) that product has -1 where eq. 2.20 prints +1 at
    (1,2) and (3,1).  The printed matrix is Trans(3,5,10) Rot(x,-90) Rot(z,-90)."""
    as_written = trans(3, 5, 10) @ rot("x", -np.pi / 2) @ rot("z", np.pi / 2)
    assert not np.allclose(as_written, EQ_2_20)
    diff = np.argwhere(~np.isclose(as_written, EQ_2_20))
    np.testing.assert_array_equal(diff, [[0, 1], [2, 0]])
    printed = trans(3, 5, 10) @ rot("x", -np.pi / 2) @ rot("z", -np.pi / 2)
    np.testing.assert_allclose(printed, EQ_2_20, atol=1e-15)


def test_rot_y_eq_2_6_sign_convention():
    np.testing.assert_allclose(rot("y", np.pi / 2) @ [1, 0, 0, 1], [0, 0, -1, 1], atol=1e-15)


@given(angles, angles, angles, offsets, offsets, offsets)
def test_inverse_eq_2_25_is_the_matrix_inverse(a, b, c, x, y, z):
    t = trans(x, y, z) @ rot("z", a) @ rot("y", b) @ rot("x", c)
    np.testing.assert_allclose(inverse(t) @ t, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(inverse(t), np.linalg.inv(t), atol=1e-11)


def test_vectorised_over_angles():
    th = np.linspace(0, np.pi, 7)
    batch = rot("z", th)
    assert batch.shape == (7, 4, 4)
    for i, a in enumerate(th):
        np.testing.assert_array_equal(batch[i], rot("z", a))
    np.testing.assert_allclose(inverse(batch) @ batch, np.broadcast_to(np.eye(4), (7, 4, 4)),
                               atol=1e-15)
