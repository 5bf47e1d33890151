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

"""Synthetic generator: determinism, exact pure-rotation rendering, gyro model, ground truth."""
from iemd_ros.datasets.synthetic import angular_velocity, generate, SyntheticConfig
from iemd_ros.gyro.predictor import rotation_homography, warp_difference
from iemd_ros.gyro.rotation import so3_exp
import numpy as np
import pytest


@pytest.fixture(scope='module')
def shake():
    return generate(n_frames=40, max_rate_deg_s=150.0, seed=4)


def test_deterministic_from_seed(shake):
    again = generate(n_frames=40, max_rate_deg_s=150.0, seed=4)
    np.testing.assert_array_equal(again.frames, shake.frames)
    np.testing.assert_array_equal(again.gyro, shake.gyro)
    np.testing.assert_array_equal(again.gt_boxes, shake.gt_boxes)
    other = generate(n_frames=40, max_rate_deg_s=150.0, seed=5, render=False)
    assert not np.allclose(other.gyro, shake.gyro)


def test_api_shapes_and_types(shake):
    s = shake
    assert s.frames.shape == (40, 240, 320, 3) and s.frames.dtype == np.uint8
    assert s.frame_stamps_ns.dtype == np.int64 and np.all(np.diff(s.frame_stamps_ns) > 0)
    assert s.gyro_t_ns.dtype == np.int64 and s.gyro.shape == (len(s.gyro_t_ns), 3)
    assert s.gt_boxes.shape == (40, 4) and s.visible.all()
    # the gyro spans the frames with margin, at 200 Hz
    assert (
        s.gyro_t_ns[0] < s.frame_stamps_ns[0] - 100_000_000
        and s.gyro_t_ns[-1] > s.frame_stamps_ns[-1] + 100_000_000
    )
    assert np.median(np.diff(s.gyro_t_ns)) == 5_000_000
    assert s.camera.width == 320 and not s.camera.has_distortion


def test_frames_are_exact_pure_rotations(shake):
    """
    Warping frame k-1 by K R^T K^-1 (true R) reproduces frame k.

    The opposite direction does not.
    """
    s = shake
    for k in (5, 17, 30):
        R = s.relative_rotation(k)
        good = warp_difference(s.frames[k - 1], s.frames[k], rotation_homography(s.K, R))
        none = warp_difference(s.frames[k - 1], s.frames[k], np.eye(3))
        wrong = warp_difference(s.frames[k - 1], s.frames[k], rotation_homography(s.K, R.T))
        assert good < 2.5, (k, good)  # only resampling noise and cube seams remain
        assert none > 5 * good and wrong > 5 * good


def test_gyro_model_noise_free():
    R_ci = so3_exp([0.0, 0.0, np.pi / 2]) @ so3_exp([np.pi, 0.0, 0.0])
    cfg = SyntheticConfig(
        n_frames=20, R_cam_imu=R_ci, gyro_bias=(0.01, -0.02, 0.03), render=False, seed=1
    )
    s = generate(cfg)
    t_true = (s.gyro_t_ns - 10_000_000_000) * 1e-9
    w_cam = angular_velocity(cfg, t_true)
    np.testing.assert_allclose((s.gyro - s.gyro_bias) @ R_ci.T, w_cam, atol=1e-9)
    assert np.degrees(
        np.linalg.norm(angular_velocity(cfg, np.linspace(0, 20 / 30, 2000)), axis=1).max()
    ) == pytest.approx(200.0, rel=1e-3)


def test_noise_jitter_offset_and_still_start():
    cfg = SyntheticConfig(
        n_frames=30,
        gyro_noise_std=0.01,
        gyro_jitter_s=0.0005,
        time_offset_s=0.005,
        still_start_s=1.0,
        gyro_rate_hz=100.0,
        render=False,
    )
    s = generate(cfg)
    clean = generate(cfg, gyro_noise_std=0.0, gyro_jitter_s=0.0)
    assert np.std(s.gyro - clean.gyro) == pytest.approx(0.01, rel=0.1)
    jit = (s.gyro_t_ns - clean.gyro_t_ns) * 1e-9
    assert np.std(jit) == pytest.approx(0.0005, rel=0.15)
    # camera stamps are earlier by the offset: t_imu = t_cam + offset
    assert np.all(
        clean.frame_stamps_ns == 10_000_000_000 + np.round(np.arange(30) / 30 * 1e9) - 5_000_000
    )
    still = (clean.gyro_t_ns - 10_000_000_000) * 1e-9 < -0.2
    assert still.sum() >= 99 and np.all(clean.gyro[still] == 0)


def test_fast_pan_renders_every_pixel():
    # 100 deg per frame
    s = generate(n_frames=12, motion='pan', max_rate_deg_s=300.0, fps=3.0, seed=2)
    assert np.mean(s.frames.max(axis=-1) == 0) < 1e-3
    yaw = np.degrees(np.arctan2(s.orientations[:, 0, 2], s.orientations[:, 2, 2]))
    assert np.allclose(np.diff(np.unwrap(np.radians(yaw))), np.radians(100.0), atol=1e-9)


def test_gt_box_contains_the_target(shake):
    s = shake
    tex = {(30, 200, 255), (200, 40, 40)}
    for k in (0, 20, 39):
        x, y, w, h = s.gt_boxes[k]
        inner = (
            s.frames[k, int(y) + 4: int(y + h) - 4, int(x) + 4: int(x + w) - 4]
            .reshape(-1, 3)
            .astype(int)
        )
        ring = np.concatenate(
            [
                s.frames[k, int(y) - 8: int(y) - 3, int(x): int(x + w)].reshape(-1, 3),
                s.frames[k, int(y + h) + 3: int(y + h) + 8, int(x): int(x + w)].reshape(-1, 3),
            ]
        ).astype(int)

        def target_like(px):
            return np.mean(
                [min(np.abs(np.sort(p) - np.sort(c)).max() for c in tex) < 40 for p in px]
            )

        assert target_like(inner) > 0.6
        assert target_like(ring) < 0.2


def test_moving_target_moves_in_the_scene():
    still = generate(n_frames=60, target_speed_deg_s=0.0, render=False, seed=3)
    moving = generate(n_frames=60, target_speed_deg_s=20.0, render=False, seed=3)
    np.testing.assert_allclose(still.orientations, moving.orientations)
    d = np.hypot(*(moving.gt_centres - still.gt_centres).T)
    assert d[0] < 1e-9 and d[-1] > 5


def test_bad_config_raises():
    with pytest.raises(ValueError, match='motion'):
        generate(motion='spin', render=False)
    with pytest.raises(ValueError, match='n_frames'):
        generate(n_frames=1, render=False)
