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
Shared helpers of the launch-free ROS tests.

Isolated DDS domain, a driver node that publishes a synthetic sequence (image + IMU + CameraInfo)
and records detections and diagnostics.
"""
from __future__ import annotations

from contextlib import contextmanager
import os
import random
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray
from iemd_ros.messages.conversions import (
    array_to_compressed_fields,
    box_to_bbox,
    compressed_topic,
    fill_bbox,
    fill_image_msg,
    ns_to_stamp,
)
from rcl_interfaces.srv import SetParameters
import rclpy
import rclpy.executors
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, QoSReliabilityPolicy
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu
from std_srvs.srv import Trigger
from vision_msgs.msg import Detection2D, Detection2DArray

FRAME_ID = 'synthetic_cam'


def stamp_header(header, t_ns: int, frame_id: str = FRAME_ID) -> None:
    """Set a std_msgs/Header to ``frame_id`` and the stamp ``t_ns``."""
    header.frame_id = frame_id
    header.stamp.sec, header.stamp.nanosec = ns_to_stamp(t_ns)


def imu_msg(t_ns: int, w, frame_id: str = FRAME_ID) -> Imu:
    """
    Return a sensor_msgs/Imu stamped ``t_ns`` with angular velocity ``w`` (3 values, rad/s).

    The synthetic gyro measures in the camera's frame, so its frame is the images' unless told.
    """
    msg = Imu()
    stamp_header(msg.header, t_ns, frame_id)
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = (float(v) for v in w)
    return msg


_ISOLATION_KEYS = ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE')


@contextmanager
def isolated_ros_env():
    """
    Yield a random ROS_DOMAIN_ID in 30..99 and localhost-only discovery.

    (restored afterwards).
    """
    saved = {k: os.environ.get(k) for k in _ISOLATION_KEYS}
    domain = random.SystemRandom().randint(30, 99)
    os.environ['ROS_DOMAIN_ID'] = str(domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    try:
        yield domain
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def child_env(base) -> dict:
    """
    Return ``base`` with the domain and discovery range of the enclosing ROS environment.

    That is isolated_ros_env / ros_context, for a child process that must meet the test's nodes.
    """
    return {**base, **{k: os.environ[k] for k in _ISOLATION_KEYS}}


@contextmanager
def ros_context():
    """
    Yield an rclpy context on an isolated domain (see isolated_ros_env).

    Shut down afterwards.
    """
    with isolated_ros_env() as domain:
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=domain)
        try:
            yield context
        finally:
            rclpy.try_shutdown(context=context)


def level(status) -> int:
    lv = status.level
    return lv[0] if isinstance(lv, (bytes, bytearray)) else int(lv)


class Driver:
    """
    Test node: publishes image/imu/camera_info, ~/init; calls ~/reset and set_parameters.

    Records detections and diagnostics of the tracker node ``tracker``.
    """

    def __init__(
        self,
        context,
        tracker: str = 'iemd_tracker',
        image_topic: str = 'image',
        reliable: bool = True,
        compressed: str | None = None,
    ):
        """
        ``compressed`` ("png" or "jpeg").

        Publish the frames as CompressedImage on ``<image_topic>/compressed``.
        """
        self.node = rclpy.create_node('iemd_test_driver', context=context)
        rel = QoSReliabilityPolicy.RELIABLE if reliable else QoSReliabilityPolicy.BEST_EFFORT
        n = self.node
        self.compressed = compressed
        image_qos = QoSProfile(depth=10, reliability=rel)
        self.image_pub = (
            n.create_publisher(CompressedImage, compressed_topic(image_topic), image_qos)
            if compressed
            else n.create_publisher(Image, image_topic, image_qos)
        )
        self.imu_pub = n.create_publisher(Imu, 'imu', QoSProfile(depth=200, reliability=rel))
        self.info_pub = n.create_publisher(
            CameraInfo, 'camera_info', QoSProfile(depth=10, reliability=rel)
        )
        self.init_pub = n.create_publisher(Detection2D, f'/{tracker}/init', 10)
        self.reset_cli = n.create_client(Trigger, f'/{tracker}/reset')
        self.param_cli = n.create_client(SetParameters, f'/{tracker}/set_parameters')
        self.tracker = tracker
        self.cond = threading.Condition()
        self.detections: list[Detection2DArray] = []
        self.diagnostics: list[DiagnosticArray] = []
        n.create_subscription(
            Detection2DArray, 'detections', lambda m: self._record(self.detections, m), 100
        )
        n.create_subscription(
            DiagnosticArray, '/diagnostics', lambda m: self._record(self.diagnostics, m), 100
        )

    def _record(self, received: list, msg) -> None:
        with self.cond:
            received.append(msg)
            self.cond.notify_all()

    def wait_for(self, predicate, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        with self.cond:
            while not predicate():
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self.cond.wait(min(remaining, 0.05))
            return True

    def wait_connected(self, timeout: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if (
                self.image_pub.get_subscription_count()
                and self.imu_pub.get_subscription_count()
                and self.info_pub.get_subscription_count()
                and self.init_pub.get_subscription_count()
                and self.node.count_publishers('detections')
                and self.reset_cli.service_is_ready()
                and self.param_cli.service_is_ready()
            ):
                return True
            time.sleep(0.05)
        return False

    # ---------------------------------------------------------------- publishing
    def publish_image(self, frame, t_ns: int, **override) -> None:
        msg = (
            CompressedImage(**array_to_compressed_fields(frame, self.compressed))
            if self.compressed
            else fill_image_msg(Image(), frame)
        )
        stamp_header(msg.header, t_ns)
        for name, value in override.items():  # a malformed message on purpose
            setattr(msg, name, value)
        self.image_pub.publish(msg)

    def publish_imu(self, t_ns: int, w, frame_id: str = FRAME_ID) -> None:
        self.imu_pub.publish(imu_msg(t_ns, w, frame_id))

    def publish_imu_until(
        self, seq, t_cam_ns: int, sent: int = 0, frame_id: str = FRAME_ID
    ) -> int:
        """
        Publish ``seq``'s gyro samples from index ``sent`` as a real IMU stream would.

        Up to the IMU time of the frame stamped ``t_cam_ns`` (+5 ms); returns the index of the next
        sample.
        """
        t_imu = t_cam_ns + seq.time_offset_ns + 5_000_000
        while sent < len(seq.gyro_t_ns) and seq.gyro_t_ns[sent] <= t_imu:
            self.publish_imu(int(seq.gyro_t_ns[sent]), seq.gyro[sent], frame_id)
            sent += 1
        return sent

    def publish_camera_info(self, seq, k=None) -> None:
        msg = CameraInfo()
        msg.header.frame_id = FRAME_ID
        msg.width, msg.height = seq.config.width, seq.config.height
        msg.k = [float(v) for v in (seq.K.ravel() if k is None else k)]
        msg.d = [float(v) for v in seq.dist]
        msg.distortion_model = 'plumb_bob'
        self.info_pub.publish(msg)

    def publish_init(self, box, t_ns: int, target_id: str = '') -> None:
        msg = Detection2D()
        stamp_header(msg.header, t_ns)
        fill_bbox(msg.bbox, box_to_bbox(box))
        msg.id = target_id
        self.init_pub.publish(msg)

    # ---------------------------------------------------------------- services
    def _call(self, client, request, timeout: float = 10.0):
        future = client.call_async(request)
        deadline = time.monotonic() + timeout
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.01)
        assert future.done(), f'service {client.srv_name} did not answer within {timeout} s'
        return future.result()

    def reset(self):
        return self._call(self.reset_cli, Trigger.Request())

    def set_parameters(self, **values):
        return self.set_parameters_raw([Parameter(k, value=v) for k, v in values.items()])

    def set_parameters_raw(self, parameters):
        """
        Send rclpy ``Parameter`` objects as they are.

        (e.g. of type NOT_SET: ``ros2 param delete``).
        """
        req = SetParameters.Request()
        req.parameters = [p.to_parameter_msg() for p in parameters]
        return self._call(self.param_cli, req).results

    # ---------------------------------------------------------------- queries
    def statuses(self, since: int = 0) -> list[dict]:
        """
        Latest statuses of the tracker by kind.

        ("tracking", "image input", "imu", "camera_info").
        """
        with self.cond:
            arrays = list(self.diagnostics[since:])
        out = []
        for arr in arrays:
            d = {}
            for st in arr.status:
                if st.name.startswith(f'{self.tracker}: '):
                    d[st.name.split(': ', 1)[1]] = st
            if d:
                out.append(d)
        return out

    def diagnostics_mark(self) -> int:
        """Return the count of diagnostics arrays received so far (a ``since`` for wait_status)."""
        with self.cond:
            return len(self.diagnostics)

    def wait_status(self, kind: str, predicate, timeout: float = 5.0, since: int | None = None):
        """
        First diagnostics status of ``kind`` satisfying ``predicate``, or None.

        Among the arrays received from :meth:`diagnostics_mark`'s ``since`` on (default: from now
        on): a status that covers a window of events (a topic's stamp ages) may be published
        between the events and this call.
        """
        start = self.diagnostics_mark() if since is None else since
        found = []

        def check():
            for d in self.statuses(start):
                if kind in d and predicate(d[kind]):
                    found.append(d[kind])
                    return True
            return False

        # statuses() takes the lock itself; poll outside it
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if check():
                return found[0]
            time.sleep(0.05)
        return None

    def detections_since(self, start: int) -> list[Detection2DArray]:
        with self.cond:
            return list(self.detections[start:])


def values(status) -> dict:
    return {kv.key: kv.value for kv in status.values}


@contextmanager
def spinning(context, *nodes):
    """Spin ``nodes`` in a background executor thread."""
    ex = rclpy.executors.SingleThreadedExecutor(context=context)
    for n in nodes:
        ex.add_node(n)
    th = threading.Thread(target=ex.spin, daemon=True)
    th.start()
    try:
        yield ex
    finally:
        ex.shutdown(timeout_sec=2.0)
        th.join(timeout=5.0)
