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
Rotation from gyroscope rates (paper, "Gyroscope Data Fusion for Rotation Compensation").

Conventions
-----------
* Quaternions are Hamilton, scalar first: ``q = m + a i + b j + c k`` stored as ``[m, a, b, c]``,
  exactly the paper's notation of eq. 22.
* Rates are *body* rates: ``dR/dt = R [w]x``, so ``R(t)`` is the orientation of the sensor at time
  t expressed in the sensor frame at the start of the interval.  Composition is by right
  multiplication, ``R = exp([w1 dt1]x) exp([w2 dt2]x) ...``, which is also what the paper's
  ``Omega(w) q`` (eq. 21) means: ``Omega(w) q == q * (0, w)``.
* ``R_cam_imu`` maps IMU-frame vectors into the camera frame (``w_cam = R_cam_imu w_imu``); the
  gyro bias is in the IMU frame and subtracted before rotating.

The exact integrator treats the rate as piecewise linear between samples (the samples are its
knots) and integrates each sub-interval with the exact SO(3) exponential of the 4th-order Magnus
term ``h (w0 + w1) / 2 + h^2 / 12 (w0 x w1)`` (trapezoid rate plus the coning correction); the
paper's first-order step is :func:`integrate_first_order`, kept for comparison.

"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

__all__ = [
    'skew', 'quat_mul', 'quat_normalize', 'quat_to_rot', 'rot_to_quat', 'quat_exp', 'so3_exp',
    'rotation_angle', 'omega_matrix', 'integrate_rates', 'integrate_first_order',
    'GyroCalibration', 'StillBiasEstimator',
]


def skew(w) -> np.ndarray:
    """
    ``[w]x``: the 3x3 cross-product matrix of ``w``.

    Parameters
    ----------
    w : array_like
        (3,) vector, or (N, 3) vectors.

    Returns
    -------
    ndarray
        (3, 3), or (N, 3, 3).

    """
    w = np.asarray(w, dtype=float)
    out = np.zeros(w.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -w[..., 2], w[..., 1]
    out[..., 1, 0], out[..., 1, 2] = w[..., 2], -w[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -w[..., 1], w[..., 0]
    return out


def quat_mul(p, q) -> np.ndarray:
    """
    Hamilton product ``p * q`` of scalar-first quaternions.

    Parameters
    ----------
    p, q : array_like
        (..., 4) quaternions; the leading axes broadcast.

    Returns
    -------
    ndarray
        (..., 4) products.

    """
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack([
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ], axis=-1)


def quat_normalize(q) -> np.ndarray:
    """
    Return unit quaternion with a non-negative scalar part.

    (``q`` and ``-q`` are the same rotation).

    Parameters
    ----------
    q : array_like
        (..., 4) quaternions.

    Returns
    -------
    ndarray
        (..., 4) unit quaternions.

    Raises
    ------
    ValueError
        For a zero or non-finite quaternion.

    """
    q = np.asarray(q, dtype=float)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if (n == 0).any() or not np.isfinite(n).all():
        raise ValueError('cannot normalize a zero or non-finite quaternion')
    q = q / n
    return np.where(q[..., :1] < 0, -q, q)


def quat_to_rot(q) -> np.ndarray:
    """
    Rotation matrix of a unit quaternion ``[m, a, b, c]`` (paper eq. 22).

    The nine entries go into one array (for one quaternion they are numpy scalars: no stacking).

    Parameters
    ----------
    q : array_like
        (..., 4) quaternions (normalized here).

    Returns
    -------
    ndarray
        (..., 3, 3) rotation matrices.

    Raises
    ------
    ValueError
        For a zero or non-finite quaternion.

    """
    q = quat_normalize(q)
    m, a, b, c = q.transpose(-1, *range(q.ndim - 1))
    R = np.array([1 - 2 * b * b - 2 * c * c, 2 * a * b - 2 * c * m, 2 * a * c + 2 * b * m,
                  2 * a * b + 2 * c * m, 1 - 2 * a * a - 2 * c * c, 2 * b * c - 2 * a * m,
                  # (9, ...)
                  2 * a * c - 2 * b * m, 2 * b * c + 2 * a * m, 1 - 2 * a * a - 2 * b * b])
    return R.transpose(*range(1, R.ndim), 0).reshape(q.shape[:-1] + (3, 3))


def rot_to_quat(R) -> np.ndarray:
    """
    Return unit quaternion of a rotation matrix (Shepperd's method, robust for all angles).

    Parameters
    ----------
    R : array_like
        (..., 3, 3) rotation matrices.

    Returns
    -------
    ndarray
        (..., 4) unit quaternions with a non-negative scalar part.

    Raises
    ------
    ValueError
        When the last two axes are not 3 x 3.

    """
    R = np.asarray(R, dtype=float)
    if R.shape[-2:] != (3, 3):
        raise ValueError(f'rotation matrices must be (..., 3, 3), got shape {R.shape}')
    tr = np.trace(R, axis1=-2, axis2=-1)
    cands = np.stack(
        [
            np.stack(
                [
                    1 + tr,
                    R[..., 2, 1] - R[..., 1, 2],
                    R[..., 0, 2] - R[..., 2, 0],
                    R[..., 1, 0] - R[..., 0, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 2, 1] - R[..., 1, 2],
                    1 + 2 * R[..., 0, 0] - tr,
                    R[..., 0, 1] + R[..., 1, 0],
                    R[..., 0, 2] + R[..., 2, 0],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 0, 2] - R[..., 2, 0],
                    R[..., 0, 1] + R[..., 1, 0],
                    1 + 2 * R[..., 1, 1] - tr,
                    R[..., 1, 2] + R[..., 2, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    R[..., 1, 0] - R[..., 0, 1],
                    R[..., 0, 2] + R[..., 2, 0],
                    R[..., 1, 2] + R[..., 2, 1],
                    1 + 2 * R[..., 2, 2] - tr,
                ],
                -1,
            ),
        ],
        axis=-2,
    )
    diag = np.stack([tr, R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]], -1)
    best = np.argmax(diag, axis=-1)
    q = np.take_along_axis(cands, best[..., None, None], axis=-2)[..., 0, :]
    return quat_normalize(q)


def quat_exp(phi) -> np.ndarray:
    """
    Return unit quaternion of the rotation vector ``phi`` (exact exponential map).

    Parameters
    ----------
    phi : array_like
        (..., 3) rotation vectors, radians.

    Returns
    -------
    ndarray
        (..., 4) unit quaternions.

    """
    phi = np.asarray(phi, dtype=float)
    theta = np.linalg.norm(phi, axis=-1, keepdims=True)
    half = 0.5 * theta
    # sin(theta/2)/theta, with its Taylor series near 0
    small = theta < 1e-6
    k = np.where(small, 0.5 - theta**2 / 48.0, np.sin(half) / np.where(small, 1.0, theta))
    return np.concatenate([np.cos(half), k * phi], axis=-1)


def so3_exp(phi) -> np.ndarray:
    """
    Rotation matrix ``exp([phi]x)`` (Rodrigues).

    Parameters
    ----------
    phi : array_like
        (..., 3) rotation vectors, radians.

    Returns
    -------
    ndarray
        (..., 3, 3) rotation matrices.

    """
    return quat_to_rot(quat_exp(phi))


def rotation_angle(R) -> np.ndarray:
    """
    Angle of a rotation matrix (numerically safe for small and large angles).

    Parameters
    ----------
    R : array_like
        (..., 3, 3) rotation matrices.

    Returns
    -------
    ndarray
        (...) angles in radians.

    """
    q = rot_to_quat(R)
    return 2.0 * np.arctan2(np.linalg.norm(q[..., 1:], axis=-1), np.abs(q[..., 0]))


def omega_matrix(w) -> np.ndarray:
    """
    Return the paper's 4x4 ``Omega(w) = [[0, -w^T], [w, -[w]x]]`` (eq.

    21), with ``Omega(w) q = q * (0, w)``.

    Parameters
    ----------
    w : array_like
        (..., 3) body rates.

    Returns
    -------
    ndarray
        (..., 4, 4) matrices.

    """
    w = np.asarray(w, dtype=float)
    out = np.zeros(w.shape[:-1] + (4, 4))
    out[..., 0, 1:] = -w
    out[..., 1:, 0] = w
    out[..., 1:, 1:] = -skew(w)
    return out


@numba.njit(cache=True)
def _exp_product(phi):
    """
    Ordered product ``exp(phi_1) * ...

    * exp(phi_n)`` as a unit quaternion with w >= 0.

    One scalar loop: a frame interval has a handful of gyro samples, where numpy's per-call
    overhead dominates.
    """
    qw, qx, qy, qz = 1.0, 0.0, 0.0, 0.0
    for i in range(phi.shape[0]):
        theta = np.sqrt(phi[i, 0] ** 2 + phi[i, 1] ** 2 + phi[i, 2] ** 2)
        k = 0.5 - theta**2 / 48.0 if theta < 1e-6 else np.sin(0.5 * theta) / theta
        pw, px, py, pz = np.cos(0.5 * theta), k * phi[i, 0], k * phi[i, 1], k * phi[i, 2]
        qw, qx, qy, qz = (
            qw * pw - qx * px - qy * py - qz * pz,
            qw * px + qx * pw + qy * pz - qz * py,
            qw * py - qx * pz + qy * pw + qz * px,
            qw * pz + qx * py - qy * px + qz * pw,
        )
    n = np.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    sign = -1.0 if qw < 0 else 1.0
    return np.array([qw, qx, qy, qz]) * (sign / n)


def integrate_rates(t, w, coning: bool = True) -> np.ndarray:
    """
    Exact integration of a piecewise-linear body rate through knots ``(t_i, w_i)``.

    The rotation is ``R = prod_i exp(phi_i)`` (right-multiplied, so ``R`` is the orientation at
    ``t[-1]`` in the frame at ``t[0]``), with ``phi_i = h_i (w_i + w_{i+1}) / 2 + coning * h_i^2 /
    12 (w_i x w_{i+1})`` (4th-order Magnus for a linear rate).

    Parameters
    ----------
    t : array_like
        (N,) knot times in seconds (any origin), strictly increasing.
    w : array_like
        (N, 3) rates, rad/s.
    coning : bool, optional
        Include the coning term.

    Returns
    -------
    ndarray
        (4,) unit quaternion of ``R`` (the identity with fewer than 2 knots).

    Raises
    ------
    ValueError
        For other shapes, or knot times that do not increase strictly.

    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(w, dtype=float)
    if t.ndim != 1 or w.shape != (len(t), 3):
        raise ValueError(
            f'need t of shape (N,) and w of shape (N, 3), got {t.shape} and {w.shape}'
        )
    if len(t) < 2:
        return np.array([1.0, 0.0, 0.0, 0.0])
    if np.any(np.diff(t) <= 0):
        raise ValueError('knot times must be strictly increasing')
    return magnus_product(t, w, coning)


@numba.njit(cache=True)
def magnus_product(t, w, coning):
    """
    Return the compiled core of :func:`integrate_rates` (knots already checked).

    Parameters
    ----------
    t : ndarray
        (N,) knot times, s, strictly increasing.
    w : ndarray
        (N, 3) rates, rad/s.
    coning : bool
        Include the coning term.

    Returns
    -------
    ndarray
        (4,) unit quaternion with w >= 0.

    """
    phi = np.empty((t.size - 1, 3))
    for i in range(t.size - 1):
        h = t[i + 1] - t[i]
        a, b = w[i], w[i + 1]
        for k in range(3):
            phi[i, k] = 0.5 * h * (a[k] + b[k])
        if coning:
            c = h * h / 12.0
            phi[i, 0] += c * (a[1] * b[2] - a[2] * b[1])
            phi[i, 1] += c * (a[2] * b[0] - a[0] * b[2])
            phi[i, 2] += c * (a[0] * b[1] - a[1] * b[0])
    return _exp_product(phi)


def integrate_first_order(t, w) -> np.ndarray:
    """
    Return the paper's step ``q(k+1) = q(k) + 1/2 Omega(w_k) q(k) dt`` (eq.

    21), renormalized each step.

    Forward Euler with the rate held at each sample over ``[t_k, t_{k+1})`` (as a sampled gyro is
    used in the paper's Algorithm 2).

    Parameters
    ----------
    t : array_like
        (N,) sample times, s.
    w : array_like
        (N, 3) rates, rad/s.

    Returns
    -------
    ndarray
        (4,) the final unit quaternion.

    Raises
    ------
    ValueError
        For other shapes.

    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(w, dtype=float)
    if t.ndim != 1 or w.shape != (len(t), 3):
        raise ValueError(
            f'need t of shape (N,) and w of shape (N, 3), got {t.shape} and {w.shape}'
        )
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for dt, om in zip(np.diff(t), omega_matrix(w[:-1])):
        q = quat_normalize(q + 0.5 * (om @ q) * dt)
    return q


@dataclass(frozen=True)
class GyroCalibration:
    """
    IMU->camera rotation and gyro bias: ``w_cam = R_cam_imu (w_imu - bias)``.

    Parameters
    ----------
    R_cam_imu : array_like, optional
        3x3 proper rotation (None: identity).
    bias : array_like, optional
        (3,) gyro bias in the IMU frame, rad/s (None: zeros).

    Raises
    ------
    ValueError
        For a rotation that is not proper or a bias that is not 3 finite values.

    """

    R_cam_imu: np.ndarray = None  # type: ignore[assignment]
    bias: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self):
        R, b = self.checked(self.R_cam_imu, self.bias)
        object.__setattr__(self, 'R_cam_imu', R)
        object.__setattr__(self, 'bias', b)

    @staticmethod
    def checked(R_cam_imu, bias) -> tuple[np.ndarray, np.ndarray]:
        """
        ``(R_cam_imu, bias)`` as arrays, checked.

        Parameters
        ----------
        R_cam_imu : array_like or None
            3x3 rotation (None: identity).
        bias : array_like or None
            3 values, rad/s (None: zeros).

        Returns
        -------
        R_cam_imu : ndarray
            (3, 3) rotation.
        bias : ndarray
            (3,) bias.

        Raises
        ------
        ValueError
            Unless a proper rotation and 3 finite values.

        """
        R = np.eye(3) if R_cam_imu is None else np.asarray(R_cam_imu, dtype=float)
        b = np.zeros(3) if bias is None else np.asarray(bias, dtype=float)
        if (
            R.shape != (3, 3)
            or not np.allclose(R @ R.T, np.eye(3), atol=1e-6)
            or np.linalg.det(R) < 0
        ):
            raise ValueError(f'R_cam_imu must be a proper 3x3 rotation matrix, got {R.tolist()}')
        if b.shape != (3,) or not np.all(np.isfinite(b)):
            raise ValueError(f'gyro bias must be 3 finite values (rad/s), got {b.tolist()}')
        return R, b

    def to_camera(self, w_imu) -> np.ndarray:
        """
        Camera-frame rates of IMU-frame rates.

        Parameters
        ----------
        w_imu : array_like
            (N, 3) IMU-frame rates, rad/s.

        Returns
        -------
        ndarray
            (N, 3) camera-frame rates, the bias removed.

        """
        return (np.asarray(w_imu, dtype=float) - self.bias) @ self.R_cam_imu.T


class StillBiasEstimator:
    """
    Gyro bias from a still start: the mean of the first ``n`` samples if their spread is small.

    The spread is the largest per-axis standard deviation; above ``max_std`` the start is not still
    and no estimate is made (``status`` says why).

    Parameters
    ----------
    n : int, optional
        Number of samples; ``n == 0`` disables the estimate, else at least 2.
    max_std : float, optional
        Largest spread of a still start, rad/s, > 0.

    Raises
    ------
    ValueError
        For other values (:meth:`check_settings`).

    """

    def __init__(self, n: int = 0, max_std: float = 0.02):
        self.check_settings(n, max_std)
        self.n, self.max_std = int(n), float(max_std)
        self._buf: list[np.ndarray] = []
        self.bias: np.ndarray | None = None
        self.done = self.n == 0
        self.status = 'off' if self.n == 0 else f'collecting 0/{self.n} samples'

    @staticmethod
    def check_settings(n, max_std) -> None:
        """
        Check the estimator's settings.

        Parameters
        ----------
        n : int
            Number of samples.
        max_std : float
            Largest spread, rad/s.

        Raises
        ------
        ValueError
            Unless ``n`` is 0 (off) or >= 2 and ``max_std > 0``.

        """
        if n < 0 or (n == 1):
            raise ValueError(f'still-bias sample count must be 0 (off) or >= 2, got {n}')
        if not max_std > 0:
            raise ValueError(f'still-bias max_std must be > 0 rad/s, got {max_std}')

    def update(self, w) -> bool:
        """
        Feed finite IMU-frame rates.

        Parameters
        ----------
        w : array_like
            (3,) or (N, 3) rates, rad/s.

        Returns
        -------
        bool
            True once an estimate exists.

        """
        if self.done:
            return self.bias is not None
        self._buf.append(np.atleast_2d(np.asarray(w, dtype=float)))
        got = sum(len(b) for b in self._buf)
        if got < self.n:
            self.status = f'collecting {got}/{self.n} samples'
            return False
        first = np.concatenate(self._buf)[: self.n]
        self._buf = []
        self.done = True
        spread = float(first.std(axis=0).max())
        if spread > self.max_std:
            self.status = (
                f'start not still: spread {spread:.4f} rad/s > {self.max_std:.4f}; '
                'keeping the configured bias'
            )
            return False
        self.bias = first.mean(axis=0)
        self.status = f'estimated from {self.n} still samples (spread {spread:.4f} rad/s)'
        return True
