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
The node's outputs for a robot (issue #26).

Several targets by id, bearings, the Foxglove overlay, the compressed debug image, the detections'
rate / stamp-age status, the camera-IMU rotation from /tf_static, and the managed (lifecycle)
variant.
"""
import time

import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
pytest.importorskip('tf2_msgs.msg')
pytest.importorskip('foxglove_msgs.msg')

from foxglove_msgs.msg import ImageAnnotations  # noqa: E402, I100
from geometry_msgs.msg import TransformStamped  # noqa: E402
from iemd_ros.datasets.synthetic import generate  # noqa: E402
from iemd_ros.gyro.bearing import bearing  # noqa: E402
from iemd_ros.gyro.camera import CameraModel  # noqa: E402
from iemd_ros.gyro.rotation import quat_to_rot  # noqa: E402
from iemd_ros.messages.conversions import (  # noqa: E402
    bbox_to_box,
    bbox_values,
    stamp_ns,
    stamp_to_ns,
)
from iemd_ros.pipeline import ExtrinsicSource  # noqa: E402
from iemd_ros.ros.extrinsics import TF_STATIC_QOS  # noqa: E402
from iemd_ros.ros.node import LifecycleTrackerNode, TrackerNode  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from ros_harness import Driver, FRAME_ID, level, spinning, values  # noqa: E402
from sensor_msgs.msg import CompressedImage  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402
from vision_msgs.msg import Detection3DArray  # noqa: E402

OK, WARN, ERROR = 0, 1, 2
N = 12


@pytest.fixture(scope='module')
def seq():
    return generate(n_frames=N, max_rate_deg_s=40.0, seed=5)


class Outputs:
    """Records the node's bearings, annotations and compressed debug images."""

    def __init__(self, node):
        self.bearings, self.annotations, self.jpegs = [], [], []
        node.create_subscription(Detection3DArray, 'bearings', self.bearings.append, 50)
        node.create_subscription(
            ImageAnnotations, '/iemd_tracker/annotations', self.annotations.append, 50
        )
        node.create_subscription(
            CompressedImage, '/iemd_tracker/debug_image/compressed', self.jpegs.append, 5
        )


def _node(ctx, cls=TrackerNode, **params):
    overrides = {'diagnostics_period_s': 0.1, 'reliable_qos': True, 'imu_wait_ms': 200.0, **params}
    return cls(
        context=ctx, parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()]
    )


def _wait(predicate, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def _three_boxes(seq):
    """Return the synthetic target and two textured regions of the scene beside it."""
    x, y, w, h = (float(v) for v in seq.gt_boxes[0])
    return {
        'target': (x, y, w, h),
        'left': (x - 70.0, y, 48.0, 48.0),
        'below': (x, y + 60.0, 48.0, 48.0),
    }


def _send(drv, seq, k, sent, imu_frame=FRAME_ID):
    sent = drv.publish_imu_until(seq, int(seq.frame_stamps_ns[k]), sent, imu_frame)
    drv.publish_image(seq.frames[k], int(seq.frame_stamps_ns[k]))
    return sent


def _answered(drv, stamp):
    return lambda: any(stamp_ns(d.header) == stamp for d in drv.detections)


def test_three_targets_by_id_bearings_annotations_drop_and_reset(ctx, seq):
    stamps = [int(s) for s in seq.frame_stamps_ns]
    boxes = _three_boxes(seq)
    node = _node(ctx)
    drv = Driver(ctx)
    out = Outputs(drv.node)
    drop_pub = drv.node.create_publisher(String, '/iemd_tracker/drop', 10)
    try:
        with spinning(ctx, node, drv.node):
            assert drv.wait_connected()
            assert _wait(lambda: drop_pub.get_subscription_count() > 0, 5.0)
            jpeg_sub_seen = _wait(lambda: node._debug_jpeg_pub.get_subscription_count() > 0, 5.0)
            drv.publish_camera_info(seq)
            sent = _send(drv, seq, 0, 0)
            assert drv.wait_for(_answered(drv, stamps[0]), 10.0)
            for target_id, box in boxes.items():
                drv.publish_init(box, stamps[0], target_id)
            assert _wait(lambda: set(node.pipeline.targets) == set(boxes), 5.0)
            start, n_ann = len(drv.detections), len(out.annotations)
            for k in range(1, 6):
                sent = _send(drv, seq, k, sent)
                assert drv.wait_for(_answered(drv, stamps[k]), 10.0)
            arrays = drv.detections_since(start)
            assert len(arrays) == 5
            # one detection per target, with its id
            for arr in arrays:
                assert sorted(d.id for d in arr.detections) == sorted(boxes)
            true = {int(s): b for s, b in zip(stamps, seq.gt_boxes)}
            last = {d.id: bbox_to_box(*bbox_values(d.bbox)) for d in arrays[-1].detections}
            gt = true[stamp_ns(arrays[-1].header)]
            assert np.hypot(last['target'][0] - gt[0], last['target'][1] - gt[1]) < 6.0
            # an annotation message per frame, stamped like it, with a closed box and a label per
            # target
            assert _wait(lambda: len(out.annotations) >= n_ann + 5, 5.0)
            ann = out.annotations[-1]
            assert len(ann.points) == 3 and all(
                p.type == 2 and len(p.points) == 4 for p in ann.points
            )
            assert sorted(t.text.split()[0] for t in ann.texts) == sorted(boxes)
            ts = ann.points[0].timestamp
            assert stamp_to_ns(ts.sec, ts.nanosec) == stamp_ns(arrays[-1].header)
            # bearings: the lens model's ray to each box centre, in the image's frame
            assert _wait(
                lambda: any(
                    stamp_ns(b.header) == stamp_ns(arrays[-1].header) for b in out.bearings
                ),
                5.0,
            )
            b = next(b for b in out.bearings if stamp_ns(b.header) == stamp_ns(arrays[-1].header))
            assert b.header.frame_id == FRAME_ID and sorted(d.id for d in b.detections) == sorted(
                boxes
            )
            cam = CameraModel(seq.K, seq.dist, seq.config.width, seq.config.height)
            for d in b.detections:
                p = d.bbox.center.position
                np.testing.assert_allclose(
                    [p.x, p.y, p.z], bearing(cam, last[d.id]).ray, atol=1e-9
                )
            if jpeg_sub_seen:
                assert _wait(lambda: len(out.jpegs) > 0, 5.0) and out.jpegs[-1].format.startswith(
                    'bgr8; jpeg'
                )
            # ~/drop forgets one; ~/reset all
            drop_pub.publish(String(data='left'))
            assert _wait(lambda: set(node.pipeline.targets) == {'target', 'below'}, 5.0)
            sent = _send(drv, seq, 6, sent)
            assert drv.wait_for(_answered(drv, stamps[6]), 10.0)
            assert sorted(d.id for d in drv.detections[-1].detections) == ['below', 'target']
            assert drv.reset().success
            # the status of the window holding frame 7's detections may come before it is answered
            mark = drv.diagnostics_mark()
            sent = _send(drv, seq, 7, sent)
            assert drv.wait_for(_answered(drv, stamps[7]), 10.0)
            assert node.pipeline.targets == [] and not drv.detections[-1].detections
            # the detections' own status: rate window and stamp age (synthetic stamps are far in
            # the past)
            st = drv.wait_status(
                'detections',
                lambda s: 'Timestamps too far in the past seen.' in s.message,
                5.0,
                since=mark,
            )
            assert st is not None and level(st) == ERROR
            assert float(values(st)['Latest timestamp delay']) > 5.0
    finally:
        node.destroy_node()
        drv.node.destroy_node()


def _tf_static(parent, child, quat_xyzw):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    (
        t.transform.rotation.x,
        t.transform.rotation.y,
        t.transform.rotation.z,
        t.transform.rotation.w,
    ) = quat_xyzw
    return t


def test_a_static_transform_gives_the_rotation_the_gyro_prior_uses(ctx, seq):
    """
    IMU messages in "imu_link", images in FRAME_ID.

    Without a transform the IMU status warns and the parameter is used; a /tf_static chain
    base_link -> imu_link, base_link -> FRAME_ID then gives the rotation.
    """
    stamps = [int(s) for s in seq.frame_stamps_ns]
    node = _node(ctx)
    drv = Driver(ctx)
    tf_pub = drv.node.create_publisher(TFMessage, '/tf_static', TF_STATIC_QOS)
    try:
        with spinning(ctx, node, drv.node):
            assert drv.wait_connected()
            drv.publish_camera_info(seq)
            sent = _send(drv, seq, 0, 0, imu_frame='imu_link')
            drv.publish_init(seq.gt_boxes[0], stamps[0])
            sent = _send(drv, seq, 1, sent, imu_frame='imu_link')
            assert drv.wait_for(_answered(drv, stamps[1]), 10.0)
            st = drv.wait_status('imu', lambda s: 'no transform' in s.message, 5.0)
            assert (
                st is not None
                and level(st) == WARN
                and values(st)['extrinsic_source'] == 'parameter gyro.R_cam_imu'
            )
            assert node.pipeline.extrinsic[0] is ExtrinsicSource.PARAMETER
            # imu_link yawed 0.5 rad in base_link
            q_imu = (0.0, 0.0, np.sin(0.25), np.cos(0.25))
            # REP 103 optical frame in base_link
            q_cam = (-0.5, 0.5, -0.5, 0.5)
            tf_pub.publish(
                TFMessage(
                    transforms=[
                        _tf_static('base_link', 'imu_link', q_imu),
                        _tf_static('/base_link', FRAME_ID, q_cam),
                    ]
                )
            )
            expected = quat_to_rot(np.array([q_cam[3], *q_cam[:3]])).T @ quat_to_rot(
                np.array([q_imu[3], *q_imu[:3]])
            )
            for k in range(2, 8):
                sent = _send(drv, seq, k, sent, imu_frame='imu_link')
                assert drv.wait_for(_answered(drv, stamps[k]), 10.0)
                if node.pipeline.extrinsic[0] is ExtrinsicSource.TF:
                    break
            source, R = node.pipeline.extrinsic
            assert source is ExtrinsicSource.TF
            np.testing.assert_allclose(R, expected, atol=1e-9)
            assert not np.allclose(R, np.eye(3))
            st = drv.wait_status('imu', lambda s: values(s)['extrinsic_source'] == 'tf', 5.0)
            assert st is not None and 'no transform' not in st.message
    finally:
        node.destroy_node()
        drv.node.destroy_node()


def _go(node, transition: str) -> str:
    """Trigger a lifecycle transition; the state it leads to."""
    getattr(node, f'trigger_{transition}')()
    return node._state_machine.current_state[1]


def test_lifecycle_transitions(ctx, seq):
    stamps = [int(s) for s in seq.frame_stamps_ns]
    node = _node(ctx, LifecycleTrackerNode, initial_box=[float(v) for v in seq.gt_boxes[0]])
    drv = Driver(ctx)
    try:
        with spinning(ctx, node, drv.node):
            assert node._state_machine.current_state[1] == 'unconfigured'
            assert not node.count_subscribers('/image') and not hasattr(node, 'pipeline')
            assert _go(node, 'configure') == 'inactive'
            assert _wait(lambda: drv.image_pub.get_subscription_count() > 0, 10.0)
            drv.publish_camera_info(seq)
            sent = _send(drv, seq, 0, 0)
            time.sleep(0.5)
            # inactive: nothing
            assert not drv.detections and node.pipeline.state.value == 'uninitialized'
            assert _go(node, 'activate') == 'active'
            assert _wait(lambda: drv.node.count_publishers('detections') > 0, 5.0)
            for k in range(1, 4):
                sent = _send(drv, seq, k, sent)
                assert drv.wait_for(_answered(drv, stamps[k]), 10.0)
            assert drv.detections[-1].detections  # tracking from initial_box
            assert _go(node, 'deactivate') == 'inactive'
            n = len(drv.detections)
            sent = _send(drv, seq, 4, sent)
            time.sleep(0.5)
            # kept, not published
            assert len(drv.detections) == n and node.pipeline.targets == ['iemd']
            assert _go(node, 'activate') == 'active'
            sent = _send(drv, seq, 5, sent)
            assert drv.wait_for(_answered(drv, stamps[5]), 10.0) and drv.detections[-1].detections
            assert _go(node, 'deactivate') == 'inactive'
            assert _go(node, 'cleanup') == 'unconfigured'
            assert _wait(lambda: drv.image_pub.get_subscription_count() == 0, 5.0)
            assert _go(node, 'configure') == 'inactive'  # configurable again after cleanup
            assert _go(node, 'shutdown') == 'finalized'
    finally:
        node.destroy_node()
        drv.node.destroy_node()


def test_lifecycle_configure_fails_on_invalid_parameters(ctx):
    """
    The managed node starts whatever its parameters.

    Configure checks them and fails, staying unconfigured (the plain node refuses to start).
    """
    with pytest.raises(ValueError, match='initial_box'):
        _node(ctx, initial_box=[1.0, 2.0])
    node = _node(ctx, LifecycleTrackerNode, initial_box=[1.0, 2.0])
    try:
        assert _go(node, 'configure') == 'unconfigured'
        assert not hasattr(node, 'pipeline')
    finally:
        node.destroy_node()
