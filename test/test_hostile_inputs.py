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
The cases of issue #28 below the node.

Absurd camera_info, gyro rates, image sizes, init boxes and clock jumps are refused at the boundary
with the field and the value named, and never reach OpenCV or numba.
"""
import re

from iemd_ros.datasets.synthetic import generate
from iemd_ros.gyro import GyroConfig
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.messages.conversions import (
    camera_model_from_info,
    compressed_to_array,
    image_to_array,
)
from iemd_ros.pipeline import Level, PipelineConfig, TrackingPipeline, TrackState
from iemd_ros.tracking import flow, IemdTracker, TrackerConfig
import numpy as np
import pytest

N = 24


@pytest.fixture(scope='module')
def seq():
    return generate(n_frames=N, max_rate_deg_s=150.0, time_offset_s=0.004, seed=3)


def _pipeline(seq, **gyro):
    return TrackingPipeline(
        PipelineConfig(gyro=GyroConfig(time_offset_ns=seq.time_offset_ns, **gyro))
    )


def _k(fx=500.0, fy=500.0, cx=319.5, cy=239.5):
    return [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]


@pytest.mark.parametrize(
    'k, field',
    [
        (_k(fx=1e300, fy=1e300), 'k[0] (fx)'),
        (_k(fx=1e8), 'k[0] (fx)'),
        (_k(fy=1e8), 'k[4] (fy)'),
        (_k(cx=1e6), 'k[2] (cx)'),
        (_k(cy=-1e6), 'k[5] (cy)'),
        (_k(fx=0.5), 'k[0] (fx)'),
    ],
)
def test_camera_info_with_an_absurd_focal_length_or_principal_point_is_rejected_naming_the_field(
    k, field
):
    with pytest.raises(
        ValueError, match=re.escape(f'camera_info {field} = ') + r'.* px is out of \['
    ):
        camera_model_from_info(k, [0.0] * 5, 'plumb_bob', 640, 480)
    # a real 640x480 camera is taken
    camera_model_from_info(_k(), [0.0] * 5, 'plumb_bob', 640, 480)


def test_camera_info_of_another_image_size_gives_no_gyro_prior_and_a_warning(seq):
    p = _pipeline(seq)
    p.set_camera(
        CameraModel(seq.camera.K * [[2, 1, 2], [1, 2, 2], [1, 1, 1]], seq.camera.D, 640, 480)
    )
    for t, w in zip(seq.gyro_t_ns, seq.gyro, strict=True):
        p.add_imu(int(t), w)
    s = [int(v) for v in seq.frame_stamps_ns]
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    r = p.process(seq.frames[1], s[1])  # the frames are 320x240
    assert (
        not r.gyro_used
        and 'camera_info is for 640x480 images, this image is 320x240' in r.gyro_reason
    )
    camera = p.statuses()[3]
    assert camera.level == Level.WARN and '640x480' in camera.message


def test_camera_info_without_an_image_size_is_checked_against_the_frames(seq):
    p = _pipeline(seq)
    # no width/height: unknown until a frame comes
    p.set_camera(CameraModel(_k(fx=1e8, cx=159.5, cy=119.5)))
    for t, w in zip(seq.gyro_t_ns, seq.gyro, strict=True):
        p.add_imu(int(t), w)
    s = [int(v) for v in seq.frame_stamps_ns]
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    r = p.process(seq.frames[1], s[1])
    assert not r.gyro_used and 'k[0] (fx)' in r.gyro_reason and '1e+08' in r.gyro_reason
    assert r.state is TrackState.TRACKING


def test_the_window_flow_never_gives_opencv_an_empty_or_non_finite_region(monkeypatch):
    """
    The hang of issue #28.

    A prior mapping a window corner to infinity made the region 0x0 (INT_MIN corners), on which
    cv2.calcOpticalFlowPyrLK never returned.
    """
    calls = []

    def checked_lk(prev, cur, points, guess, **kw):
        assert min(prev.shape) > 0 and prev.shape == cur.shape, prev.shape
        assert np.all(np.isfinite(points)) and np.all(np.isfinite(guess))
        calls.append(prev.shape)
        return guess, np.ones((len(points), 1), np.uint8), np.zeros((len(points), 1), np.float32)

    monkeypatch.setattr(flow.cv2, 'calcOpticalFlowPyrLK', checked_lk)
    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (240, 320), dtype=np.uint8)
    box = (100.0, 100.0, 50.0, 50.0)
    # w = 0 at x = 100
    to_infinity = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.01, 0.0, -1.0]])
    # finite, far outside
    far = np.array([[1.0, 0.0, 1e15], [0.0, 1.0, 1e15], [0.0, 0.0, 1.0]])
    for prior in (to_infinity, far):
        assert flow.window_flow(frame, frame, box, prior) is None
    # a plain window still flows
    assert flow.window_flow(frame, frame, box, None) is not None and calls


def _gyro_stream_with(seq, rate: float, start_ns: int, length_ns: int):
    """Return the gyro with the samples in [start, start + length) set to ``rate`` on each axis."""
    t = np.asarray(seq.gyro_t_ns)
    w = np.array(seq.gyro, dtype=float)
    w[(t >= start_ns) & (t < start_ns + length_ns)] = rate
    return t, w


@pytest.mark.parametrize('rate', [1e3, 1e10, 1e30])
def test_absurd_finite_gyro_rates_are_rejected_by_the_default_saturation(seq, rate):
    # 2000 deg/s, a MEMS gyro's full scale
    assert GyroConfig().saturation == 35.0
    s = [int(v) for v in seq.frame_stamps_ns]
    # 35 ms of nonsense after frame 5
    t, w = _gyro_stream_with(seq, rate, s[5], 35_000_000)
    p = _pipeline(seq)
    p.set_camera(seq.camera)
    accepted = [p.add_imu(int(ti), wi) for ti, wi in zip(t, w, strict=True)]
    assert accepted.count(False) == int(np.sum(w[:, 0] == rate)) > 0
    d = p.diagnostics()
    assert (
        d['imu_saturated'] == accepted.count(False)
        and 'saturation limit 35.0 rad/s' in d['imu_reason']
    )
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    results = [p.process(seq.frames[k], s[k]) for k in range(1, N)]
    assert all(r.state is TrackState.TRACKING for r in results), [
        (r.state, r.reason) for r in results
    ]


def test_gyro_rates_of_1e308_fail_no_frame(seq):
    s = [int(v) for v in seq.frame_stamps_ns]
    t, w = _gyro_stream_with(seq, 1e308, 0, 10**15)  # the whole stream
    p = _pipeline(seq)
    p.set_camera(seq.camera)
    for ti, wi in zip(t, w, strict=True):
        p.add_imu(int(ti), wi)
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    # raised "cannot normalize" before
    results = [p.process(seq.frames[k], s[k]) for k in range(1, N)]
    assert not any(r.gyro_used for r in results)
    assert p.statuses()[2].level == Level.ERROR and 'saturation' in p.statuses()[2].message


@pytest.mark.parametrize('width, height', [(1, 1), (100_000, 1), (1, 100_000), (20_000, 16)])
def test_an_image_of_1x1_or_100000x1_is_malformed_naming_its_size(width, height):
    field, value = ('width', width) if not 2 <= width <= 16384 else ('height', height)
    with pytest.raises(ValueError, match=rf'image {field} = {value} px is out of \[2, 16384\] px'):
        image_to_array('mono8', height, width, width, bytes(width * height))


def test_a_compressed_image_decoding_to_1x1_is_malformed():
    import cv2

    ok, png = cv2.imencode('.png', np.zeros((1, 1), np.uint8))
    with pytest.raises(ValueError, match=r'image width = 1 px is out of'):
        compressed_to_array('png', png.tobytes())


def test_rates_after_a_clock_jump_are_computed_since_the_reset(seq):
    p = _pipeline(seq)
    s = [int(v) for v in seq.frame_stamps_ns]
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    for k in range(1, 12):
        p.process(seq.frames[k], s[k])
    back = s[11] + 20_000_000_000  # a bag that loops: 20 s back
    for k in range(12, 16):
        p.process(seq.frames[k], s[k] - back)
    d = p.diagnostics()
    assert d['clock_resets'] == 1
    # read 0.0 Hz for ~30 frames
    assert d['input_rate_hz'] == pytest.approx(seq.config.fps, rel=0.01)
    assert d['processing_rate_hz'] == pytest.approx(seq.config.fps, rel=0.01)


@pytest.mark.parametrize(
    'box, text',
    [
        ((10.0, 10.0, 200_000.0, 200_000.0), 'box w = 200000 px is out of [0, 320] px'),
        ((10.0, 10.0, 50.0, 241.0), 'box h = 241 px is out of [0, 240] px'),
    ],
)
def test_an_init_box_larger_than_the_image_is_rejected_naming_the_size(seq, box, text):
    with pytest.raises(ValueError, match=re.escape(text)):
        IemdTracker().init(seq.frames[0], box)
    p = _pipeline(seq)
    with pytest.raises(ValueError, match='px is out of'):
        p.init(seq.frames[0], box, 1)
    assert p.state is TrackState.UNINITIALIZED


@pytest.mark.parametrize('size', [(100_000, 100_000), (128, 128)])
def test_a_template_size_beyond_its_range_is_refused(size):
    with pytest.raises(ValueError, match=r'tracker.template_size\[0\] must be in \[8, 96\] px'):
        TrackerConfig(template_size=size)


@pytest.mark.parametrize(
    'layout, patches',
    [
        ({'template_size': (64, 64), 'patch_step': 2}, 841),
        ({'template_size': (48, 48), 'patch_size': (2, 2), 'patch_step': 2}, 576),
        ({'template_size': (96, 96), 'patch_size': (32, 32)}, 289),
    ],
)
def test_a_template_layout_that_would_overrun_the_watchdog_on_every_frame_is_refused(
    layout, patches
):
    """
    Within their ranges, these layouts took 5.5.

    1.5 and 1.6 s per update (docs/decisions.md#patch-budget).
    """
    with pytest.raises(
        ValueError, match=rf'code a window with {patches} patches of \d+ pixels; at most 529'
    ):
        TrackerConfig(**layout)
    # 529 patches of 8x8: taken
    TrackerConfig(template_size=(96, 96))


def test_the_gyro_saturation_cannot_be_switched_off():
    with pytest.raises(ValueError, match=r'gyro.saturation must be in \[1, 1000\] rad/s, got 0'):
        GyroConfig(saturation=0.0)


def test_limits_are_declared_with_meaning_and_range():
    from iemd_ros.common.limits import FOCAL_LENGTH, IMAGE_SIDE, PRINCIPAL_POINT, TARGET_SIDE

    for limit in (IMAGE_SIDE, FOCAL_LENGTH, PRINCIPAL_POINT, TARGET_SIDE):
        assert limit.doc and limit.low < limit.high
