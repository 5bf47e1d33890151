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

"""Camera model: plumb_bob distortion round trip, CameraInfo parsing, image undistortion."""
import cv2
from helpers import DESK_D, DESK_INFO, DESK_K, DESK_K_DATA
from iemd_ros.gyro.camera import CameraModel
import numpy as np
import pytest


def grid(w, h, step=4):
    u, v = np.meshgrid(np.arange(0, w, step, dtype=float), np.arange(0, h, step, dtype=float))
    return np.stack([u.ravel(), v.ravel()], 1)


@pytest.mark.parametrize('D', [DESK_D, [-0.2, 0.05, 0.001, -0.002, 0.01]])
def test_distortion_round_trip_inside_the_image(D):
    cam = CameraModel.from_camera_info({**DESK_INFO, 'distortion_coefficients': {'data': D}})
    raw = grid(640, 480)
    und = cam.undistort_points(raw)
    assert np.all(np.isfinite(und))
    back = cam.distort_points(und)
    assert np.abs(back - raw).max() < 0.01
    assert np.abs(back - raw).max() < 1e-6          # Newton actually converges
    # barrel distortion: the raw corners come from further out in the pinhole image
    assert np.hypot(*(und[0] - cam.K[:2, 2])) > np.hypot(*(raw[0] - cam.K[:2, 2])) + 20


def test_undistort_points_agrees_with_opencv_when_there_is_no_skew():
    K = np.array([[570.0, 0, 309.4], [0, 569.3, 218.0], [0, 0, 1]])
    D = np.array([-0.346217, 0.128289, 0.0005, -0.0003, 0.0])
    cam = CameraModel(K, D, 640, 480)
    raw = grid(640, 480, 37)
    ours = cam.undistort_points(raw)
    ocv = cv2.undistortPoints(
        raw[:, None, :],
        K,
        D,
        P=K,
        criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-12),
    )[:, 0]
    assert np.abs(ours - ocv).max() < 0.01
    # OpenCV's default (5 fixed-point iterations) is not accurate enough at the corners
    ocv5 = cv2.undistortPoints(raw[:, None, :], K, D, P=K)[:, 0]
    assert np.abs(cam.distort_points(ocv5) - raw).max() > 0.01


def test_undistort_points_is_nan_where_the_lens_is_not_invertible():
    # r_d = r (1 - 0.6 r^2) peaks at r_d ~ 0.497 (283 px): beyond it no undistorted point maps
    # there
    cam = CameraModel(DESK_K, [-0.6, 0, 0, 0, 0], 640, 480)
    c = cam.K[:2, 2]
    raw = np.array(
        [c + [100.0, 0.0], c + [400.0, 0.0], c + [0.0, -150.0], c + [300.0, 300.0], [np.nan, 5.0]]
    )
    und = cam.undistort_points(raw)
    assert np.isnan(und[[1, 3, 4]]).all()
    assert np.isfinite(und[[0, 2]]).all()
    assert np.abs(cam.distort_points(und[[0, 2]]) - raw[[0, 2]]).max() < 1e-6
    assert cam.undistort_points(raw.reshape(5, 1, 2)).shape == (5, 1, 2)


def test_skew_is_honoured():
    cam = CameraModel.from_camera_info(DESK_INFO)
    p = cam.distort_points(np.array([[100.0, 400.0]]))
    x = np.linalg.solve(cam.K, [100.0, 400.0, 1.0])
    r2 = x[0] ** 2 + x[1] ** 2
    xd = x[:2] * (1 + cam.D[0] * r2 + cam.D[1] * r2**2)
    np.testing.assert_allclose(p[0], (cam.K @ np.r_[xd, 1.0])[:2], atol=1e-9)


def test_camera_info_variants_and_errors(tmp_path):
    msg = {
        'width': 640,
        'height': 480,
        'k': DESK_K_DATA,
        'd': [-0.3, 0.1, 0, 0, 0],
        'distortion_model': 'plumb_bob',
    }
    cam = CameraModel.from_camera_info(msg)
    assert (cam.width, cam.height) == (640, 480) and cam.D[0] == -0.3
    again = CameraModel.from_camera_info(cam.to_camera_info())
    np.testing.assert_array_equal(again.K, cam.K)
    np.testing.assert_array_equal(again.D, cam.D)
    assert not CameraModel.from_camera_info({**msg, 'd': []}).has_distortion
    with pytest.raises(ValueError, match='camera_matrix'):
        CameraModel.from_camera_info({'width': 1})
    with pytest.raises(ValueError, match='unsupported distortion_model'):
        CameraModel.from_camera_info({**msg, 'distortion_model': 'equidistant'})
    with pytest.raises(ValueError, match='fx, fy > 0'):
        CameraModel(np.diag([0.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match='plumb_bob'):
        CameraModel(np.eye(3), np.ones(8))
    bad = tmp_path / 'bad.yaml'
    bad.write_text('camera_matrix: [unclosed')
    with pytest.raises(ValueError, match='cannot read camera YAML'):
        CameraModel.from_yaml(bad)


def test_undistort_image_straightens_a_distorted_line():
    cam = CameraModel.from_camera_info(DESK_INFO)
    # straight in the pinhole image
    und_line = np.stack([np.linspace(40, 600, 400), np.full(400, 60.0)], 1)
    raw_line = cam.distort_points(und_line)
    img = np.zeros((480, 640), np.uint8)
    cv2.polylines(
        img, [np.round(raw_line * 16).astype(np.int32)], False, 255, 3, cv2.LINE_AA, shift=4
    )
    und = cam.undistort_image(img)
    cols = np.arange(80, 560, 40)
    rows = [np.average(np.arange(480), weights=und[:, c].astype(float) + 1e-9) for c in cols]
    assert np.ptp(rows) < 1.0  # straight again, at y = 60
    assert abs(np.mean(rows) - 60) < 0.5
    raw_rows = [np.average(np.arange(480), weights=img[:, c].astype(float) + 1e-9) for c in cols]
    assert np.ptp(raw_rows) > 5  # it was curved


def test_real_camera_yaml(imu_root):
    cam = CameraModel.from_yaml(imu_root / 'cmu_hwangbo_desk' / 'derived_camera_info.yaml')
    assert (cam.width, cam.height) == (640, 480)
    assert cam.D[0] == pytest.approx(-0.346217) and cam.K[0, 1] == pytest.approx(-0.100721)
    raw = grid(640, 480, 8)
    assert np.abs(cam.distort_points(cam.undistort_points(raw)) - raw).max() < 0.01
