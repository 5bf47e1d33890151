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
The bearing of a tracked box.

The unit ray to its centre in the camera's optical frame, and its angular size.

REP 103's optical frame: z forward along the optical axis, x right, y down.  The box centre
(pixel-index coordinates, :func:`iemd_ros.common.boxes.box_centre`) is undistorted with the lens
model and lifted through ``K^-1``; the ray is that direction normalized.  The angular width is the
angle between the rays through the midpoints of the box's left and right edges (the region
``[x-0.5, x+w-0.5]``), the angular height the same between top and bottom.  A gimbal or
visual-servoing controller steers by ``pan = atan2(x, z)``, ``tilt = atan2(y, z)`` without the
camera model.
"""
from __future__ import annotations

from typing import NamedTuple

from iemd_ros.common.boxes import box_centre, check_box
from iemd_ros.gyro.camera import CameraModel
import numpy as np

__all__ = ['Bearing', 'bearing', 'pixel_rays', 'ray_quaternion']


class Bearing(NamedTuple):
    """
    The bearing of one box.

    Attributes
    ----------
    ray : ndarray
        (3,) unit vector to the box centre, optical frame.
    angular_width, angular_height : float
        Angles subtended by the box between its edge midpoints, rad.

    """

    ray: np.ndarray
    angular_width: float
    angular_height: float


def pixel_rays(camera: CameraModel, points) -> np.ndarray:
    """
    Return unit rays of raw-image pixels.

    Parameters
    ----------
    camera : CameraModel
        The lens (K, plumb_bob D).
    points : array_like
        (..., 2) raw-image pixels, pixel-index coordinates.

    Returns
    -------
    ndarray
        (..., 3) unit rays, optical frame (NaN where the lens model cannot be inverted).

    """
    und = camera.undistort_points(points)
    homog = np.concatenate([und, np.ones(und.shape[:-1] + (1,))], axis=-1)
    rays = homog @ camera.K_inv.T
    return rays / np.linalg.norm(rays, axis=-1, keepdims=True)


def bearing(camera: CameraModel, box) -> Bearing:
    """
    Return the bearing of ``box`` seen through ``camera``.

    Parameters
    ----------
    camera : CameraModel
        The lens.
    box : sequence of 4 float
        (x, y, w, h), 0-based top-left + size, px.

    Returns
    -------
    Bearing
        The ray to the centre and the angular size.

    Raises
    ------
    ValueError
        For an invalid box, or one whose centre or edges lie outside the lens model's valid region.

    """
    x, y, w, h = check_box(box)
    cx, cy = box_centre((x, y, w, h))
    left, right, top, bottom = x - 0.5, x + w - 0.5, y - 0.5, y + h - 0.5
    rays = pixel_rays(
        camera, np.array([[cx, cy], [left, cy], [right, cy], [cx, top], [cx, bottom]])
    )
    if not np.all(np.isfinite(rays)):
        raise ValueError(f"box {[x, y, w, h]} lies outside the lens model's valid region")

    def angle(a, b) -> float:
        return float(np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))

    return Bearing(rays[0], angle(rays[1], rays[2]), angle(rays[3], rays[4]))


def ray_quaternion(ray) -> np.ndarray:
    """
    Return the shortest rotation taking the optical axis (0, 0, 1) onto ``ray``.

    As ROS orders a quaternion.

    Parameters
    ----------
    ray : array_like
        (3,) unit vector with a positive z.

    Returns
    -------
    ndarray
        (x, y, z, w).

    """
    r = np.asarray(ray, dtype=float)
    half = np.array([r[0], r[1], r[2] + 1.0])  # the bisector of z and the ray (z > 0: never zero)
    half /= np.linalg.norm(half)
    axis = np.cross([0.0, 0.0, 1.0], half)  # sin(angle/2) * unit axis
    return np.array([axis[0], axis[1], axis[2], half[2]])
