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
Gyro-aided prediction of the target box (paper: eqs. 21-25, Algorithm 2), ROS-free.

Direction of the homography (the paper's cumulative form, eqs. 24-25, is ambiguous)
------------------------------------------------------------------------------------
With ``R`` the orientation of camera ``k`` expressed in camera ``k-1`` (the body-rate integral over
the frame interval, :mod:`iemd_ros.gyro.rotation`), a scene direction seen at undistorted pixel
``x`` in frame ``k-1`` is seen in frame ``k`` at ``x' ~ K R^T K^-1 x``.  This is the paper's
``H_gyro^-1`` (eq. 23 gives ``H_gyro = K R K^-1``, eq. 24 applies its inverse).  We apply it per
frame to the box of frame ``k-1``: eq. 24's accumulation ``H^{k+1} = H^k H_gyro^-1`` applied to
``p(k)`` (already the tracked position in frame k) would count earlier rotations twice, so it is
not used.  The direction is checked on the synthetic generator (test) and on the real recordings
(``benchmarks/gyro_prewarp.py``).

Lens distortion
---------------
``K R^T K^-1`` acts on undistorted pixels; a point of the raw image is mapped by undistort -> H ->
distort (:func:`warp_points`).  The tracker takes one 3x3 prior in raw pixels, which with
distortion can only be a local approximation: :func:`local_prior` fits a homography to the
lens-aware mapping of the box's 3x3 grid (corners, edge midpoints, centre) and then corrects its
translation so the box centre is mapped *exactly*; the corner residual is reported.

Coordinates: points, ``H`` and the prior are in pixel-index coordinates (pixel centres at integers,
as ``K``, OpenCV and the tracker's ``update(frame, prior)``).  A box ``(x, y, w, h)`` covers pixels
``x .. x+w-1`` (0-based), i.e. the region ``[x-0.5, x+w-0.5]``, centre ``x + (w-1)/2``
(:func:`iemd_ros.common.boxes.box_centre`), the tracker's convention.

"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
from iemd_ros.common.boxes import centre_box, check_box, map_points
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.gyro.config import GyroConfig
from iemd_ros.gyro.imu import ACCEPTED_STATUS, Coverage, ImuBuffer, ImuIntegration
from iemd_ros.gyro.rotation import GyroCalibration, StillBiasEstimator
import numpy as np

__all__ = ['rotation_homography', 'warp_points', 'box_grid', 'local_prior', 'predict_box',
           'warp_difference', 'GyroPrediction', 'GyroPredictor', 'warm_up']


def rotation_homography(K, R, K_inv=None) -> np.ndarray:
    """
    ``K R^T K^-1``: undistorted pixels of frame k-1 -> frame k.

    Parameters
    ----------
    K : array_like
        3x3 camera matrix.
    R : array_like
        3x3 orientation of camera k in camera k-1.
    K_inv : array_like, optional
        ``K^-1`` when the caller has it (``CameraModel.K_inv``), else it is computed.

    Returns
    -------
    ndarray
        3x3 homography scaled to H[2, 2] = 1.

    Raises
    ------
    ValueError
        When K or R is not 3x3.

    """
    K = np.asarray(K, dtype=float)
    R = np.asarray(R, dtype=float)
    if K.shape != (3, 3) or R.shape != (3, 3):
        raise ValueError(f'K and R must be 3x3, got {K.shape} and {R.shape}')
    H = K @ R.T @ (np.linalg.inv(K) if K_inv is None else K_inv)
    return H / H[2, 2]


def warp_points(points, H, camera: CameraModel | None = None) -> np.ndarray:
    """
    Map raw-image points of frame k-1 to frame k: undistort -> ``H`` -> distort.

    Points and ``H`` are in OpenCV pixel-centre coordinates; without distortion this is just ``H``.

    Parameters
    ----------
    points : array_like
        (..., 2) raw-image points of frame k-1.
    H : array_like
        3x3 homography on undistorted pixels.
    camera : CameraModel, optional
        The lens (None: no distortion).

    Returns
    -------
    ndarray
        (..., 2) raw-image points of frame k (NaN where the lens model cannot be inverted).

    """
    p = np.asarray(points, dtype=float)
    H = np.asarray(H, dtype=float)
    if camera is None or not camera.has_distortion:
        return map_points(H, p)
    return camera.distort_points(map_points(H, camera.undistort_points(p)))


def box_grid(box) -> np.ndarray:
    """
    Return the 3x3 grid of a box's region.

    Parameters
    ----------
    box : array_like
        (x, y, w, h), covering the region ``[x-0.5, x+w-0.5]``.

    Returns
    -------
    ndarray
        (9, 2): the 4 corners (TL, TR, BR, BL), the 4 edge midpoints, the centre (last).

    Raises
    ------
    ValueError
        For a box that is not 4 finite values with a positive size.

    """
    x, y, w, h = check_box(box)
    x, y = x - 0.5, y - 0.5
    xs, ys = [x, x + w / 2, x + w], [y, y + h / 2, y + h]
    return np.array(
        [
            [xs[0], ys[0]],
            [xs[2], ys[0]],
            [xs[2], ys[2]],
            [xs[0], ys[2]],
            [xs[1], ys[0]],
            [xs[2], ys[1]],
            [xs[1], ys[2]],
            [xs[0], ys[1]],
            [xs[1], ys[1]],
        ]
    )


def local_prior(box, H, camera: CameraModel | None = None) -> tuple[np.ndarray, float]:
    """
    Best 3x3 prior (raw pixels of frame k-1 -> frame k) at ``box`` for the undistorted-pixel ``H``.

    Without distortion the exact global ``H`` is returned.  With distortion: least-squares
    homography (``cv2.findHomography``, method 0) through the lens-aware images of
    :func:`box_grid`, then a translation so the box centre maps exactly.

    Parameters
    ----------
    box : array_like
        (x, y, w, h) in frame k-1.
    H : array_like
        3x3 homography on undistorted pixels (:func:`rotation_homography`).
    camera : CameraModel, optional
        The lens (None: no distortion).

    Returns
    -------
    prior : ndarray
        3x3 homography on raw pixels.
    max_residual_px : float
        Largest residual of the prior over the grid.

    Raises
    ------
    ValueError
        When the box maps outside the lens model's valid region or no homography fits.

    """
    return _prior_and_box(box, H, camera)[:2]


def predict_box(box, H, camera: CameraModel | None = None) -> np.ndarray:
    """
    Lens-aware predicted box in frame k of ``box`` (frame k-1).

    The centre is the exact image of the box centre; the width/height are the mean lengths of the
    mapped top/bottom and left/right edges (so a camera roll moves but does not inflate the box).

    Parameters
    ----------
    box : array_like
        (x, y, w, h) in frame k-1.
    H : array_like
        3x3 homography on undistorted pixels (:func:`rotation_homography`).
    camera : CameraModel, optional
        The lens (None: no distortion).

    Returns
    -------
    ndarray
        (x, y, w, h) in frame k.

    Raises
    ------
    ValueError
        When the box maps outside the lens model's valid region.

    """
    return _box_from_grid(_warp_grid(box, box_grid(box), H, camera))


def _prior_and_box(box, H, camera):
    """
    (local prior, its max residual px, predicted box).

    The lens-aware box grid is mapped once for both.
    """
    src = box_grid(box)
    dst = _warp_grid(box, src, H, camera)
    if camera is not None and camera.has_distortion:
        prior, res = _fit_prior(box, src, dst)
    else:
        prior, res = np.asarray(H, dtype=float) / H[2, 2], 0.0
    return prior, res, _box_from_grid(dst)


def _warp_grid(box, src, H, camera) -> np.ndarray:
    dst = warp_points(src, H, camera)
    if not np.all(np.isfinite(dst)):
        raise ValueError(
            f"box {np.asarray(box).tolist()} maps outside the lens model's valid region"
        )
    return dst


def _fit_prior(box, src, dst) -> tuple[np.ndarray, float]:
    G, _ = cv2.findHomography(src, dst, 0)
    if G is None:
        raise ValueError(
            'could not fit a homography to the lens-aware mapping of box '
            f'{np.asarray(box).tolist()}'
        )
    c_fit = map_points(G, src[-1])
    T = np.array([[1.0, 0, dst[-1, 0] - c_fit[0]], [0, 1.0, dst[-1, 1] - c_fit[1]], [0, 0, 1.0]])
    G = T @ G
    G = G / G[2, 2]
    res = float(np.max(np.hypot(*(map_points(G, src) - dst).T)))
    return G, res


def _box_from_grid(g) -> np.ndarray:
    tl, tr, br, bl, c = g[0], g[1], g[2], g[3], g[8]
    w = 0.5 * (np.hypot(*(tr - tl)) + np.hypot(*(br - bl)))
    h = 0.5 * (np.hypot(*(bl - tl)) + np.hypot(*(br - tr)))
    return centre_box(c, (w, h))


def warp_difference(frame_prev, frame_cur, H, valid=None, erode: int = 5) -> float:
    """
    Mean absolute grey-level difference between ``frame_prev`` warped by ``H`` and ``frame_cur``.

    Only pixels defined in both count, eroded by ``erode`` px against interpolation at the borders.

    Parameters
    ----------
    frame_prev, frame_cur : ndarray
        Grey (or BGR, converted) images in the same (undistorted) pixel space.
    H : array_like
        3x3 homography from ``frame_prev`` to ``frame_cur``.
    valid : ndarray, optional
        Boolean mask of defined pixels (e.g. after undistortion), shared by both frames.
    erode : int, optional
        Erosion of the mask, px (0: none).

    Returns
    -------
    float
        The mean difference, grey levels.

    Raises
    ------
    ValueError
        When the frames differ in size or the warped frame does not overlap the current one.

    """
    a, b = (
        cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) if f.ndim == 3 else f
        for f in map(np.asarray, (frame_prev, frame_cur))
    )
    if a.shape != b.shape:
        raise ValueError(f'frames differ in size: {a.shape} vs {b.shape}')
    h, w = a.shape
    v = np.ones((h, w), bool) if valid is None else np.asarray(valid, bool)
    warped = cv2.warpPerspective(
        a.astype(np.float32), np.asarray(H, float), (w, h), flags=cv2.INTER_LINEAR
    )
    vw = (
        cv2.warpPerspective(
            v.astype(np.uint8) * 255, np.asarray(H, float), (w, h), flags=cv2.INTER_NEAREST
        )
        == 255
    )
    m = (vw & v).astype(np.uint8)
    if erode > 0:
        m = cv2.erode(m, np.ones((erode, erode), np.uint8))
    if not m.any():
        raise ValueError('the warped frame does not overlap the current one')
    return float(np.abs(warped - b.astype(np.float32))[m.astype(bool)].mean())


@dataclass(frozen=True)
class GyroPrediction:
    """
    Prediction for frame k from frame k-1.

    Parameters
    ----------
    integration : ImuIntegration
        The gyro integration over the frame interval.
    R : ndarray or None
        Camera k in camera k-1; None when the gyro gives no rotation.
    H : ndarray or None
        ``K R^T K^-1`` (undistorted pixels); None when the gyro gives no rotation.
    prior : ndarray or None
        The 3x3 for ``tracker.update(frame, prior=...)`` (raw pixels; fitted locally at ``box``
        when the lens distorts); None when the gyro gives no rotation or the box lies outside the
        lens model (without a box: the global ``H``, :meth:`GyroPredictor.predict`).
    box : ndarray or None
        The lens-aware predicted box; None also when no box was given.
    reason : str
        Why there is no prior, else the integration's reason.
    prior_residual_px : float, optional
        Largest residual of the locally fitted prior over the box grid.

    """

    integration: ImuIntegration
    R: np.ndarray | None
    H: np.ndarray | None
    prior: np.ndarray | None
    box: np.ndarray | None
    reason: str
    prior_residual_px: float = 0.0

    @property
    def ok(self) -> bool:
        """Whether the gyro gave a rotation."""
        return self.R is not None

    @property
    def status(self) -> Coverage:
        """Return the integration's coverage status."""
        return self.integration.status


class GyroPredictor:
    """
    Owns the :class:`~iemd_ros.gyro.imu.ImuBuffer`, the camera model and the gyro configuration.

    Feed raw IMU-frame rates with :meth:`add_imu`; for consecutive frames call :meth:`predict` with
    their camera stamps (and the previous box).  If the gyro does not cover the new frame yet, the
    result has ``status == not_covered`` and no prior: wait a bounded time (:meth:`ready`) and call
    again, or go on without the prior and log ``reason``.

    Parameters
    ----------
    camera : CameraModel or None
        May be None until the calibration is known (set it then): samples are buffered,
        :meth:`predict` needs it.
    config : GyroConfig, optional
        Checked by :class:`GyroConfig` when it is built; the parts built from it here (calibration,
        IMU buffer, bias estimator) check their own values again, so a field changed afterwards is
        still caught.

    Raises
    ------
    ValueError
        For a ``camera`` that is not a CameraModel or None, or invalid ``config`` values.

    """

    def __init__(self, camera: CameraModel | None, config: GyroConfig | None = None):
        if camera is not None and not isinstance(camera, CameraModel):
            raise ValueError(f'camera must be a CameraModel or None, got {type(camera).__name__}')
        self.camera = camera
        self.config = cfg = config if config is not None else GyroConfig()
        self._cal = GyroCalibration(cfg.rotation, cfg.bias)
        self.buffer = ImuBuffer(cfg.buffer_ns, cfg.buffer_samples, cfg.saturation, cfg.max_gap_ns)
        self.bias_estimator = StillBiasEstimator(cfg.still_bias_samples, cfg.still_bias_max_std)

    @property
    def calibration(self) -> GyroCalibration:
        """Return current extrinsic + bias (the still-start estimate once available)."""
        return self._cal

    def add_imu(self, t_ns, w) -> np.ndarray:
        """
        Add raw gyro samples; the accepted ones also feed the still-start bias estimate.

        Parameters
        ----------
        t_ns : int or array_like
            Stamp(s) in ns on the IMU clock.
        w : array_like
            (3,) or (N, 3) rates, IMU frame, rad/s.

        Returns
        -------
        ndarray
            The samples' :class:`~iemd_ros.gyro.imu.SampleStatus`.

        Raises
        ------
        ValueError
            For bad shapes or stamps (:meth:`~iemd_ros.gyro.imu.ImuBuffer.add`).

        """
        status = self.buffer.add(t_ns, w)
        if not self.bias_estimator.done:
            good = status == ACCEPTED_STATUS
            if good.any() and self.bias_estimator.update(
                np.atleast_2d(np.asarray(w, dtype=float))[good]
            ):
                self._cal = GyroCalibration(self._cal.R_cam_imu, self.bias_estimator.bias)
        return status

    def imu_time(self, t_cam_ns: int) -> int:
        """
        IMU-clock time of a camera stamp (``t_cam + time_offset_ns``).

        Parameters
        ----------
        t_cam_ns : int
            Camera stamp, ns.

        Returns
        -------
        int
            IMU-clock time, ns.

        """
        return int(t_cam_ns) + int(self.config.time_offset_ns)

    def ready(self, t_cam_ns: int) -> bool:
        """
        Return True once the gyro covers the frame stamped ``t_cam_ns``.

        Parameters
        ----------
        t_cam_ns : int
            Camera stamp, ns.

        Returns
        -------
        bool
            Whether the frame can be integrated.

        """
        return self.buffer.covers(self.imu_time(t_cam_ns))

    def rotation(self, t_prev_ns: int, t_cur_ns: int) -> ImuIntegration:
        """
        Rotation of camera k (``t_cur_ns``) in camera k-1 (``t_prev_ns``), camera frame.

        Parameters
        ----------
        t_prev_ns, t_cur_ns : int
            Camera stamps of frames k-1 and k, ns.

        Returns
        -------
        ImuIntegration
            The rotation with its coverage status.

        """
        return self.buffer.integrate(
            self.imu_time(t_prev_ns), self.imu_time(t_cur_ns), self._cal, coning=self.config.coning
        )

    def predict(self, t_prev_ns: int, t_cur_ns: int, box=None) -> GyroPrediction:
        """
        Gyro prediction for the frame at ``t_cur_ns`` from the one at ``t_prev_ns``.

        With ``box`` (frame k-1) the prior is fitted locally at the box and the predicted box is
        returned; without it the prior is the global ``H`` (exact only without lens distortion).

        Parameters
        ----------
        t_prev_ns, t_cur_ns : int
            Camera stamps of frames k-1 and k, ns.
        box : array_like, optional
            (x, y, w, h) in frame k-1.

        Returns
        -------
        GyroPrediction
            Without a prior when the gyro gives no usable rotation (``reason`` says why) or the box
            lies outside the lens model.

        Raises
        ------
        ValueError
            Without a camera model.

        """
        return self.at_box(self.homography(t_prev_ns, t_cur_ns), box)

    def homography(self, t_prev_ns: int, t_cur_ns: int) -> GyroPrediction:
        """
        Return the box-free part of :meth:`predict`.

        The rotation and ``K R^T K^-1`` between two frames.

        Integrated once per frame pair, it serves every target of the frame (:meth:`at_box`).

        Parameters
        ----------
        t_prev_ns, t_cur_ns : int
            Camera stamps of frames k-1 and k, ns.

        Returns
        -------
        GyroPrediction
            With the global ``H`` as prior and no box; without a prior when the gyro gives no
            usable rotation.

        Raises
        ------
        ValueError
            Without a camera model.

        """
        if self.camera is None:
            raise ValueError('no camera model: the gyro prior needs K')
        integ = self.rotation(t_prev_ns, t_cur_ns)
        usable = integ.ok or (integ.status is Coverage.GAP and self.config.allow_gaps)
        if not usable:
            return GyroPrediction(integ, None, None, None, None, f'no gyro prior: {integ.reason}')
        H = rotation_homography(self.camera.K, integ.R, self.camera.K_inv)
        return GyroPrediction(integ, integ.R, H, H, None, integ.reason)

    def at_box(self, global_prediction: GyroPrediction, box=None) -> GyroPrediction:
        """
        :meth:`homography`'s prediction fitted at ``box`` (frame k-1).

        The local prior and the predicted box.

        Parameters
        ----------
        global_prediction : GyroPrediction
            What :meth:`homography` gave for the frame pair.
        box : array_like, optional
            (x, y, w, h) in frame k-1 (None: ``global_prediction`` as it is).

        Returns
        -------
        GyroPrediction
            Without a prior when there is no rotation or the box lies outside the lens model.

        """
        g = global_prediction
        if box is None or g.H is None:
            return g
        try:
            prior, res, pbox = _prior_and_box(box, g.H, self.camera)
        except ValueError as exc:  # box far outside the lens model's valid region
            return GyroPrediction(
                g.integration, g.R, g.H, None, None, f'no gyro prior at this box: {exc}'
            )
        return GyroPrediction(g.integration, g.R, g.H, prior, pbox, g.reason, res)


def warm_up() -> None:
    """
    Compile the gyro path's numba kernels now (or load them from numba's on-disk cache).

    The IMU screening, the window integration and the lens model, so that the first IMU message and
    prediction do not stall.
    """
    predictor = GyroPredictor(
        CameraModel(np.diag([100.0, 100.0, 1.0]), [0.1, 0.0, 0.0, 0.0, 0.0], 64, 48)
    )
    predictor.add_imu(np.array([0, 10_000_000, 20_000_000]), np.full((3, 3), 0.1))
    predictor.predict(2_000_000, 12_000_000, (16.0, 16.0, 16.0, 16.0))
