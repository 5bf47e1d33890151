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
``ros2 run iemd_ros tracker``: the iEMD tracker as a ROS 2 node (a thin adapter over the pipeline).

Topics (relative names, remap with ``-r image:=/camera/image_raw`` ...):

* subscribes ``image`` (sensor_msgs/Image: mono8, mono16, bgr8, rgb8, bgra8, rgba8; with
  ``image_transport`` "compressed": sensor_msgs/CompressedImage on ``<image>/compressed``, jpeg or
  png as image_transport's compressed plugin publishes them; ``image`` remapped to a compressed
  stream itself is taken as it is), ``imu`` (sensor_msgs/Imu, angular velocity in the IMU frame),
  ``camera_info`` (sensor_msgs/CameraInfo: K, plumb_bob D); sensor-data QoS (best effort) unless
  ``reliable_qos`` is true.
* publishes ``detections`` (vision_msgs/Detection2DArray, the image's header, one Detection2D per
  tracked target with the target's id, empty when none is tracked), ``bearings``
  (vision_msgs/Detection3DArray in the image's optical frame: the unit ray to each target and its
  angular size, :func:`~iemd_ros.messages.outputs.bearing_array`), ``~/annotations``
  (foxglove_msgs/ImageAnnotations: the boxes Foxglove's Image panel draws over the image),
  ``/diagnostics`` (diagnostic_msgs/DiagnosticArray), ``~/debug_image`` (annotated bgr8) and
  ``~/debug_image/compressed`` (the same as JPEG), both drawn only while somebody subscribes, and
  ``~/lost`` (std_msgs/Bool with every answered frame: true while every target is lost, the cue for
  a detector to send ``~/init``; /diagnostics says for how long).
* targets: parameter ``initial_box`` [x, y, w, h] (the target ``detection_id``, applied to the next
  frame), topic ``~/init`` (vision_msgs/Detection2D: adds the target of its ``id``, or restarts the
  one with that id; an empty id is ``detection_id``; its header stamp picks the frame from a ring
  buffer of recent frames, a zero stamp means the newest frame), topic ``~/drop`` (std_msgs/String:
  forget the target of that id), service ``~/reset`` (std_srvs/Trigger: forget every target;
  restart from ``initial_box`` if it is set).
* extrinsics: the camera-IMU rotation is looked up in TF between the IMU message's frame and the
  image's frame (:class:`~iemd_ros.ros.extrinsics.TfExtrinsics`), ``gyro.R_cam_imu`` when no
  transform is known.

:class:`TrackerNode` starts at once; :class:`LifecycleTrackerNode` (``ros2 run iemd_ros
tracker_lifecycle``) is the managed variant: configure creates the pipeline, subscriptions and
publishers, activate starts tracking and publishing, deactivate stops both (the target and the IMU
buffer are kept), cleanup destroys them.

Parameters: :mod:`iemd_ros.ros.parameters` (docs/parameters.md).

Processing model: the image callback only stores the message in a single-slot "latest frame" buffer
(and in the ring buffer for ``~/init``); a worker thread takes the newest frame, lets it wait for
the gyro as :class:`~iemd_ros.pipeline.ImuWait` says, converts it, tracks it and publishes.  A
frame that is replaced in the slot before the worker took it is stale: it is dropped and counted
(no backlog ever builds up).  Malformed messages are logged (throttled) and explained in
/diagnostics; they never stop the node.
"""
from __future__ import annotations

from collections import deque
import enum
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray
from foxglove_msgs.msg import ImageAnnotations
from iemd_ros.common.boxes import check_box
from iemd_ros.common.cli import one_line
from iemd_ros.messages.conversions import (
    array_to_compressed_fields,
    bbox_to_box,
    bbox_values,
    camera_model_from_msg,
    compressed_topic,
    fill_image_msg,
    image_from_msg,
    imu_sample,
    is_compressed_topic,
    raw_twin,
    stamp_ns,
)
from iemd_ros.messages.outputs import (
    bearing_array,
    detection_array,
    diagnostic_array,
    header,
    image_annotations,
)
from iemd_ros.pipeline import (
    FrameResult,
    ImuWait,
    Level,
    Part,
    PipelineConfig,
    TrackingPipeline,
    TrackState,
)
from iemd_ros.pipeline.drawing import box_colour, draw_results
from iemd_ros.pipeline.pipeline import kernel_cache_dir, kernels_cached
from iemd_ros.pipeline.topic_status import TopicStatus
from iemd_ros.ros.extrinsics import TfExtrinsics
from iemd_ros.ros.messages import RCLPY_MESSAGES
from iemd_ros.ros.parameters import descriptor, ImageTransport, NODE_NAME, NodeConfig, parameters
from iemd_ros.ros.spin import quiet_interrupts, spin_until_shutdown, stopped_by_shutdown
import numpy as np
from rcl_interfaces.msg import SetParametersResult
import rclpy
from rclpy.exceptions import ParameterException
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.parameter import Parameter as RclpyParameter
from rclpy.qos import qos_profile_sensor_data, QoSProfile, QoSReliabilityPolicy
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu
from std_msgs.msg import Bool, String
from std_srvs.srv import Trigger
from vision_msgs.msg import Detection2D, Detection2DArray, Detection3DArray

__all__ = ['TrackerNode', 'LifecycleTrackerNode', 'main', 'main_lifecycle', 'NODE_NAME']


class Note(enum.Enum):
    """What the node itself has to say in the tracking status, besides the pipeline."""

    INIT = 'init'                      # an ~/init or initial_box that could not be used
    # an exception in the worker (a bug): ERROR until the next good frame
    INTERNAL_ERROR = 'internal error'
    # an INIT note is a WARN while tracking (the previous target stays) until the next init or
    # ~/reset


class _Op(enum.Enum):
    """Requests for the worker thread."""

    CONFIG = 'config'
    RESET = 'reset'
    INIT = 'init'
    DROP = 'drop'


class _Tracker:
    """
    What the plain and the managed node share.

    Mixed into a :class:`rclpy.node.Node` (see the module docstring).

    :meth:`_declare` declares the parameters (at construction), :meth:`_start` builds the pipeline,
    subscriptions, publishers and the worker, :meth:`_shut` takes them down; :attr:`_active` gates
    tracking and publishing.
    """

    def _declare(self) -> None:
        self._declared = parameters()
        for p in self._declared:
            self.declare_parameter(p.name, p.default, descriptor(p))
        self._started = False
        self._active = False
        self.add_on_set_parameters_callback(self._on_set_parameters)

    def _start(self, make_publisher) -> None:
        """
        Build everything from the current parameters.

        ``make_publisher`` creates the output publishers (the managed node's are lifecycle
        publishers).  ValueError for invalid parameters.
        """
        values = self._values({})
        # ValueError: invalid parameter file / overrides
        cfg = PipelineConfig.from_parameters(values)
        node = NodeConfig.from_parameters(values)
        self._node_cfg = node
        self._initial_box = self._check_initial_box(node.initial_box)
        if not kernels_cached():
            self.get_logger().warning(
                f"compiling the tracker's numba kernels into {kernel_cache_dir()} (10-30 s, once "
                'per install: '
                f'`iemd-compile` at install time avoids this wait)'
            )
        self.pipeline = TrackingPipeline(cfg)
        self._wait = ImuWait(self.pipeline)

        self._cond = threading.Condition()
        # single-slot buffer of the newest frame
        self._latest: Image | CompressedImage | None = None
        self._ring: deque = deque(maxlen=node.frame_buffer_size)  # recent frames for ~/init
        self._ops: list = []  # requests for the worker (_Op, ...)
        self._pending_box = self._initial_box  # initial_box to apply to the next frame
        self._latest_received = None
        # stamp of the frame the worker holds for IMU coverage
        self._awaiting_imu: int | None = None
        self._stop = False
        # (monotonic start, stamp) of the frame the worker is on
        self._busy: tuple[float, int] | None = None
        self._note: tuple[Note, str] | None = None  # the latest init problem / internal error
        self._last_image_wall = self._last_imu_wall = None
        self._imu_frame = ''
        self._latency_ms: deque = deque(maxlen=30)
        self._start_wall = time.monotonic()
        self._output_status = TopicStatus(
            node.min_rate_hz,
            node.max_rate_hz,
            node.rate_tolerance,
            node.rate_window,
            node.stamp_age_min_s,
            node.stamp_age_max_s,
            self._start_wall,
        )
        if node.reliable_qos:
            sensor_qos = QoSProfile(depth=5, reliability=QoSReliabilityPolicy.RELIABLE)
            imu_qos = QoSProfile(depth=200, reliability=QoSReliabilityPolicy.RELIABLE)
        else:
            sensor_qos = qos_profile_sensor_data
            imu_qos = QoSProfile(depth=200, reliability=QoSReliabilityPolicy.BEST_EFFORT)
        self._det_pub = make_publisher(Detection2DArray, 'detections', 10)
        self._bearing_pub = make_publisher(Detection3DArray, 'bearings', 10)
        self._annotation_pub = make_publisher(ImageAnnotations, '~/annotations', 10)
        self._debug_pub = make_publisher(Image, '~/debug_image', 1)
        self._debug_jpeg_pub = make_publisher(CompressedImage, '~/debug_image/compressed', 1)
        self._lost_pub = make_publisher(Bool, '~/lost', 10)
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        image_sub = self._subscribe_image(node.image_transport, sensor_qos)
        self._image_topic = image_sub.topic_name  # after remapping
        self._entities = [
            image_sub,
            self._diag_pub,
            self.create_subscription(Imu, 'imu', self._on_imu, imu_qos),
            self.create_subscription(CameraInfo, 'camera_info', self._on_camera_info, sensor_qos),
            self.create_subscription(Detection2D, '~/init', self._on_init, 10),
            self.create_subscription(String, '~/drop', self._on_drop, 10),
            self.create_service(Trigger, '~/reset', self._on_reset),
            self.create_timer(node.diagnostics_period_s, self._publish_diagnostics),
        ]
        self._outputs = [
            self._det_pub,
            self._bearing_pub,
            self._annotation_pub,
            self._debug_pub,
            self._debug_jpeg_pub,
            self._lost_pub,
        ]
        self._extrinsics = TfExtrinsics(self, self._warn)

        self._worker = threading.Thread(target=self._work, name='iemd_tracker_worker', daemon=True)
        self._worker.start()
        self._started = True
        self.get_logger().info(
            f"tracking '{self._image_topic}' -> '{self.resolve_topic_name('detections')}' "
            f'(gyro {"on" if cfg.use_gyro else "off"}, '
            f'{"reliable" if node.reliable_qos else "sensor-data"} '
            f'QoS, camera-IMU rotation from {self._extrinsics.backend} or gyro.R_cam_imu); '
            + ('initial box ' + str(self._initial_box) if self._initial_box
               else 'waiting for ~/init')
        )

    def _shut(self, destroy_publisher) -> None:
        """
        Stop the worker and destroy what :meth:`_start` built.

        (``destroy_publisher`` for the outputs).
        """
        if not self._started:
            return
        self._active = False
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if self._worker.is_alive() and threading.current_thread() is not self._worker:
            self._worker.join(timeout=5.0)
        self._extrinsics.close()
        for pub in self._outputs:
            destroy_publisher(pub)
        for entity in self._entities:
            kind = type(entity).__name__
            {
                'Subscription': self.destroy_subscription,
                'Publisher': self.destroy_publisher,
                'Service': self.destroy_service,
                'Timer': self.destroy_timer,
            }[kind](entity)
        self._started = False

    # ------------------------------------------------------------------ parameters
    def _subscribe_image(self, transport: ImageTransport, qos):
        """
        Return the image subscription.  image_transport's naming.

        The compressed stream of the (remapped) image topic is <image>/compressed.  An image topic
        remapped to a compressed stream itself is taken as it is with the compressed transport (not
        <image>/compressed/compressed), and warned about with the raw one (an Image subscription
        there would never match the publisher's type).
        """
        image_topic = self.resolve_topic_name('image')
        compressed_name = is_compressed_topic(image_topic)
        if transport is ImageTransport.COMPRESSED:
            if compressed_name:
                self.get_logger().warning(
                    f'image is remapped to {image_topic}, a compressed stream: subscribing to '
                    f"it (image_transport's convention is image:={raw_twin(image_topic)})"
                )
            topic = image_topic if compressed_name else compressed_topic(image_topic)
            return self.create_subscription(CompressedImage, topic, self._on_image, qos)
        if compressed_name:
            self.get_logger().warning(
                f'image is remapped to {image_topic}, which looks like a compressed stream; '
                f"for sensor_msgs/CompressedImage set image_transport to 'compressed'"
            )
        return self.create_subscription(Image, 'image', self._on_image, qos)

    def _values(self, overrides: dict) -> dict:
        return {
            p.name: overrides[p.name] if p.name in overrides else self.get_parameter(p.name).value
            for p in self._declared
        }

    @staticmethod
    def _check_initial_box(value):
        box = list(value) if value is not None else []
        if not box:
            return None
        return check_box(box, 'initial_box ([] for none)')

    def _on_set_parameters(self, params) -> SetParametersResult:
        deleted = [p.name for p in params if p.type_ == RclpyParameter.Type.NOT_SET]
        if deleted:  # `ros2 param delete`: every later change would fail on the missing parameter
            return SetParametersResult(
                successful=False,
                reason=f'parameters cannot be deleted: {", ".join(deleted)} '
                f'(initial_box takes [] for none)',
            )
        changes = {p.name: p.value for p in params}
        try:
            values = self._values(changes)
            cfg = PipelineConfig.from_parameters(values)
            node = NodeConfig.from_parameters(values)
            box = self._check_initial_box(node.initial_box) if 'initial_box' in changes else None
        except (ValueError, TypeError) as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        if not self._started:  # the managed node before configure: taken then
            return SetParametersResult(successful=True)
        node_only = {p.name for p in self._declared if p.node_only}
        with self._cond:
            self._node_cfg = node
            self._output_status.configure(
                node.min_rate_hz,
                node.max_rate_hz,
                node.rate_tolerance,
                node.rate_window,
                node.stamp_age_min_s,
                node.stamp_age_max_s,
            )
            if any(name not in node_only for name in changes):
                self._ops.append((_Op.CONFIG, cfg))
            if 'initial_box' in changes:
                self._initial_box = self._pending_box = box
            self._cond.notify_all()
        return SetParametersResult(successful=True)

    # ------------------------------------------------------------------ callbacks (fast)
    def _on_image(self, msg: Image | CompressedImage) -> None:
        if not self._active:
            return
        now = time.monotonic()
        self._last_image_wall = now
        with self._cond:
            self._ring.append(msg)
            if self._latest is not None:
                self.pipeline.note_dropped(stamp_ns(self._latest.header))
            self._latest = msg
            self._latest_received = now
            self._cond.notify_all()

    def _on_imu(self, msg: Imu) -> None:
        self._last_imu_wall = time.monotonic()
        self._imu_frame = msg.header.frame_id
        if not self.pipeline.add_imu_message(*imu_sample(msg)):
            self._warn(self.pipeline.last_reasons()['imu_reason'])
        # Wake the worker only when this sample lets the frame it holds go.  No race: the sample is
        # stored before the lock is taken here, and the worker sets _awaiting_imu and checks
        # readiness under the lock before it waits, so either it sees the sample or we see it
        # waiting.
        with self._cond:
            if self._awaiting_imu is not None and self._wait.ready(self._awaiting_imu):
                self._cond.notify_all()

    def _on_camera_info(self, msg: CameraInfo) -> None:
        try:
            camera = camera_model_from_msg(msg)
        except ValueError as exc:
            self.pipeline.note_bad_camera_info(str(exc))
            self._warn(f'camera_info rejected: {exc}')
            return
        if self.pipeline.set_camera(camera):
            self.get_logger().info(f'camera model: {camera!r}')

    def _on_init(self, msg: Detection2D) -> None:
        try:
            box = bbox_to_box(*bbox_values(msg.bbox))
        except ValueError as exc:
            self._set_note(Note.INIT, f'~/init rejected: {exc}')
            return
        target = msg.id or self._node_cfg.detection_id
        with self._cond:
            self._ops.append((_Op.INIT, box, stamp_ns(msg.header), target))
            if target == self._node_cfg.detection_id:
                self._pending_box = None
            self._cond.notify_all()

    def _on_drop(self, msg: String) -> None:
        with self._cond:
            self._ops.append((_Op.DROP, msg.data))
            self._cond.notify_all()

    def _on_reset(self, request, response):
        with self._cond:
            self._ops.append((_Op.RESET,))
            self._pending_box = self._initial_box
            self._cond.notify_all()
        response.success = True
        response.message = (
            'targets cleared; restarting from initial_box on the next frame'
            if self._initial_box is not None
            else 'targets cleared; waiting for ~/init'
        )
        return response

    def _warn(self, text: str) -> None:
        self.get_logger().warning(text, throttle_duration_sec=5.0)

    def _set_note(self, kind: Note, text: str) -> None:
        self._note = (kind, text)
        if kind is Note.INTERNAL_ERROR:
            self.get_logger().error(text, throttle_duration_sec=5.0)
        else:
            self._warn(text)

    # ------------------------------------------------------------------ worker thread
    def _work(self) -> None:
        while True:
            with self._cond:
                self._cond.wait_for(lambda: self._stop or self._latest is not None or self._ops)
                if self._stop:
                    return
                ops, self._ops = self._ops, []
                msg, self._latest = self._latest, None
                received = self._latest_received
            try:
                for op in ops:
                    self._apply(op)
            # a bug must not kill the worker; say so in the log and /diagnostics
            except Exception as exc:
                if self._internal_error(exc):
                    return
            if msg is None:
                continue
            self._busy = (time.monotonic(), stamp_ns(msg.header))
            try:
                self._handle_frame(msg, received)
            except Exception as exc:
                if self._internal_error(exc):
                    return
                # the frame is answered all the same: no detection
                self._publish(msg, [], received)
            finally:
                self._busy = None

    def _internal_error(self, exc: Exception) -> bool:
        """
        Note an exception of the worker (a bug) in the log and /diagnostics.

        True when the node is stopping.
        """
        if self._stop or not self.context.ok():
            return True
        self._set_note(Note.INTERNAL_ERROR, f'internal error: {type(exc).__name__}: {exc}')
        return False

    def _apply(self, op) -> None:
        kind = op[0]
        if kind is _Op.CONFIG:
            what = self.pipeline.configure(op[1])
            self.get_logger().info(f'parameters applied: {what}')
        elif kind is _Op.RESET:
            self.pipeline.reset()
            self._note = None
        elif kind is _Op.INIT:
            self._init_from_ring(*op[1:])
        elif kind is _Op.DROP:
            if self.pipeline.drop(op[1]):
                self.get_logger().info(f"target '{op[1]}' dropped")
            else:
                self._warn(
                    f"~/drop: no target '{op[1]}' (targets: "
                    f'{", ".join(self.pipeline.targets) or "none"})'
                )

    def _init_from_ring(self, box, stamp: int, target: str) -> None:
        with self._cond:
            frames = list(self._ring)
        if not frames:
            self._set_note(Note.INIT, '~/init ignored: no frame received yet')
            return
        tolerance_ns = int(self._node_cfg.init_tolerance_ms * 1e6)
        stamps = np.array([stamp_ns(m.header) for m in frames])
        i = len(frames) - 1 if stamp == 0 else int(np.argmin(np.abs(stamps - stamp)))
        if stamp != 0 and abs(int(stamps[i]) - stamp) > tolerance_ns:
            self._set_note(
                Note.INIT,
                f'~/init ignored: no buffered frame within {tolerance_ns / 1e6:.0f} ms of its '
                f'stamp {stamp} ns (buffer spans {stamps.min()}..{stamps.max()} ns)',
            )
            return
        try:
            self.pipeline.init(image_from_msg(frames[i]), box, int(stamps[i]), target)
        except ValueError as exc:
            self._set_note(Note.INIT, f'~/init failed: {exc}')
            return
        self._note = None
        self.get_logger().info(
            f"target '{target}' initialized from ~/init at {box} on the frame stamped "
            f'{int(stamps[i])} ns'
        )

    def _handle_frame(self, msg: Image | CompressedImage, received) -> None:
        stamp = stamp_ns(msg.header)
        try:
            frame = image_from_msg(msg)
        except ValueError as exc:
            self._warn(f'image rejected: {exc}')
            self._publish(msg, [self.pipeline.note_bad_image(str(exc), stamp)], received)
            return
        self._update_extrinsic(msg.header.frame_id)
        # initial_box (startup, parameter change, ~/reset): this frame
        with self._cond:
            pending_box, self._pending_box = self._pending_box, None
        if pending_box is not None:
            results = self._init_on_frame(frame, pending_box, stamp)
            if results is None:
                self._publish(msg, [], received)
                return
        else:
            self._wait_for_gyro(stamp)
            results = self.pipeline.process_all(frame, stamp)
        if self._note is not None and self._note[0] is Note.INTERNAL_ERROR:
            self._note = None  # a good frame clears it
        self._publish(msg, results, received)
        self._publish_debug(msg, frame, results)

    def _init_on_frame(self, frame, box, stamp: int) -> list[FrameResult] | None:
        """
        initial_box on this frame (the target ``detection_id``).

        After tracking the other targets into it; None when the box cannot be used.
        """
        target = self._node_cfg.detection_id
        others = [t for t in self.pipeline.targets if t != target]
        results = []
        if others:
            self._wait_for_gyro(stamp)
            results = [r for r in self.pipeline.process_all(frame, stamp) if r.target_id != target]
        try:
            results.append(self.pipeline.init(frame, box, stamp, target))
        except ValueError as exc:
            self._set_note(Note.INIT, f'initial_box not usable: {exc}')
            return None
        self._note = None
        self.get_logger().info(f"target '{target}' initialized at {box}")
        return results

    def _update_extrinsic(self, camera_frame: str) -> None:
        """
        Update the camera-IMU rotation from TF.

        It is the rotation between the latest IMU message's frame and this image's frame (the
        parameter when the frames are one, unnamed, or no transform is known).
        """
        imu_frame = self._imu_frame
        R = None
        if imu_frame and camera_frame and imu_frame.lstrip('/') != camera_frame.lstrip('/'):
            R = self._extrinsics.rotation(camera_frame, imu_frame)
        try:
            changed = self.pipeline.set_extrinsic(R, imu_frame, camera_frame)
        except ValueError as exc:
            self._warn(f'transform {imu_frame} -> {camera_frame} not used: {exc}')
            return
        if changed:
            self.get_logger().info(
                'camera-IMU rotation: '
                f'{"from TF" if R is not None else "gyro.R_cam_imu (no transform known)"} '
                f'({imu_frame} -> {camera_frame}): '
                f'{np.round(self.pipeline.extrinsic[1], 6).tolist()}'
            )

    def _wait_for_gyro(self, stamp: int) -> None:
        """
        Hold the frame stamped ``stamp`` until the gyro covers it or it has waited its longest.

        (ImuWait).
        """
        arrival = time.monotonic_ns()
        with self._cond:
            self._awaiting_imu = stamp
            while not self._stop and not self._wait.ready(stamp):
                now = time.monotonic_ns()
                if self._wait.waited_out(arrival, now):
                    break
                self._cond.wait(max(self._wait.remaining_s(arrival, now), 0.0))
            self._awaiting_imu = None

    # ------------------------------------------------------------------ output
    def _publish(self, img: Image | CompressedImage, results: list, received) -> None:
        """
        Publish the image's Detection2DArray (one detection per tracked target).

        Also its bearings and annotations.
        """
        cfg = self._node_cfg
        results = [r for r in results if r is not None]
        if self._stop or not self._active or not self.context.ok():
            return
        # the detections first: their latency is the node's
        self._det_pub.publish(
            detection_array(RCLPY_MESSAGES, img.header, results, cfg.class_id, cfg.detection_id)
        )
        # what a detector acts on
        self._lost_pub.publish(Bool(data=self.pipeline.state is TrackState.LOST))
        self._bearing_pub.publish(
            bearing_array(
                RCLPY_MESSAGES,
                img.header,
                results,
                self.pipeline.camera,
                cfg.class_id,
                cfg.detection_id,
            )
        )
        self._annotation_pub.publish(
            image_annotations(
                RCLPY_MESSAGES, stamp_ns(img.header), results, cfg.detection_id, box_colour
            )
        )
        self._output_status.tick(
            time.monotonic(),
            (self.get_clock().now().nanoseconds - stamp_ns(img.header)) / 1e9,
            stamp_ns(img.header) == 0,
        )
        if received is not None:
            self._latency_ms.append((time.monotonic() - received) * 1e3)

    def _publish_debug(
        self, img: Image | CompressedImage, frame: np.ndarray, results: list
    ) -> None:
        raw, jpeg = (
            pub.get_subscription_count() > 0 for pub in (self._debug_pub, self._debug_jpeg_pub)
        )
        if not (raw or jpeg) or self._stop:
            return
        drawn = draw_results(frame, results)
        if raw:
            out = fill_image_msg(Image(), drawn)
            out.header = img.header
        if jpeg:
            compressed = CompressedImage(
                header=img.header, **array_to_compressed_fields(drawn, 'jpeg')
            )
        if self.context.ok() and self._active:
            if raw:
                self._debug_pub.publish(out)
            if jpeg:
                self._debug_jpeg_pub.publish(compressed)

    def diagnostic_statuses(self) -> list[tuple[str, Level, str, dict]]:
        """
        Return the pipeline's statuses with the node's wall-clock liveness checks and notes.

        And the detections' rate and stamp-age status: (name, level, message, values) tuples.
        """
        now = time.monotonic()
        timeout = self._node_cfg.input_timeout_s
        stuck = self._stuck(now)
        out = []
        for s in self.pipeline.statuses():
            level, message, values = s.level, s.message, dict(s.values)
            if s.part is Part.IMAGE:
                since = now - (self._last_image_wall or self._start_wall)
                values['latency_ms_mean'] = (
                    f'{np.mean(self._latency_ms):.1f}' if self._latency_ms else 'nan'
                )
                values['topic'] = self._image_topic
                if since > timeout and level < Level.ERROR:
                    note = (
                        f'no image on {values["topic"]} for {since:.1f} s'
                        if self._last_image_wall
                        else f'no image received on {values["topic"]} yet'
                    )
                    message = (
                        note
                        if level == Level.OK or not self._last_image_wall
                        else f'{message}; {note}'
                    )
                    level = Level.WARN
            elif s.part is Part.IMU and self.pipeline.config.use_gyro and level < Level.ERROR:
                since = now - (self._last_imu_wall or self._start_wall)
                values['tf_backend'] = self._extrinsics.backend
                if since > timeout:
                    topic = self.resolve_topic_name('imu')
                    note = (
                        f'no IMU message on {topic} for {since:.1f} s'
                        if self._last_imu_wall
                        else f'no IMU message received on {topic}: tracking without gyro'
                    )
                    message = note if level == Level.OK else f'{message}; {note}'
                    level = Level.WARN
            elif s.part is Part.TRACKING and stuck:
                level, message = Level.ERROR, stuck
            elif s.part is Part.TRACKING and self._note is not None:
                kind, text = self._note
                values['note'] = text
                if kind is Note.INTERNAL_ERROR:
                    level, message = Level.ERROR, text
                elif self.pipeline.state is TrackState.UNINITIALIZED:
                    message = f'{message} ({text})'
                # an ~/init that could not be used: the old target stays
                else:
                    level, message = max(level, Level.WARN), f'{message}; {text}'
            out.append((s.name(self.get_name()), level, message, values))
        if self._active:
            level, message, values = self._output_status.status(now)
            values['topic'] = self.resolve_topic_name('detections')
            out.append((f'{self.get_name()}: {Part.OUTPUT.value}', level, message, values))
        return out

    def _stuck(self, now: float) -> str:
        """
        Why the worker looks stuck ("" when it does not).

        On one frame for longer than its IMU wait and two watchdog periods (the tracker update has
        its own watchdog; this catches the rest of the frame's path).
        """
        busy = self._busy
        if busy is None:
            return ''
        cfg = self.pipeline.config
        since = now - busy[0]
        if since <= (cfg.imu_wait_ms + 2 * cfg.watchdog_ms) / 1e3:
            return ''
        return (f'the tracking worker has been on the frame stamped {busy[1]} ns for {since:.1f} '
                's (stuck?)')

    def _publish_diagnostics(self) -> None:
        hdr = header(RCLPY_MESSAGES, self.get_clock().now().nanoseconds, '')
        self._diag_pub.publish(
            diagnostic_array(
                RCLPY_MESSAGES, hdr, self.diagnostic_statuses(), self.get_fully_qualified_name()
            )
        )


class TrackerNode(_Tracker, Node):
    """
    The iEMD tracker node, tracking from its start.

    (see the module docstring for topics, parameters, threading).

    Raises
    ------
    ValueError
        For invalid parameters.

    """

    def __init__(self, node_name: str = NODE_NAME, **kwargs):
        super().__init__(node_name, **kwargs)
        self._declare()
        self._start(self.create_publisher)
        self._active = True

    def destroy_node(self):
        self._shut(self.destroy_publisher)
        return super().destroy_node()


class LifecycleTrackerNode(_Tracker, LifecycleNode):
    """
    The managed iEMD tracker node (``ros2 run iemd_ros tracker_lifecycle``; REP 2000's lifecycle).

    unconfigured -> configure (parameters checked, pipeline, subscriptions, publishers and the
    worker built; FAILURE with the reason for invalid parameters) -> inactive -> activate (images
    are tracked and the outputs published) -> active; deactivate stops tracking and publishing,
    keeping the targets and the IMU buffer; cleanup destroys what configure built; shutdown from
    any state.  /diagnostics is published from configure on.
    """

    def __init__(self, node_name: str = NODE_NAME, **kwargs):
        super().__init__(node_name, **kwargs)
        self._declare()

    def on_configure(self, state) -> TransitionCallbackReturn:
        try:
            self._start(self.create_lifecycle_publisher)
        except (ValueError, ParameterException) as exc:
            self.get_logger().error(f'configure failed: invalid parameters: {one_line(exc)}')
            return TransitionCallbackReturn.FAILURE
        return super().on_configure(state)

    def on_activate(self, state) -> TransitionCallbackReturn:
        ret = super().on_activate(state)
        self._active = ret == TransitionCallbackReturn.SUCCESS
        return ret

    def on_deactivate(self, state) -> TransitionCallbackReturn:
        self._active = False
        return super().on_deactivate(state)

    def on_cleanup(self, state) -> TransitionCallbackReturn:
        self._shut(self.destroy_lifecycle_publisher)
        return super().on_cleanup(state)

    def on_shutdown(self, state) -> TransitionCallbackReturn:
        self._shut(self.destroy_lifecycle_publisher)
        return super().on_shutdown(state)

    def destroy_node(self):
        self._shut(self.destroy_lifecycle_publisher)
        return super().destroy_node()


def _run(make_node, args) -> int:
    """
    Start ``make_node()`` and spin it until shutdown.

    0, or 2 with one line for invalid parameters.
    """
    quiet_interrupts()
    rclpy.init(args=args if args is not None else sys.argv)
    try:
        node = make_node()
    # invalid parameters: one readable line, exit 2
    except (ValueError, ParameterException) as exc:
        print(f'{NODE_NAME}: invalid parameters: {one_line(exc)}', file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    except BaseException as exc:  # a signal during start-up
        if not stopped_by_shutdown(exc):
            raise
        rclpy.try_shutdown()
        return 0
    try:
        spin_until_shutdown(node)
    # a second Ctrl-C before the clean-up could ignore it: stopping all the same
    except KeyboardInterrupt:
        pass
    return 0


def main(args=None) -> int:
    """Entry point of ``ros2 run iemd_ros tracker`` (and ``iemd-tracker``)."""
    return _run(TrackerNode, args)


def main_lifecycle(args=None) -> int:
    """
    Entry point of ``ros2 run iemd_ros tracker_lifecycle`` (and ``iemd-tracker-lifecycle``).

    The managed node, unconfigured until a lifecycle manager (or ``ros2 lifecycle set``) configures
    and activates it.
    """
    return _run(LifecycleTrackerNode, args)


if __name__ == '__main__':
    sys.exit(main())
