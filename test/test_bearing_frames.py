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

"""The bearing of a box through a distorted lens, and the static frames' composition (ROS-free)."""
from iemd_ros.common.boxes import box_centre
from iemd_ros.gyro.bearing import bearing, pixel_rays, ray_quaternion
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.gyro.frames import StaticFrames
from iemd_ros.gyro.rotation import quat_to_rot, so3_exp
import numpy as np
import pytest

CAMERA = CameraModel([[520.0, 0.0, 331.0], [0.0, 515.0, 238.0], [0.0, 0.0, 1.0]],
                     [-0.28, 0.09, 0.0012, -0.0007, -0.012], 640, 480)


def _project(camera, rays):
    """Rays -> raw-image pixels: the lens model forwards (K, then distortion)."""
    rays = np.asarray(rays, float)
    und = (rays / rays[..., 2:]) @ camera.K.T
    return camera.distort_points(und[..., :2])


@pytest.mark.parametrize(
    'box', [(300.0, 220.0, 40.0, 30.0), (10.0, 12.0, 60.0, 44.0), (580.0, 420.0, 50.0, 50.0)]
)
def test_bearing_agrees_with_the_lens_model(box):
    b = bearing(CAMERA, box)
    assert abs(np.linalg.norm(b.ray) - 1.0) < 1e-12 and b.ray[2] > 0
    # back onto the centre
    np.testing.assert_allclose(_project(CAMERA, b.ray), box_centre(box), atol=1e-6)
    x, y, w, h = box
    cy = box_centre(box)[1]
    edges = pixel_rays(CAMERA, np.array([[x - 0.5, cy], [x + w - 0.5, cy]]))
    np.testing.assert_allclose(
        _project(CAMERA, edges), [[x - 0.5, cy], [x + w - 0.5, cy]], atol=1e-6
    )
    assert b.angular_width == pytest.approx(
        np.arccos(np.clip(edges[0] @ edges[1], -1, 1)), abs=1e-9
    )
    # the lens matters: the pinhole ray of the same pixel differs by far more than the tolerance at
    # the corners
    pinhole = CameraModel(CAMERA.K, None, 640, 480)
    if box[0] < 100:
        assert np.linalg.norm(bearing(pinhole, box).ray - b.ray) > 1e-3


def test_centred_box_looks_along_the_optical_axis_and_its_angular_size():
    cam = CameraModel([[500.0, 0, 319.5], [0, 500.0, 239.5], [0, 0, 1]], None, 640, 480)
    b = bearing(cam, (300.0, 220.0, 40.0, 40.0))
    np.testing.assert_allclose(b.ray, [0.0, 0.0, 1.0], atol=1e-12)
    assert b.angular_width == pytest.approx(2 * np.arctan(20.0 / 500.0), rel=1e-12)
    assert b.angular_height == pytest.approx(b.angular_width, rel=1e-12)


def test_ray_quaternion_turns_the_optical_axis_onto_the_ray():
    for ray in ([0.3, -0.2, 0.9], [0.0, 0.0, 1.0], [-0.7, 0.1, 0.2]):
        r = np.asarray(ray) / np.linalg.norm(ray)
        x, y, z, w = ray_quaternion(r)
        np.testing.assert_allclose(quat_to_rot(np.array([w, x, y, z])) @ [0, 0, 1], r, atol=1e-12)


def test_bearing_outside_the_lens_model_is_an_error():
    # not invertible at the corner
    strong = CameraModel(CAMERA.K, [0.0, -3.0, 0.0, 0.0, 0.0], 640, 480)
    with pytest.raises(ValueError, match='lens model'):
        bearing(strong, (0.0, 0.0, 4.0, 4.0))


def _q(R):
    """(x, y, z, w) of a rotation matrix."""
    from iemd_ros.gyro.rotation import rot_to_quat

    w, x, y, z = rot_to_quat(R)
    return x, y, z, w


def test_static_frames_compose_the_chain_between_two_frames():
    R_base_imu = so3_exp([0.1, -0.4, 0.3])
    R_base_mount = so3_exp([0.0, 0.2, -1.0])
    R_mount_cam = so3_exp([-1.2, 0.3, 0.5])
    f = StaticFrames()
    f.add('base_link', 'imu_link', _q(R_base_imu))
    # a leading "/" is the same frame (tf2)
    f.add('/base_link', 'camera_mount', _q(R_base_mount))
    f.add('camera_mount', 'camera_optical', _q(R_mount_cam))
    R = f.rotation('camera_optical', 'imu_link')  # w_cam = R w_imu
    np.testing.assert_allclose(R, (R_base_mount @ R_mount_cam).T @ R_base_imu, atol=1e-12)
    np.testing.assert_allclose(f.rotation('imu_link', 'camera_optical'), R.T, atol=1e-12)
    np.testing.assert_allclose(f.rotation('imu_link', 'imu_link'), np.eye(3))
    assert f.rotation('camera_optical', 'odom') is None  # another tree
    assert not f.add('base_link', 'imu_link', _q(R_base_imu))  # nothing new
    assert f.add('base_link', 'imu_link', _q(np.eye(3)))  # replaced, as tf2 does
    np.testing.assert_allclose(
        f.rotation('camera_optical', 'imu_link'), (R_base_mount @ R_mount_cam).T, atol=1e-12
    )


def test_static_frames_refuse_bad_transforms_and_cycles():
    f = StaticFrames()
    with pytest.raises(ValueError, match='two different'):
        f.add('a', 'a', (0, 0, 0, 1))
    with pytest.raises(ValueError, match='two different'):
        f.add('', 'b', (0, 0, 0, 1))
    with pytest.raises(ValueError):
        f.add('a', 'b', (0, 0, 0, 0))
    with pytest.raises(ValueError):
        f.add('a', 'b', (np.nan, 0, 0, 1))
    f.add('a', 'b', (0, 0, 0, 1))
    f.add('b', 'a', (0, 0, 0, 1))
    with pytest.raises(ValueError, match='cycle'):
        f.rotation('a', 'c')
