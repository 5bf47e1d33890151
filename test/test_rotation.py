# Copyright 2026 iemd_ros authors
# SPDX-License-Identifier: BSD-3-Clause
#
# Redistribution and use in source and binary forms, with or without
# modification, are permitted provided that the following conditions are met:
#
#    * Redistributions of source code must retain the above copyright
#      notice, this list of conditions and the following disclaimer.
#
#    * Redistributions in binary form must reproduce the above copyright
#      notice, this list of conditions and the following disclaimer in the
#      documentation and/or other materials provided with the distribution.
#
#    * Neither the name of the iemd_ros authors nor the names of its
#      contributors may be used to endorse or promote products derived from
#      this software without specific prior written permission.
#
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"
# AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE
# IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE
# ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE
# LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR
# CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF
# SUBSTITUTE GOODS OR SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS
# INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN
# CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE)
# ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE
# POSSIBILITY OF SUCH DAMAGE.

"""
Rotation integration: exact exponential map vs closed forms, the paper's first-order step (eq.

21-22).
"""
from iemd_ros.gyro.rotation import (
    GyroCalibration,
    integrate_first_order,
    integrate_rates,
    omega_matrix,
    quat_exp,
    quat_mul,
    quat_to_rot,
    rot_to_quat,
    rotation_angle,
    skew,
    so3_exp,
    StillBiasEstimator,
)
import numpy as np
import pytest


def rodrigues(phi):
    th = np.linalg.norm(phi)
    k = skew(phi / th)
    return np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k


def test_exp_matches_rodrigues_and_quaternion_roundtrip():
    rng = np.random.default_rng(1)
    for phi in rng.normal(0, 1.5, (20, 3)):
        R = so3_exp(phi)
        np.testing.assert_allclose(R, rodrigues(phi), atol=1e-12)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(quat_to_rot(rot_to_quat(R)), R, atol=1e-12)
        assert rotation_angle(R) == pytest.approx(
            np.linalg.norm(phi)
            if np.linalg.norm(phi) <= np.pi
            else 2 * np.pi - np.linalg.norm(phi),
            abs=1e-9,
        )
    # near-zero and near-pi angles
    np.testing.assert_allclose(
        so3_exp([1e-9, 0, 0]), rodrigues(np.array([1e-9, 0, 0])), atol=1e-15
    )
    R = so3_exp([0, np.pi - 1e-7, 0])
    np.testing.assert_allclose(quat_to_rot(rot_to_quat(R)), R, atol=1e-9)


def test_quat_to_rot_entries_and_batches():
    """
    Eq. 22's layout (a quarter turn about x), normalization.

    And (..., 4) batches equal to one at a time.
    """
    np.testing.assert_allclose(
        quat_to_rot([1.0, 1.0, 0.0, 0.0]), [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-15
    )
    q = np.random.default_rng(3).normal(size=(5, 7, 4))
    R = quat_to_rot(q)
    assert R.shape == (5, 7, 3, 3) and quat_to_rot(q[0, 0]).shape == (3, 3)
    for i in range(5):
        np.testing.assert_array_equal(quat_to_rot(q[i]), R[i])
        for j in range(7):
            np.testing.assert_array_equal(quat_to_rot(q[i, j]), R[i, j])
            np.testing.assert_array_equal(quat_to_rot(-q[i, j]), R[i, j])
            np.testing.assert_allclose(quat_to_rot(3.0 * q[i, j]), R[i, j], atol=1e-15)
    np.testing.assert_allclose(
        R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-15
    )
    assert quat_to_rot(np.zeros((0, 4))).shape == (0, 3, 3)


def test_omega_matrix_is_right_multiplication_by_rate():
    """
    The paper's Omega(w) q equals q * (0, w): body rates, right-multiplied (eq.

    21).
    """
    rng = np.random.default_rng(2)
    q = rng.normal(size=4)
    w = rng.normal(size=3)
    np.testing.assert_allclose(omega_matrix(w) @ q, quat_mul(q, np.r_[0.0, w]), atol=1e-12)


def test_constant_rate_matches_closed_form():
    w = np.radians(257.0) * np.array([0.3, 1.0, -0.2]) / np.linalg.norm([0.3, 1.0, -0.2])
    t = np.array([0.0, 0.004, 0.014, 0.024, 0.0333])  # irregular knots, constant rate
    q = integrate_rates(t, np.tile(w, (len(t), 1)))
    np.testing.assert_allclose(quat_to_rot(q), so3_exp(w * t[-1]), atol=1e-13)


def test_coning_term_makes_linear_rate_integration_4th_order():
    """A linear rate whose axis turns: the exact scheme beats trapezoid-only and converges fast."""
    w0, w1 = np.radians([200.0, 0.0, 50.0]), np.radians([0.0, 250.0, -80.0])
    T = 0.05

    def rate(t):
        return w0 + (w1 - w0) * (t / T)[:, None]

    fine = np.linspace(0, T, 4001)
    ref = integrate_rates(fine, rate(fine))
    coarse = np.array([0.0, T])
    err_c = rotation_angle(
        quat_to_rot(quat_mul(ref * [1, -1, -1, -1], integrate_rates(coarse, rate(coarse))))
    )
    err_t = rotation_angle(
        quat_to_rot(
            quat_mul(ref * [1, -1, -1, -1], integrate_rates(coarse, rate(coarse), coning=False))
        )
    )
    assert err_t > 1e-5  # the coning correction matters at these rates
    assert err_c < err_t / 50


def test_paper_first_order_step_error_is_the_known_tangent_error():
    """One normalized Euler quaternion step turns by 2 atan(theta/2) instead of theta."""
    w = np.radians(257.0) * np.array([0.0, 1.0, 0.0])
    for dt in (1 / 100, 1 / 30, 1 / 11):
        q = integrate_first_order(np.array([0.0, dt]), np.tile(w, (2, 1)))
        theta = np.linalg.norm(w) * dt
        assert rotation_angle(quat_to_rot(q)) == pytest.approx(2 * np.arctan(theta / 2), rel=1e-12)
        exact = integrate_rates(np.array([0.0, dt]), np.tile(w, (2, 1)))
        assert rotation_angle(quat_to_rot(exact)) == pytest.approx(theta, rel=1e-12)


def test_quat_exp_is_unit_and_small_angle_safe():
    q = quat_exp(np.array([[0, 0, 0], [1e-9, 0, 0], [3.0, 0, 0]]))
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    assert np.all(np.isfinite(q))


def test_calibration_applies_bias_then_rotation_and_validates():
    R = so3_exp([0.0, 0.0, np.pi / 2])
    cal = GyroCalibration(R, [0.1, 0.0, 0.0])
    np.testing.assert_allclose(cal.to_camera([[0.1, 1.0, 0.0]]), [[-1.0, 0.0, 0.0]], atol=1e-12)
    with pytest.raises(ValueError, match='rotation'):
        GyroCalibration(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match='bias'):
        GyroCalibration(None, [0.0, np.nan, 0.0])


def test_still_bias_estimator():
    rng = np.random.default_rng(3)
    bias = np.array([0.02, -0.01, 0.005])
    est = StillBiasEstimator(n=200, max_std=0.02)
    assert not est.update(bias + rng.normal(0, 0.004, (150, 3)))
    assert 'collecting 150/200' in est.status
    assert est.update(bias + rng.normal(0, 0.004, (100, 3)))
    np.testing.assert_allclose(est.bias, bias, atol=0.002)
    moving = StillBiasEstimator(n=100, max_std=0.02)
    assert not moving.update(np.radians(50) * np.sin(np.linspace(0, 6, 100))[:, None] * [1, 0, 0])
    assert moving.bias is None and 'not still' in moving.status
    with pytest.raises(ValueError):
        StillBiasEstimator(n=1)
