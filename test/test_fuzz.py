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
Property-based fuzzing (hypothesis) of what turns message fields into numbers.

The image conversions, the camera model from camera_info, boxes, the IMU buffer and the pipeline's
IMU input, with arbitrary field values.

The property everywhere: a value is either taken, and then what comes out is finite and within its
limits, or refused with a ValueError; no other exception, nothing non-finite passed on.  The
examples are derandomized (the same cases on every run, in CI too); ``FUZZ_EXAMPLES`` below is the
number of cases per test.
"""
import math

import cv2
from hypothesis import event, given, HealthCheck, settings
from hypothesis import strategies as st
from iemd_ros.common.boxes import check_box
from iemd_ros.common.limits import FOCAL_LENGTH, IMAGE_SIDE, PRINCIPAL_POINT
from iemd_ros.gyro import GyroConfig, GyroPredictor
from iemd_ros.gyro.imu import ImuBuffer, SampleStatus
from iemd_ros.messages.conversions import (
    bbox_to_box,
    camera_model_from_info,
    compressed_to_array,
    ENCODINGS,
    image_to_array,
)
from iemd_ros.pipeline import PipelineConfig, TrackingPipeline
import numpy as np
import pytest

FUZZ_EXAMPLES = 300
fuzz = settings(max_examples=FUZZ_EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# every float a message field can carry: NaN, infinities, the extremes, subnormals, and ordinary
# values
any_float = st.floats(allow_nan=True, allow_infinity=True, width=64)
ordinary = st.floats(-2000.0, 2000.0)
field_float = st.one_of(
    any_float, ordinary, st.sampled_from([0.0, -0.0, 1e-300, 1e300, -1e300, 1e308, 5e-324])
)
# ROS stamps: int32 seconds and uint32 nanoseconds, as integer ns
stamp = st.integers(-(2**31) * 10**9, 2**31 * 10**9)


@fuzz
@given(
    encoding=st.one_of(st.sampled_from(sorted(ENCODINGS)), st.text(max_size=8)),
    height=st.integers(2, 40) | st.sampled_from([0, 1, 16385, 2**31]),
    width=st.integers(2, 40) | st.sampled_from([0, 1, 16385]),
    step_extra=st.sampled_from([0, 0, 0, 1, 7, -1, -8]),
    size_extra=st.sampled_from([0, 0, 0, 0, -1, 1, -100]),
    big_endian=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_image_fields_convert_to_a_frame_or_a_value_error(
    encoding, height, width, step_extra, size_extra, big_endian, seed
):
    channels, depth = ENCODINGS.get(encoding, (1, 1))
    step = max(width * channels * depth + step_extra, 0)
    n = max(min(step * height, 1 << 16) + size_extra, 0)  # never a huge buffer
    data = np.random.default_rng(seed).integers(0, 256, n, dtype=np.uint8).tobytes()
    try:
        frame = image_to_array(encoding, height, width, step, data, big_endian)
    except ValueError as exc:
        assert str(exc)
        event('refused')
        return
    event('converted')
    assert encoding in ENCODINGS and IMAGE_SIDE.low <= width <= IMAGE_SIDE.high
    assert frame.dtype == np.uint8 and frame.shape[:2] == (height, width)
    assert frame.ndim == (2 if channels == 1 else 3)


@fuzz
@given(
    data=st.binary(max_size=512),
    fmt=st.sampled_from(
        ['jpeg', 'png', 'bgr8; jpeg compressed bgr8', '', '16UC1; compressedDepth']
    ),
    prefix=st.sampled_from([b'', b'\xff\xd8\xff', b'\x89PNG\r\n\x1a\n']),
)
def test_compressed_data_decode_to_a_frame_or_a_value_error(data, fmt, prefix):
    try:
        frame = compressed_to_array(fmt, prefix + data)
    except ValueError as exc:
        assert str(exc)
        return
    assert (
        frame.dtype == np.uint8 and frame.ndim in (2, 3) and min(frame.shape[:2]) >= IMAGE_SIDE.low
    )


@fuzz
@given(
    shape=st.tuples(st.integers(1, 40), st.integers(1, 40)),
    channels=st.sampled_from([1, 3, 4]),
    codec=st.sampled_from(['.png', '.jpg']),
    cut=st.sampled_from([0, 0, 0, 1, 8, 64]),
    seed=st.integers(0, 2**16),
)
def test_truncated_real_images_decode_or_raise_a_value_error(shape, channels, codec, cut, seed):
    img = np.random.default_rng(seed).integers(
        0, 256, shape + ((channels,) if channels > 1 else ()), dtype=np.uint8
    )
    ok, buf = cv2.imencode(codec, img)
    data = buf.tobytes()[: max(len(buf) - cut, 0)]
    try:
        frame = compressed_to_array(codec[1:], data)
    except ValueError:
        event('refused')
        return
    event('decoded')
    assert frame.shape[:2] == shape and frame.dtype == np.uint8


real_k = st.builds(
    lambda fx, fy, cx, cy, skew: [fx, skew, cx, 0.0, fy, cy, 0.0, 0.0, 1.0],
    st.floats(1.0, 1e5),
    st.floats(1.0, 1e5),
    st.floats(-1000.0, 2000.0),
    st.floats(-1000.0, 2000.0),
    st.floats(-5.0, 5.0),
)


@fuzz
@given(
    k=st.lists(field_float, min_size=9, max_size=9) | st.lists(field_float, max_size=12) | real_k,
    d=st.lists(field_float, max_size=8) | st.lists(st.floats(-1.0, 1.0), max_size=5),
    model=st.sampled_from(['plumb_bob', '', 'rational_polynomial', 'none']),
    size=st.sampled_from([(640, 480), (320, 240), (0, 0), (1280, 720)])
    | st.tuples(st.integers(0, 20_000), st.integers(0, 20_000)),
)
def test_camera_info_gives_a_model_within_the_limits_or_a_value_error(k, d, model, size):
    width, height = size
    try:
        cam = camera_model_from_info(k, d, model, width, height)
    except ValueError as exc:
        assert str(exc)
        event('refused')
        return
    event('taken')
    assert np.all(np.isfinite(cam.K)) and np.all(np.isfinite(cam.D))
    if cam.width is not None:
        side = max(cam.width, cam.height)
        lo, hi = FOCAL_LENGTH.bounds(side)
        assert lo <= cam.K[0, 0] <= hi and lo <= cam.K[1, 1] <= hi
        lo, hi = PRINCIPAL_POINT.bounds(cam.width)
        assert lo <= cam.K[0, 2] <= hi
    pts = np.array([[0.0, 0.0], [cam.K[0, 2], cam.K[1, 2]], [1e4, -1e4]])
    # far points of a strong lens overflow to NaN
    with np.errstate(over='ignore', invalid='ignore'):
        # NaN where the lens model cannot be inverted
        out = cam.undistort_points(cam.distort_points(pts))
    assert out.shape == pts.shape and not np.any(np.isinf(out))


@fuzz
@given(values=st.lists(field_float, min_size=4, max_size=4))
def test_boxes_are_finite_with_a_positive_size_or_a_value_error(values):
    for convert in (check_box, lambda v: bbox_to_box(*v)):
        try:
            box = convert(values)
        except ValueError as exc:
            assert str(exc)
            continue
        assert all(math.isfinite(v) for v in box) and box[2] > 0 and box[3] > 0


samples = st.lists(
    st.tuples(
        st.integers(0, 200_000_000) | stamp,
        st.lists(field_float, min_size=3, max_size=3) | st.lists(ordinary, min_size=3, max_size=3),
    ),
    max_size=60,
)


@fuzz
@given(
    samples=samples,
    saturation=st.sampled_from([None, 35.0, 1.0]),
    window=st.tuples(st.integers(0, 200_000_000), st.integers(0, 200_000_000))
    | st.tuples(stamp, stamp),
)
def test_the_imu_buffer_screens_any_stream_and_integrates_to_a_rotation(
    samples, saturation, window
):
    buf = ImuBuffer(saturation=saturation, max_samples=50)
    for t, w in samples:
        (status,) = buf.add(t, w)
        finite = all(math.isfinite(v) for v in w)
        assert (status == SampleStatus.NOT_FINITE) == (not finite)
        if finite and saturation is not None and max(abs(v) for v in w) >= saturation:
            assert status == SampleStatus.SATURATED
    assert len(buf) <= 50
    t, w = buf.samples()
    assert np.all(np.diff(t) > 0) and np.all(np.isfinite(w))
    t0, t1 = sorted(window)
    try:
        integ = buf.integrate(t0, t1)
    # rates too large to integrate (no saturation limit): refused
    except ValueError as exc:
        assert saturation is None and 'quaternion' in str(exc)
        event('not integrable')
        return
    event(f'integration {integ.status.value}')
    assert np.all(np.isfinite(integ.R)) and np.allclose(integ.R @ integ.R.T, np.eye(3), atol=1e-6)


@fuzz
@given(samples=samples, covariance=st.sampled_from([0.0, -1.0, float('nan')]))
def test_the_pipeline_takes_any_imu_message_without_raising(
    samples, covariance, _pipeline_and_frames
):
    p, frames, stamps, box = _pipeline_and_frames
    p.reset()
    received = p.diagnostics()['imu_received']
    for t, w in samples:
        assert p.add_imu_message(t, w, covariance) in (True, False)
    assert p.diagnostics()['imu_received'] == received + len(samples)
    p.init(frames[0], box, stamps[0])
    # a prior, if any, is finite: tracked
    r = p.process(frames[1], stamps[1])
    assert r.gyro_box is None or all(math.isfinite(v) for v in r.gyro_box)


@pytest.fixture(scope='module')
def _pipeline_and_frames():
    from iemd_ros.datasets.synthetic import generate

    seq = generate(n_frames=2, seed=3)
    p = TrackingPipeline(PipelineConfig(imu_wait_ms=0.0))
    p.set_camera(seq.camera)
    return p, seq.frames, [int(v) for v in seq.frame_stamps_ns], seq.gt_boxes[0]


@fuzz
@given(
    box=st.tuples(
        st.floats(-500, 800), st.floats(-500, 800), st.floats(0.5, 2000), st.floats(0.5, 2000)
    ),
    rates=st.lists(st.floats(-34.0, 34.0), min_size=3, max_size=3),
    dt_ms=st.integers(1, 200),
)
def test_the_gyro_prediction_of_any_box_is_finite_or_none(box, rates, dt_ms):
    from iemd_ros.gyro.camera import CameraModel

    cam = CameraModel(
        [500.0, 0.0, 319.5, 0.0, 500.0, 239.5, 0.0, 0.0, 1.0], [-0.3, 0.1, 0.0, 0.0, 0.0], 640, 480
    )
    pred = GyroPredictor(cam, GyroConfig())
    t = np.arange(0, (dt_ms + 10) * 1_000_000, 5_000_000)
    pred.add_imu(t, np.tile(rates, (len(t), 1)))
    p = pred.predict(0, dt_ms * 1_000_000, box=box)
    event('prior' if p.prior is not None else 'no prior')
    assert p.prior is None or np.all(np.isfinite(p.prior))
    assert p.box is None or np.all(np.isfinite(p.box))
