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
The node-level cases of issue #28 (one process, over DDS).

Nothing a sensor or a user sends stops the tracker. Each test is named after its case; every one
ends with the node still answering valid frames.
"""
import threading

import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
pytest.importorskip('vision_msgs.msg')

from iemd_ros.datasets.synthetic import generate  # noqa: E402, I100
from iemd_ros.messages.conversions import stamp_ns  # noqa: E402
from iemd_ros.tracking import IemdTracker  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from ros_harness import level, values  # noqa: E402
from sensor_msgs.msg import CameraInfo  # noqa: E402
from test_node import ERROR, OK, tracker_and_driver, WARN  # noqa: E402

N = 16


@pytest.fixture(scope='module')
def seq():
    return generate(n_frames=N, max_rate_deg_s=100.0, time_offset_s=0.004, seed=3)


def _answered(drv, t_ns, tracked=None, timeout=15.0):
    """
    Wait for the Detection2DArray of the image stamped ``t_ns``.

    (with a detection if ``tracked``, empty if ``tracked`` is False); returns it or None.
    """
    found = []

    def check():
        for d in drv.detections:
            if stamp_ns(d.header) == t_ns and (tracked is None or bool(d.detections) == tracked):
                found.append(d)
                return True
        return False
    return found[0] if drv.wait_for(check, timeout) else None


def _camera_info(seq, k):
    msg = CameraInfo()
    msg.width, msg.height = seq.config.width, seq.config.height
    msg.k = [float(v) for v in k]
    msg.d = [0.0] * 5
    msg.distortion_model = 'plumb_bob'
    return msg


def _feed(drv, seq, frames, sent=0):
    """
    Publish the gyro up to each frame of ``frames`` (indices) and the frame.

    Each answered before the next; returns the index of the next gyro sample and whether every
    frame was answered with a detection.
    """
    s = [int(v) for v in seq.frame_stamps_ns]
    tracked = True
    for k in frames:
        sent = drv.publish_imu_until(seq, s[k], sent)
        drv.publish_image(seq.frames[k], s[k])
        tracked &= _answered(drv, s[k], tracked=True) is not None
    return sent, tracked


def test_absurd_focal_length_camera_info_then_imu_and_frames_do_not_stop_the_tracker(ctx, seq):
    """
    The worker hung for ever after k = [1e300, 0, cx, 0, 1e300, cy, 0, 0, 1] and IMU.

    (issue #28).
    """
    box0 = [float(v) for v in seq.gt_boxes[0]]
    cx, cy = (seq.config.width - 1) / 2, (seq.config.height - 1) / 2
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=500.0) as (node, drv):
        drv.info_pub.publish(_camera_info(seq, [1e300, 0, cx, 0, 1e300, cy, 0, 0, 1]))
        sent, tracked = _feed(drv, seq, range(0, 6))
        assert tracked
        st = drv.wait_status('camera_info', lambda x: level(x) == ERROR)
        assert (
            st is not None
            and 'camera_info k[0] (fx) = 1e+300 px is out of [32, 32000] px' in st.message
        )
        for k in ([1e8, 0, cx, 0, 1e8, cy, 0, 0, 1], [500.0, 0, 1e6, 0, 500.0, cy, 0, 0, 1]):
            drv.info_pub.publish(_camera_info(seq, k))
        assert (
            drv.wait_status('camera_info', lambda x: 'k[2] (cx) = 1e+06' in x.message) is not None
        )
        drv.publish_camera_info(seq)  # a valid one: used
        assert drv.wait_status('camera_info', lambda x: level(x) == OK) is not None
        sent, tracked = _feed(drv, seq, range(6, 10), sent)
        assert tracked
        assert drv.wait_status('imu', lambda x: 'gyro prior used' in x.message) is not None


def test_a_1x1_frame_is_malformed_and_its_error_clears_on_the_next_good_frame(ctx, seq):
    """A 1x1 mono8 frame gave ERROR "internal error: frame is empty" on every good frame after."""
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=0.0) as (node, drv):
        _feed(drv, seq, range(0, 3))
        for k, (w, h) in zip((3, 4), ((1, 1), (100_000, 1))):
            drv.publish_image(
                seq.frames[k], s[k], encoding='mono8', width=w, height=h, step=w, data=bytes(w * h)
            )
            # an empty array, not silence
            assert _answered(drv, s[k], tracked=False) is not None, (w, h)
        st = drv.wait_status('image input', lambda x: level(x) == ERROR)
        assert st is not None and 'image width = 100000 px is out of [2, 16384] px' in st.message
        _, tracked = _feed(drv, seq, range(5, 7))
        assert tracked
        trk = drv.wait_status('tracking', lambda x: True)
        img = drv.wait_status('image input', lambda x: True)
        assert level(trk) == OK and level(img) == OK, (trk.message, img.message)


def test_malformed_frames_get_an_empty_detection_array(ctx, seq):
    """
    A malformed frame got no Detection2DArray at all.

    A consumer could not tell "no frame" from "no target".
    """
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=0.0) as (node, drv):
        _feed(drv, seq, range(0, 2))
        for k, bad in (
            (2, {'encoding': 'yuv422'}),
            (3, {'step': 100}),
            (4, {'data': b'\x00' * 10}),
        ):
            drv.publish_image(seq.frames[k], s[k], **bad)
            arr = _answered(drv, s[k])
            assert arr is not None and not arr.detections, bad
        _, tracked = _feed(drv, seq, range(5, 7))
        assert tracked


def test_an_internal_error_clears_on_the_next_good_frame(ctx, seq, monkeypatch):
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=0.0) as (node, drv):
        _feed(drv, seq, range(0, 2))
        update = IemdTracker.update
        calls = []

        def broken_once(self, frame, prior=None, interval=None):
            calls.append(1)
            if len(calls) == 1:
                raise RuntimeError('a bug')
            return update(self, frame, prior, interval)

        monkeypatch.setattr(IemdTracker, 'update', broken_once)
        drv.publish_image(seq.frames[2], s[2])
        arr = _answered(drv, s[2])
        assert arr is not None and not arr.detections  # answered, empty
        st = drv.wait_status('tracking', lambda x: level(x) == ERROR)
        assert st is not None and 'internal error: RuntimeError: a bug' in st.message
        _, tracked = _feed(drv, seq, range(3, 5))
        assert tracked
        assert drv.wait_status('tracking', lambda x: level(x) == OK) is not None


def test_a_hung_tracker_update_is_abandoned_and_the_tracker_rebuilt(ctx, seq, monkeypatch):
    """
    The watchdog: an update that does not return within watchdog_ms is abandoned.

    The frame answered empty, the tracking status says ERROR with the reason, and the rebuilt
    tracker tracks the next frames.
    """
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    release = threading.Event()
    update = IemdTracker.update
    calls = []

    def hangs_once(self, frame, prior=None, interval=None):
        calls.append(1)
        if len(calls) == 2:
            # as the hung calcOpticalFlowPyrLK
            release.wait(120.0)
        return update(self, frame, prior, interval)

    monkeypatch.setattr(IemdTracker, 'update', hangs_once)
    try:
        with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=0.0, watchdog_ms=300.0) as (
            node,
            drv,
        ):
            _feed(drv, seq, range(0, 2))
            drv.publish_image(seq.frames[2], s[2])
            arr = _answered(drv, s[2])
            assert arr is not None and not arr.detections
            st = drv.wait_status('tracking', lambda x: level(x) == ERROR)
            assert st is not None and 'abandoned' in st.message and '300 ms' in st.message, (
                st and st.message
            )
            _, tracked = _feed(drv, seq, range(3, 6))
            assert tracked
            trk = drv.wait_status('tracking', lambda x: level(x) == OK)
            assert trk is not None and values(trk)['updates_abandoned'] == '1'
    finally:
        release.set()


def test_deleting_a_parameter_is_refused_and_changes_still_work(ctx):
    """
    `ros2 param delete /iemd_tracker initial_box` succeeded.

    And every change after it failed.
    """
    with tracker_and_driver(ctx) as (node, drv):
        # rclpy itself refuses typed ones
        for name in ('initial_box', 'tracker.n_iter', 'use_gyro'):
            (r,) = drv.set_parameters_raw([Parameter(name, Parameter.Type.NOT_SET, None)])
            assert not r.successful and 'cannot be' in r.reason, (name, r.reason)
            assert node.has_parameter(name)
        (r,) = drv.set_parameters_raw([Parameter('initial_box', Parameter.Type.NOT_SET, None)])
        assert (
            r.reason == 'parameters cannot be deleted: initial_box (initial_box takes [] for none)'
        )
        (r,) = drv.set_parameters(**{'tracker.n_iter': 7})
        assert r.successful, r.reason
        assert drv.wait_for(lambda: node.pipeline.config.tracker.n_iter == 7, 5.0)
        (r,) = drv.set_parameters(initial_box=[10.0, 10.0, 40.0, 40.0])
        assert r.successful, r.reason


@pytest.mark.parametrize(
    'name, value, reason',
    [
        ('tracker.template_size', [100_000, 100_000], 'must be in [8, 96]'),
        ('tracker.template_size', [128, 128], 'must be in [8, 96]'),
        ('initial_box', [10.0, 10.0, 200_000.0, 200_000.0], 'must be in [-16384, 16384]'),
        ('gyro.saturation', 0.0, 'out of range'),
        ('watchdog_ms', 0.0, 'out of range'),
    ],
)
def test_run_time_changes_that_would_make_every_frame_fail_are_rejected(ctx, name, value, reason):
    with tracker_and_driver(ctx) as (node, drv):
        (r,) = drv.set_parameters(**{name: value})
        assert not r.successful and reason in r.reason, (name, r.reason)


def test_an_init_rejection_while_tracking_warns_in_the_tracking_status(ctx, seq):
    """~/init rejections showed only in a diagnostic value while the status stayed OK."""
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=0.0) as (node, drv):
        _feed(drv, seq, range(0, 3))
        drv.publish_init((10.0, 10.0, 200_000.0, 200_000.0), s[2])
        st = drv.wait_status('tracking', lambda x: level(x) == WARN)
        assert (
            st is not None and '~/init failed' in st.message and 'box w = 200000 px' in st.message
        ), st and st.message
        # still tracking the old target
        _, tracked = _feed(drv, seq, range(3, 5))
        assert tracked
        # a good one clears the warning
        drv.publish_init(seq.gt_boxes[4], s[4])
        assert (
            drv.wait_status('tracking', lambda x: level(x) == OK and 'note' not in values(x))
            is not None
        )


def test_the_node_keeps_answering_after_a_burst_of_hostile_inputs(ctx, seq):
    """
    Garbage on every input at once, then valid frames.

    Each is answered with a Detection2DArray (empty while the tracker reports the target lost: the
    burst's mono16 frames lack the colour it learned) and the target is tracked again by the last
    one.
    """
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = [float(v) for v in seq.gt_boxes[0]]
    rng = np.random.default_rng(28)
    with tracker_and_driver(ctx, initial_box=box0, imu_wait_ms=50.0) as (node, drv):
        drv.publish_camera_info(seq)
        sent, _ = _feed(drv, seq, range(0, 2))
        for i in range(40):
            drv.publish_imu(
                int(s[2] + rng.integers(-(10**9), 10**9)), rng.choice([1e308, -1e30, 0.0, 7.0], 3)
            )
            drv.publish_image(
                seq.frames[2],
                s[2] + i,
                **rng.choice([{'encoding': 'mono16'}, {'height': 0}, {'step': 1}, {'width': 7}]),
            )
        drv.publish_camera_info(seq)
        for k in range(3, N):
            sent = drv.publish_imu_until(seq, s[k], sent)
            drv.publish_image(seq.frames[k], s[k])
            assert _answered(drv, s[k]) is not None, k
        assert (
            _answered(drv, s[N - 1], tracked=True, timeout=1.0) is not None
            and node._worker.is_alive()
        )


def test_sigterm_in_the_middle_of_a_wait_set_is_a_clean_stop(monkeypatch):
    """
    SIGTERM in the middle of a wait set stops the node cleanly (docs/decisions.md#node-soak).

    RCLError "failed to initialize wait set: the given context is not valid" out of rclpy.spin.
    The race, made certain: the context goes while spin is in a wait.
    """
    from iemd_ros.ros import spin
    from rclpy.impl.implementation_singleton import rclpy_implementation
    from ros_harness import ros_context

    with ros_context() as context:
        node = rclpy.create_node('iemd_spin_race', context=context)

        def racing_spin(n):
            # rclpy's signal handler, meanwhile
            context.try_shutdown()
            raise rclpy_implementation.RCLError(
                'failed to initialize wait set: the given context is not valid'
            )

        monkeypatch.setattr(spin.rclpy, 'spin', racing_spin)
        spin.spin_until_shutdown(node)  # returns: a clean stop
        assert not context.ok()
    # the same error with the context alive
    with ros_context() as context:
        node = rclpy.create_node('iemd_spin_error', context=context)  # is a real one: raised

        def failing_spin(n):
            raise rclpy_implementation.RCLError('something else')

        monkeypatch.setattr(spin.rclpy, 'spin', failing_spin)
        with pytest.raises(rclpy_implementation.RCLError, match='something else'):
            spin.spin_until_shutdown(node)
