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
Pinhole camera with plumb_bob lens distortion (ROS ``sensor_msgs/CameraInfo`` conventions).

Pixel coordinates here are OpenCV's: pixel centres at integer coordinates, as in ``K``.
(Tracker boxes use 0-based pixel *corners*; :mod:`iemd_ros.gyro.predictor` converts by 0.5 px.)

The plumb_bob model ``D = [k1, k2, p1, p2, k3]`` maps a normalized undistorted point (x, y) to
``x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)`` and
``y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y``; a skew entry of K is
honoured (OpenCV's point functions ignore it).  "Undistorted" pixels use the same K (P = K).
"""
from __future__ import annotations

import math
from pathlib import Path

import cv2
from iemd_ros.common.limits import FOCAL_LENGTH, PRINCIPAL_POINT
import numba
import numpy as np

__all__ = ['CameraModel']


def _field(info: dict, *names):
    for n in names:
        if n in info and info[n] is not None:
            v = info[n]
            return v['data'] if isinstance(v, dict) and 'data' in v else v
    return None


class CameraModel:
    """
    Pinhole camera: intrinsics ``K`` (3x3), plumb_bob distortion ``D`` and image size.

    Parameters
    ----------
    K : array_like
        3x3 camera matrix, or its 9 values row-major: upper-triangular with fx, fy > 0 and last row
        [0, 0, 1].
    D : array_like, optional
        The plumb_bob coefficients [k1, k2, p1, p2, k3]: at most 5 finite values, the missing ones
        0 (None: no distortion).
    width, height : int, optional
        Image size in pixels, both or neither: K is then checked against it (:meth:`check_image`).
    name : str, optional
        The camera's name (camera_info's ``camera_name``).

    Raises
    ------
    ValueError
        For a ``K`` or ``D`` that is not so, an image size that is not two positive integers, or a
        focal length or principal point out of its limit for that size
        (:data:`~iemd_ros.common.limits.FOCAL_LENGTH`,
        :data:`~iemd_ros.common.limits.PRINCIPAL_POINT`).

    """

    def __init__(
        self, K, D=None, width: int | None = None, height: int | None = None, name: str = ''
    ):
        K = np.asarray(K, dtype=float)
        if K.shape == (9,):
            K = K.reshape(3, 3)
        if (
            K.shape != (3, 3)
            or not np.all(np.isfinite(K))
            or K[0, 0] <= 0
            or K[1, 1] <= 0
            or not np.allclose(K[2], [0, 0, 1])
            or K[1, 0] != 0
        ):
            raise ValueError(
                f'K must be an upper-triangular 3x3 camera matrix with fx, fy > 0 and '
                f'last row [0, 0, 1], got {K.tolist()}'
            )
        D = np.zeros(5) if D is None else np.asarray(D, dtype=float).ravel()
        if len(D) > 5 or not np.all(np.isfinite(D)):
            raise ValueError(
                f'plumb_bob distortion needs at most 5 finite coefficients [k1 k2 p1 p2 k3], '
                f'got {D.tolist()}'
            )
        self.K = K
        self.K_inv = np.linalg.inv(K)
        self.D = np.concatenate([D, np.zeros(5 - len(D))])
        self._has_distortion = bool(np.any(self.D != 0))
        if (width is None) != (height is None) or (
            width is not None and (int(width) <= 0 or int(height) <= 0)
        ):
            raise ValueError(f'image size must be two positive integers, got {width}x{height}')
        self.width = None if width is None else int(width)
        self.height = None if height is None else int(height)
        self.name = name
        if self.width is not None:
            self._check_intrinsics(self.width, self.height)

    def check_image(self, width: int, height: int) -> None:
        """
        Check that the camera describes images of ``width`` x ``height`` px.

        Its own image size, when it has one, must be that; without one, K is checked against that
        size.

        Parameters
        ----------
        width, height : int
            The image's size, px.

        Raises
        ------
        ValueError
            Saying what does not fit.

        """
        if self.width is None:
            self._check_intrinsics(int(width), int(height))
        elif (self.width, self.height) != (int(width), int(height)):
            raise ValueError(
                f'camera_info is for {self.width}x{self.height} images, this image is '
                f'{width}x{height}'
            )

    def _check_intrinsics(self, width: int, height: int) -> None:
        """Raise ValueError naming the entry of K out of its limit for ``width`` x ``height``."""
        K = self.K
        side = max(width, height)
        FOCAL_LENGTH.check('camera_info k[0] (fx)', K[0, 0], side)
        FOCAL_LENGTH.check('camera_info k[4] (fy)', K[1, 1], side)
        PRINCIPAL_POINT.check('camera_info k[2] (cx)', K[0, 2], width)
        PRINCIPAL_POINT.check('camera_info k[5] (cy)', K[1, 2], height)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_camera_info(cls, info: dict) -> CameraModel:
        """
        Camera model of a camera_info dict.

        Parameters
        ----------
        info : dict
            A ROS camera_info YAML dict (``camera_matrix.data`` ...) or a CameraInfo-like dict
            (``k``, ``d``, ``width``, ``height``, ``distortion_model``).

        Returns
        -------
        CameraModel
            The model of ``info``.

        Raises
        ------
        ValueError
            For a non-mapping, no camera matrix, a distortion model other than plumb_bob (or none)
            with non-zero coefficients, or invalid values.

        """
        if not isinstance(info, dict):
            raise ValueError(f'camera info must be a mapping, got {type(info).__name__}')
        K = _field(info, 'camera_matrix', 'k', 'K')
        if K is None:
            raise ValueError('camera info has no camera_matrix / k entry')
        D = _field(info, 'distortion_coefficients', 'd', 'D')
        model = info.get('distortion_model', 'plumb_bob') or 'plumb_bob'
        if model not in ('plumb_bob', 'none') and D is not None and np.any(np.asarray(D, float)):
            raise ValueError(
                f'unsupported distortion_model {model!r}: only plumb_bob is implemented'
            )
        w = _field(info, 'image_width', 'width')
        h = _field(info, 'image_height', 'height')
        return cls(
            K, D if D is not None and len(D) else None, w, h, str(info.get('camera_name', ''))
        )

    @classmethod
    def from_yaml(cls, path) -> CameraModel:
        """
        Load a ROS camera_info-style YAML file.

        Parameters
        ----------
        path : str or path-like
            The YAML file.

        Returns
        -------
        CameraModel
            The model of the file (:meth:`from_camera_info`).

        Raises
        ------
        ValueError
            For a file that cannot be read or parsed, or invalid contents.

        """
        import yaml

        path = Path(path)
        try:
            info = yaml.safe_load(path.read_text())
        except (OSError, yaml.YAMLError) as exc:
            raise ValueError(f'cannot read camera YAML {path}: {exc}') from exc
        return cls.from_camera_info(info)

    def to_camera_info(self) -> dict:
        """
        ROS camera_info-style dict, which round-trips through :meth:`from_camera_info`.

        Returns
        -------
        dict
            Image size, camera name, camera matrix, plumb_bob coefficients, rectification
            (identity) and projection (``[K | 0]``) matrices.

        """
        P = np.hstack([self.K, np.zeros((3, 1))])
        return {
            'image_width': self.width,
            'image_height': self.height,
            'camera_name': self.name,
            'camera_matrix': {'rows': 3, 'cols': 3, 'data': self.K.ravel().tolist()},
            'distortion_model': 'plumb_bob',
            'distortion_coefficients': {'rows': 1, 'cols': 5, 'data': self.D.tolist()},
            'rectification_matrix': {'rows': 3, 'cols': 3, 'data': np.eye(3).ravel().tolist()},
            'projection_matrix': {'rows': 3, 'cols': 4, 'data': P.ravel().tolist()},
        }

    @property
    def has_distortion(self) -> bool:
        """Whether any distortion coefficient is non-zero."""
        return self._has_distortion

    # ------------------------------------------------------------------ points
    @staticmethod
    def _points(pts) -> np.ndarray:
        p = np.asarray(pts, dtype=float)
        if p.shape[-1] != 2:
            raise ValueError(f'points must have shape (..., 2), got {p.shape}')
        return p

    def _to_norm(self, p):
        x = (
            p[..., 0] - self.K[0, 2] - self.K[0, 1] * (p[..., 1] - self.K[1, 2]) / self.K[1, 1]
        ) / self.K[0, 0]
        y = (p[..., 1] - self.K[1, 2]) / self.K[1, 1]
        return x, y

    def _to_pix(self, x, y):
        return np.stack(
            [self.K[0, 0] * x + self.K[0, 1] * y + self.K[0, 2], self.K[1, 1] * y + self.K[1, 2]],
            -1,
        )

    def _distort_norm(self, x, y):
        shape = np.shape(x)
        xd, yd = _distort_arrays(np.ravel(x), np.ravel(y), self.D)
        return xd.reshape(shape), yd.reshape(shape)

    def distort_points(self, pts) -> np.ndarray:
        """
        Undistorted pixel coordinates -> distorted (raw image) pixel coordinates.

        Parameters
        ----------
        pts : array_like
            (..., 2) undistorted pixels.

        Returns
        -------
        ndarray
            (..., 2) raw-image pixels (a copy of ``pts`` without distortion).

        Raises
        ------
        ValueError
            When the points' last axis is not 2.

        """
        p = self._points(pts)
        if not self.has_distortion:
            return p.copy()
        return self._to_pix(*self._distort_norm(*self._to_norm(p)))

    def undistort_points(self, pts, iterations: int = 30, tol: float = 1e-12) -> np.ndarray:
        """
        Distorted (raw image) pixels -> undistorted pixels.

        By Newton's method on the plumb_bob model.

        Parameters
        ----------
        pts : array_like
            (..., 2) raw-image pixels.
        iterations : int, optional
            Most Newton steps per point.
        tol : float, optional
            Step length (normalized coordinates) below which a point has converged.

        Returns
        -------
        ndarray
            (..., 2) undistorted pixels: converged to < 1e-6 px where the model is invertible, NaN
            where it fails.

        Raises
        ------
        ValueError
            When the points' last axis is not 2.

        """
        p = self._points(pts)
        if not self.has_distortion:
            return p.copy()
        xd, yd = self._to_norm(p)
        shape = np.shape(xd)
        x, y = _undistort_newton(np.ravel(xd), np.ravel(yd), self.D, iterations, tol)
        return self._to_pix(x.reshape(shape), y.reshape(shape))

    # ------------------------------------------------------------------ images
    def undistort_maps(self) -> tuple[np.ndarray, np.ndarray]:
        """
        ``cv2.remap`` maps giving, for each undistorted pixel, its raw-image position.

        Returns
        -------
        map_x : ndarray
            (height, width) float32 raw-image x of each pixel.
        map_y : ndarray
            (height, width) float32 raw-image y of each pixel.

        Raises
        ------
        ValueError
            When the camera has no image size.

        """
        if self.width is None:
            raise ValueError('undistort_maps needs the image size (width/height) of the camera')
        u, v = np.meshgrid(np.arange(self.width, dtype=float), np.arange(self.height, dtype=float))
        m = self.distort_points(np.stack([u, v], -1)).astype(np.float32)
        return m[..., 0], m[..., 1]

    def undistort_image(self, image: np.ndarray, maps=None) -> np.ndarray:
        """
        Undistorted image with the same K (pixels mapping outside the raw image are black).

        Parameters
        ----------
        image : ndarray
            Raw image.
        maps : tuple of ndarray, optional
            :meth:`undistort_maps`, if already computed.

        Returns
        -------
        ndarray
            The undistorted image.

        """
        mx, my = self.undistort_maps() if maps is None else maps
        return cv2.remap(
            image, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0
        )

    def __repr__(self) -> str:
        return (
            f'CameraModel(fx={self.K[0, 0]:.2f}, fy={self.K[1, 1]:.2f}, cx={self.K[0, 2]:.2f}, '
            f'cy={self.K[1, 2]:.2f}, D={np.round(self.D, 6).tolist()}, '
            f'size={self.width}x{self.height})'
        )


@numba.njit(cache=True)
def _distort(x, y, k1, k2, p1, p2, k3):
    """Return the plumb_bob model on one normalized point: (x, y) -> (x_d, y_d)."""
    r2 = x * x + y * y
    rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    return (
        x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
        y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y,
    )


@numba.njit(cache=True)
def _distort_arrays(x, y, D):
    """:func:`_distort` over 1-D arrays of normalized points."""
    k1, k2, p1, p2, k3 = D[0], D[1], D[2], D[3], D[4]
    xd = np.empty_like(x)
    yd = np.empty_like(y)
    for i in range(x.size):
        xd[i], yd[i] = _distort(x[i], y[i], k1, k2, p1, p2, k3)
    return xd, yd


@numba.njit(cache=True)
def _undistort_newton(xd, yd, D, iterations, tol):
    """
    Newton's method on the plumb_bob model, point by point (normalized coordinates).

    A per-point loop: for the 9 points of a box grid numpy's per-call overhead dominates.  A point
    whose final residual (the distorted result against (xd, yd)) is not below 1e-9 is NaN.
    """
    k1, k2, p1, p2, k3 = D[0], D[1], D[2], D[3], D[4]
    x = xd.copy()
    y = yd.copy()
    for i in range(x.size):
        for _ in range(iterations):
            xi, yi = x[i], y[i]
            r2 = xi * xi + yi * yi
            rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
            fx, fy = _distort(xi, yi, k1, k2, p1, p2, k3)
            ex = fx - xd[i]
            ey = fy - yd[i]
            drad = k1 + r2 * (2 * k2 + 3 * k3 * r2)
            a = rad + 2 * xi * xi * drad + 2 * p1 * yi + 6 * p2 * xi
            b = 2 * xi * yi * drad + 2 * p1 * xi + 2 * p2 * yi
            d = rad + 2 * yi * yi * drad + 6 * p1 * yi + 2 * p2 * xi
            det = a * d - b * b
            dx = (d * ex - b * ey) / det
            dy = (a * ey - b * ex) / det
            x[i], y[i] = xi - dx, yi - dy
            if not abs(dx) + abs(dy) >= tol:  # converged (or NaN: the check below rejects it)
                break
        fx, fy = _distort(x[i], y[i], k1, k2, p1, p2, k3)
        if not math.hypot(fx - xd[i], fy - yd[i]) < 1e-9:
            x[i] = np.nan
            y[i] = np.nan
    return x, y
