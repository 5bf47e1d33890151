"""``ros2 run iemd_ros tracker``: the iEMD tracker as a ROS 2 node (thin adapter over the pipeline).

Topics (relative names, remap with ``-r image:=/camera/image_raw`` ...):

* subscribes ``image`` (sensor_msgs/Image: mono8, mono16, bgr8, rgb8, bgra8, rgba8; with
  ``image_transport`` "compressed": sensor_msgs/CompressedImage on ``<image>/compressed``, jpeg or
  png as image_transport's compressed plugin publishes them; ``image`` remapped to a compressed stream
  itself is taken as it is), ``imu``
  (sensor_msgs/Imu, angular velocity in the IMU frame), ``camera_info`` (sensor_msgs/CameraInfo: K,
  plumb_bob D); sensor-data QoS (best effort) unless ``reliable_qos`` is true.
* publishes ``detections`` (vision_msgs/Detection2DArray, the image's header, one Detection2D while
  tracking, empty when lost or not initialized), ``/diagnostics`` (diagnostic_msgs/DiagnosticArray)
  and ``~/debug_image`` (annotated bgr8, drawn only while somebody subscribes).
* start/restart: parameter ``initial_box`` [x, y, w, h] (applied to the next frame), topic ``~/init``
  (vision_msgs/Detection2D; its header stamp picks the frame from a ring buffer of recent frames,
  a zero stamp means the newest frame), service ``~/reset`` (std_srvs/Trigger: forget the target;
  restart from ``initial_box`` if it is set).

Processing model: the image callback only stores the message in a single-slot "latest frame"
buffer (and in the ring buffer for ``~/init``); a worker thread takes the newest frame, waits at
most ``imu_wait_ms`` for the gyro to cover it, converts it, tracks it and publishes.  A frame that
is replaced in the slot before the worker took it is stale: it is dropped and counted (no backlog
ever builds up).  Malformed messages are logged (throttled) and explained in /diagnostics; they
never stop the node.  All tracking logic is in :class:`iemd_ros.pipeline.pipeline.TrackingPipeline`.
"""
from __future__ import annotations

import sys
import threading
import time
from collections import deque
from dataclasses import fields

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor, SetParametersResult
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile, QoSReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu
from std_srvs.srv import Trigger
from vision_msgs.msg import Detection2D, Detection2DArray, ObjectHypothesisWithPose

from iemd_ros.common.boxes import check_box
from iemd_ros.common.cli import one_line
from iemd_ros.messages.conversions import (CLASS_ID, DETECTION_ID, bbox_to_box, bbox_values, camera_model_from_msg, detection_values,
                          compressed_topic, fill_bbox, fill_image_msg, image_from_msg, imu_sample, is_compressed_topic,
                          raw_twin, stamp_ns)
from iemd_ros.pipeline.drawing import draw_result
from iemd_ros.gyro.predictor import GyroConfig
from iemd_ros.pipeline.pipeline import ERROR, NODE_NAME, OK, WARN, FrameResult, PipelineConfig, TrackingPipeline, gyro_config_to_dict
from iemd_ros.ros.spin import spin_until_shutdown
from iemd_ros.tracking.tracker import TrackerConfig

__all__ = ["TrackerNode", "main", "NODE_NAME"]


# Descriptions and ranges of the tracker parameters (``tracker.<field>`` of TrackerConfig).  The
# ranges are the outer limits a GUI can offer; TrackerConfig's own validation (cross-field rules
# included) decides, and its message is the rejection reason.
_TRACKER_DOC = {
    "template_size": ("[width, height] of the resampled target window, px (>= 8)", None),
    "patch_size": ("[m, n] local patch size, px", None),
    "patch_step": ("stride between local patches, px", (1, 64)),
    "normalization": ("grey-level normalization of the patches (see PatchLayout.extract)", None),
    "n_templates": ("L, templates in the dictionary (Algorithm 2)", (1, 50)),
    "lam": ("lambda of the sparse coding (eq. lagrange)", (1e-6, 10.0)),
    "alpha": ("weight of appearance vs. spatial distance in the EMD ground distance (0, 1)", (1e-3, 0.999)),
    "kernel_bandwidth": ("h, kernel bandwidth in normalized window units", (1e-3, 10.0)),
    "n_iter": ("maximum EMD descent iterations per start (Algorithm 1)", (0, 500)),
    "step_px": ("first descent step along -dEMD/dy, px", (1e-3, 100.0)),
    "min_step_px": ("stop when backtracking halves the step below this, px (<= step_px)", (1e-3, 100.0)),
    "coarse_to_fine": ("first descend on the next pyramid level (wider convergence region)", None),
    "gradient": ("EMD gradient: appearance, envelope or paper (eq. 10)", None),
    "scale_estimator": ("filter (DSST scale filter) or emd (the paper's EMD scale variants)", None),
    "scale_step": ("relative step between the scales searched (0: the window keeps its size), [0, 0.5)",
                   (0.0, 0.499)),
    "scale_range": ("emd: largest relative scale change per frame, [scale_step, 0.5)", (0.0, 0.499)),
    "flow_start": ("also start where the window's median optical flow moved it (section 6.1)", None),
    "flow_max_error": ("forward-backward error above which a flow point is dropped, px", (1e-3, 100.0)),
    "translation_weight": ("weight of the translation filter's response against EMD / background EMD when "
                           "choosing among the descended starts (0: no filter)", (0.0, 100.0)),
    "colour_weight": ("weight of the colour histograms' mean score against EMD / background EMD, colour images "
                      "only (0: no colour model)", (0.0, 100.0)),
    "motion_weight": ("weight of the squared displacement from the prediction, over the window's area, in the "
                      "same score (0: no motion prior)", (0.0, 100.0)),
    "update_confidence": ("a tracked frame learns (template, filters, colour, size) only when the translation "
                          "filter's response at the window is at least this times its running mean (0: always)",
                          (0.0, 0.99)),
    "descend_all_starts": ("with the translation filter, descend every start, not only the best by EMD and by score "
                           "(about 1.8x the update time)", None),
    "n_particles": ("extra starting points for abrupt motion (section 6.1)", (0, 64)),
    "particle_offset": ("distance of the extra starts from the prediction, window sizes", (0.0, 10.0)),
    "particle_trigger": ("run the extra starts when EMD > trigger x background EMD (0: always)", (0.0, 100.0)),
    "lost_factor": ("lost when EMD > factor x background EMD measured at init", (1e-3, 100.0)),
    "min_visible": ("lost when less of the window than this is inside the image", (0.0, 1.0)),
    "update_templates": ("update the template dictionary (Algorithm 2)", None),
    "forgetting": ("gamma_0 of the template update, (0, 1]", (1e-3, 1.0)),
    "reconstruction_lambda": ("lambda of the reconstructed template", (1e-6, 10.0)),
}
_GYRO_DOC = {
    "time_offset_ns": ("camera-IMU time offset, t_imu = t_cam + offset (Kalibr's shift), ns",
                       (-1_000_000_000, 1_000_000_000)),
    "R_cam_imu": ("IMU -> camera rotation, 9 values row-major: w_cam = R (w_imu - bias)", None),
    "bias": ("gyro bias [x, y, z] in the IMU frame, rad/s", None),
    "still_bias_samples": ("estimate the bias from the first N samples if the camera is still (0: off)",
                           (0, 100_000)),
    "still_bias_max_std": ("largest per-axis std of a still start, rad/s", (1e-6, 1.0)),
    "saturation": ("reject samples with |w_i| >= this, rad/s (0: no limit)", (0.0, 1000.0)),
    "max_gap_ns": ("IMU sample spacing reported as a gap, ns", (1_000_000, 10_000_000_000)),
    "buffer_ns": ("IMU history kept, ns", (100_000_000, 600_000_000_000)),
    "buffer_samples": ("IMU samples kept at most", (2, 10_000_000)),
    "allow_gaps": ("use a rotation integrated across a gap (else no prior)", None),
    "coning": ("coning correction in the rotation integration", None),
}
_PIPELINE_DOC = {
    "use_gyro": ("use the gyro prior K R^T K^-1 (section 5.2)", None),
    "imu_wait_ms": ("longest wait for IMU samples covering a frame before tracking it without the prior, ms",
                    (0.0, 1000.0)),
    "clock_reset_ms": ("a stamp this much earlier than the previous one is a clock reset, ms", (1.0, 1e7)),
    "score_emd_scale": ("detection score = exp(-EMD / score_emd_scale)", (1e-6, 100.0)),
}


def _descriptor(name: str, doc: tuple, value, read_only: bool = False) -> ParameterDescriptor:
    text, rng = doc
    d = ParameterDescriptor(name=name, description=text, read_only=read_only)
    if rng is not None and isinstance(value, bool):
        pass
    elif rng is not None and isinstance(value, int):
        d.integer_range = [IntegerRange(from_value=int(rng[0]), to_value=int(rng[1]), step=0)]
    elif rng is not None and isinstance(value, float):
        d.floating_point_range = [FloatingPointRange(from_value=float(rng[0]), to_value=float(rng[1]), step=0.0)]
    return d


def _param_value(value):
    """Dataclass default -> a ROS parameter value (tuples -> lists)."""
    if isinstance(value, tuple):
        return list(value)
    return value


class TrackerNode(Node):
    """The iEMD tracker node (see the module docstring for topics, parameters and threading)."""

    def __init__(self, node_name: str = NODE_NAME, **kwargs):
        super().__init__(node_name, **kwargs)
        self._declare_all()
        cfg = self._pipeline_config({})           # ValueError: invalid parameter file / overrides
        self._initial_box = self._check_initial_box(self.get_parameter("initial_box").value)
        transport = self.get_parameter("image_transport").value
        if transport not in ("raw", "compressed"):
            raise ValueError(f"image_transport must be 'raw' or 'compressed', got {transport!r}")
        self.pipeline = TrackingPipeline(cfg)
        p = self.get_parameter
        self._class_id = p("class_id").value
        self._detection_id = p("detection_id").value
        self._init_tolerance_ns = int(p("init_tolerance_ms").value * 1e6)
        self._timeout_s = p("input_timeout_s").value

        self._cond = threading.Condition()
        self._latest: Image | CompressedImage | None = None  # single-slot buffer of the newest frame
        self._ring: deque = deque(maxlen=p("frame_buffer_size").value)  # recent frames for ~/init
        self._ops: list = []                         # requests for the worker (config, reset, init)
        self._pending_box = self._initial_box        # initial_box to apply to the next frame
        self._latest_received = None
        self._awaiting_imu: int | None = None        # stamp of the frame the worker holds for IMU coverage
        self._stop = False
        self._note = ""                              # latest init problem / internal error
        self._last_image_wall = self._last_imu_wall = None
        self._latency_ms: deque = deque(maxlen=30)
        self._started = time.monotonic()
        if p("reliable_qos").value:
            sensor_qos = QoSProfile(depth=5, reliability=QoSReliabilityPolicy.RELIABLE)
            imu_qos = QoSProfile(depth=200, reliability=QoSReliabilityPolicy.RELIABLE)
        else:
            sensor_qos = qos_profile_sensor_data
            imu_qos = QoSProfile(depth=200, reliability=QoSReliabilityPolicy.BEST_EFFORT)
        self._det_pub = self.create_publisher(Detection2DArray, "detections", 10)
        self._diag_pub = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self._debug_pub = self.create_publisher(Image, "~/debug_image", 1)
        image_sub = self._subscribe_image(transport, sensor_qos)
        self._image_topic = image_sub.topic_name  # after remapping
        self.create_subscription(Imu, "imu", self._on_imu, imu_qos)
        self.create_subscription(CameraInfo, "camera_info", self._on_camera_info, sensor_qos)
        self.create_subscription(Detection2D, "~/init", self._on_init, 10)
        self.create_service(Trigger, "~/reset", self._on_reset)
        self.create_timer(p("diagnostics_period_s").value, self._publish_diagnostics)
        self.add_on_set_parameters_callback(self._on_set_parameters)

        self._worker = threading.Thread(target=self._work, name="iemd_tracker_worker", daemon=True)
        self._worker.start()
        self.get_logger().info(
            f"tracking '{self._image_topic}' -> '{self.resolve_topic_name('detections')}' "
            f"(gyro {'on' if cfg.use_gyro else 'off'}, {'reliable' if p('reliable_qos').value else 'sensor-data'} "
            f"QoS); {'initial box ' + str(self._initial_box) if self._initial_box else 'waiting for ~/init'}")

    # ------------------------------------------------------------------ parameters
    def _declare(self, name, value, descriptor) -> None:
        self.declare_parameter(name, value, descriptor)
        self._declared.append(name)

    def _subscribe_image(self, transport: str, qos):
        """The image subscription.  image_transport's naming: the compressed stream of the (remapped) image
        topic is <image>/compressed.  An image topic remapped to a compressed stream itself is taken as it
        is with the compressed transport (not <image>/compressed/compressed), and warned about with the raw
        one (an Image subscription there would never match the publisher's type)."""
        image_topic = self.resolve_topic_name("image")
        compressed_name = is_compressed_topic(image_topic)
        if transport == "compressed":
            if compressed_name:
                self.get_logger().warning(f"image is remapped to {image_topic}, a compressed stream: subscribing to "
                                          f"it (image_transport's convention is image:={raw_twin(image_topic)})")
            topic = image_topic if compressed_name else compressed_topic(image_topic)
            return self.create_subscription(CompressedImage, topic, self._on_image, qos)
        if compressed_name:
            self.get_logger().warning(f"image is remapped to {image_topic}, which looks like a compressed stream; "
                                      f"for sensor_msgs/CompressedImage set image_transport to 'compressed'")
        return self.create_subscription(Image, "image", self._on_image, qos)

    def _declare_all(self) -> None:
        self._declared: list[str] = []
        tracker_defaults = TrackerConfig().to_dict()
        for f in fields(TrackerConfig):
            value = _param_value(tracker_defaults[f.name])
            doc = _TRACKER_DOC.get(f.name, (f"TrackerConfig.{f.name}", None))
            self._declare(f"tracker.{f.name}", value, _descriptor(f"tracker.{f.name}", doc, value))
        gyro_defaults = gyro_config_to_dict(GyroConfig())
        for f in fields(GyroConfig):
            value = _param_value(gyro_defaults[f.name])
            doc = _GYRO_DOC.get(f.name, (f"GyroConfig.{f.name}", None))
            self._declare(f"gyro.{f.name}", value, _descriptor(f"gyro.{f.name}", doc, value))
        pipe_defaults = PipelineConfig()
        for name, doc in _PIPELINE_DOC.items():
            value = getattr(pipe_defaults, name)
            self._declare(name, value, _descriptor(name, doc, value))
        self._declare("initial_box", [], ParameterDescriptor(
            description="[x, y, w, h] target box (0-based top-left + size, px) applied to the next frame; "
                        "[] for none", dynamic_typing=True))
        node_params = [
            ("reliable_qos", False, ("reliable QoS for image/imu/camera_info instead of sensor-data (best effort)",
                                     None), True),
            ("image_transport", "raw", ('"raw": sensor_msgs/Image on image; "compressed": sensor_msgs/CompressedImage '
                                        '(jpeg/png) on <image>/compressed', None), True),
            ("frame_buffer_size", 30, ("recent frames kept for ~/init", (1, 1000)), True),
            ("init_tolerance_ms", 20.0, ("largest stamp difference between ~/init and a buffered frame, ms",
                                         (0.0, 10_000.0)), False),
            ("diagnostics_period_s", 1.0, ("period of /diagnostics, s", (0.01, 60.0)), True),
            ("input_timeout_s", 2.0, ("warn when no image / IMU arrived for this long, s", (0.01, 3600.0)), False),
            ("class_id", CLASS_ID, ("class_id of the published hypothesis", None), False),
            ("detection_id", DETECTION_ID, ("id of the published Detection2D", None), False),
        ]
        for name, value, doc, read_only in node_params:
            self._declare(name, value, _descriptor(name, doc, value, read_only))

    def _values(self, overrides: dict) -> dict:
        return {n: overrides[n] if n in overrides else self.get_parameter(n).value for n in self._declared}

    def _pipeline_config(self, overrides: dict) -> PipelineConfig:
        return PipelineConfig.from_parameters(self._values(overrides))

    @staticmethod
    def _check_initial_box(value):
        box = list(value) if value is not None else []
        if not box:
            return None
        return check_box(box, "initial_box ([] for none)")

    def _on_set_parameters(self, params) -> SetParametersResult:
        changes = {p.name: p.value for p in params}
        try:
            cfg = self._pipeline_config(changes)
            box = self._check_initial_box(changes["initial_box"]) if "initial_box" in changes else None
        except (ValueError, TypeError) as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        if "init_tolerance_ms" in changes:
            self._init_tolerance_ns = int(changes["init_tolerance_ms"] * 1e6)
        if "input_timeout_s" in changes:
            self._timeout_s = changes["input_timeout_s"]
        if "class_id" in changes:
            self._class_id = changes["class_id"]
        if "detection_id" in changes:
            self._detection_id = changes["detection_id"]
        with self._cond:
            if any(not (n == "initial_box" or n in ("init_tolerance_ms", "input_timeout_s", "class_id",
                                                    "detection_id")) for n in changes):
                self._ops.append(("config", cfg))
            if "initial_box" in changes:
                self._initial_box = self._pending_box = box
            self._cond.notify_all()
        return SetParametersResult(successful=True)

    # ------------------------------------------------------------------ callbacks (fast)
    def _on_image(self, msg: Image | CompressedImage) -> None:
        now = time.monotonic()
        self._last_image_wall = now
        with self._cond:
            self._ring.append(msg)
            if self._latest is not None:
                old = self._latest
                self.pipeline.note_dropped(stamp_ns(old.header))
            self._latest = msg
            self._latest_received = now
            self._cond.notify_all()

    def _on_imu(self, msg: Imu) -> None:
        self._last_imu_wall = time.monotonic()
        if not self.pipeline.add_imu_message(*imu_sample(msg)):
            self._warn(self.pipeline.last_reasons()["imu_reason"])
        # Wake the worker only when this sample lets the frame it holds go.  No race: the sample is
        # stored before the lock is taken here, and the worker sets _awaiting_imu and checks gyro_ready
        # under the lock before it waits, so either it sees the sample or we see it waiting.
        with self._cond:
            if self._awaiting_imu is not None and self.pipeline.gyro_ready(self._awaiting_imu):
                self._cond.notify_all()

    def _on_camera_info(self, msg: CameraInfo) -> None:
        try:
            camera = camera_model_from_msg(msg)
        except ValueError as exc:
            self.pipeline.note_bad_camera_info(str(exc))
            self._warn(f"camera_info rejected: {exc}")
            return
        if self.pipeline.set_camera(camera):
            self.get_logger().info(f"camera model: {camera!r}")

    def _on_init(self, msg: Detection2D) -> None:
        try:
            box = bbox_to_box(*bbox_values(msg.bbox))
        except ValueError as exc:
            self._note = f"~/init rejected: {exc}"
            self._warn(self._note)
            return
        stamp = stamp_ns(msg.header)
        with self._cond:
            self._ops.append(("init", box, stamp))
            self._pending_box = None
            self._cond.notify_all()

    def _on_reset(self, request, response):
        with self._cond:
            self._ops.append(("reset",))
            self._pending_box = self._initial_box
            self._cond.notify_all()
        response.success = True
        response.message = ("target cleared; restarting from initial_box on the next frame"
                            if self._initial_box is not None else "target cleared; waiting for ~/init")
        return response

    def _warn(self, text: str) -> None:
        self.get_logger().warning(text, throttle_duration_sec=5.0)

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
                if msg is not None:
                    self._handle_frame(msg, received)
            except Exception as exc:  # a bug must not kill the worker; say so in the log and /diagnostics
                if self._stop or not self.context.ok():
                    return
                self._note = f"internal error: {type(exc).__name__}: {exc}"
                self.get_logger().error(self._note, throttle_duration_sec=5.0)

    def _apply(self, op) -> None:
        kind = op[0]
        if kind == "config":
            what = self.pipeline.configure(op[1])
            self.get_logger().info(f"parameters applied: {what}")
        elif kind == "reset":
            self.pipeline.reset()
            self._note = ""
        elif kind == "init":
            self._init_from_ring(op[1], op[2])

    def _init_from_ring(self, box, stamp: int) -> None:
        with self._cond:
            frames = list(self._ring)
        if not frames:
            self._note = "~/init ignored: no frame received yet"
            self._warn(self._note)
            return
        stamps = np.array([stamp_ns(m.header) for m in frames])
        i = len(frames) - 1 if stamp == 0 else int(np.argmin(np.abs(stamps - stamp)))
        if stamp != 0 and abs(int(stamps[i]) - stamp) > self._init_tolerance_ns:
            self._note = (f"~/init ignored: no buffered frame within {self._init_tolerance_ns / 1e6:.0f} ms of its "
                          f"stamp {stamp} ns (buffer spans {stamps.min()}..{stamps.max()} ns)")
            self._warn(self._note)
            return
        m = frames[i]
        try:
            frame = image_from_msg(m)
            self.pipeline.init(frame, box, int(stamps[i]))
        except ValueError as exc:
            self._note = f"~/init failed: {exc}"
            self._warn(self._note)
            return
        self._note = ""
        self.get_logger().info(f"target initialized from ~/init at {box} on the frame stamped {int(stamps[i])} ns")

    def _handle_frame(self, msg: Image | CompressedImage, received) -> None:
        stamp = stamp_ns(msg.header)
        try:
            frame = image_from_msg(msg)
        except ValueError as exc:
            self.pipeline.note_bad_image(str(exc), stamp)
            self._warn(f"image rejected: {exc}")
            return
        with self._cond:                   # initial_box (startup, parameter change, ~/reset): this frame
            pending_box, self._pending_box = self._pending_box, None
        if pending_box is not None:
            try:
                result = self.pipeline.init(frame, pending_box, stamp)
            except ValueError as exc:
                self._note = f"initial_box not usable: {exc}"
                self._warn(self._note)
                self._publish(msg, None, received)
                return
            self._note = ""
            self.get_logger().info(f"target initialized at {pending_box}")
        else:
            deadline = time.monotonic() + self.pipeline.config.imu_wait_ms * 1e-3
            with self._cond:
                self._awaiting_imu = stamp
                while not self._stop and not self.pipeline.gyro_ready(stamp):
                    remaining = deadline - time.monotonic()
                    if remaining <= 0:
                        break
                    self._cond.wait(remaining)
                self._awaiting_imu = None
            result = self.pipeline.process(frame, stamp)
        self._publish(msg, result, received)
        self._publish_debug(msg, frame, result)

    # ------------------------------------------------------------------ output
    def _publish(self, img: Image | CompressedImage, result: FrameResult | None, received) -> None:
        """The image's Detection2DArray: one detection while ``result`` is tracking, else empty."""
        out = Detection2DArray()
        out.header = img.header
        values = detection_values(result)
        if values is not None:
            det = Detection2D()
            det.header = img.header
            det.id = self._detection_id
            fill_bbox(det.bbox, values.bbox)
            hyp = ObjectHypothesisWithPose()
            hyp.hypothesis.class_id = self._class_id
            hyp.hypothesis.score = values.score
            det.results = [hyp]
            out.detections = [det]
        if self._stop or not self.context.ok():
            return
        self._det_pub.publish(out)
        if received is not None:
            self._latency_ms.append((time.monotonic() - received) * 1e3)

    def _publish_debug(self, img: Image | CompressedImage, frame: np.ndarray, result: FrameResult) -> None:
        if self._debug_pub.get_subscription_count() == 0 or self._stop:
            return
        canvas = draw_result(frame, result)
        out = fill_image_msg(Image(), canvas)
        out.header = img.header
        if self.context.ok():
            self._debug_pub.publish(out)

    def diagnostic_statuses(self):
        """Pipeline statuses plus the node's wall-clock liveness checks, as (Status-like) tuples."""
        now = time.monotonic()
        out = []
        for s in self.pipeline.statuses(prefix=self.get_name()):
            level, message, values = s.level, s.message, dict(s.values)
            kind = s.name.split(": ", 1)[1]
            if kind == "image input":
                since = now - (self._last_image_wall or self._started)
                values["latency_ms_mean"] = f"{np.mean(self._latency_ms):.1f}" if self._latency_ms else "nan"
                values["topic"] = self._image_topic
                if since > self._timeout_s and level < ERROR:
                    note = (f"no image on {values['topic']} for {since:.1f} s" if self._last_image_wall
                            else f"no image received on {values['topic']} yet")
                    message = note if level == OK or not self._last_image_wall else f"{message}; {note}"
                    level = WARN
            elif kind == "imu" and self.pipeline.config.use_gyro and level < ERROR:
                since = now - (self._last_imu_wall or self._started)
                if since > self._timeout_s:
                    note = (f"no IMU message on {self.resolve_topic_name('imu')} for {since:.1f} s"
                            if self._last_imu_wall else
                            f"no IMU message received on {self.resolve_topic_name('imu')}: tracking without gyro")
                    message = note if level == OK else f"{message}; {note}"
                    level = WARN
            elif kind == "tracking" and self._note:
                values["note"] = self._note
                if self.pipeline.state == "uninitialized":
                    message = f"{message} ({self._note})"
                elif self._note.startswith("internal error"):
                    level, message = ERROR, self._note
            out.append((s.name, level, message, values))
        return out

    def _publish_diagnostics(self) -> None:
        arr = DiagnosticArray()
        arr.header.stamp = self.get_clock().now().to_msg()
        for name, level, message, values in self.diagnostic_statuses():
            st = DiagnosticStatus(name=name, message=message, hardware_id=self.get_fully_qualified_name())
            st.level = bytes([level])
            st.values = [KeyValue(key=k, value=v) for k, v in values.items()]
            arr.status.append(st)
        self._diag_pub.publish(arr)

    def destroy_node(self):
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if self._worker.is_alive() and threading.current_thread() is not self._worker:
            self._worker.join(timeout=5.0)
        return super().destroy_node()


def main(args=None) -> int:
    """Entry point of ``ros2 run iemd_ros tracker`` (and ``iemd-tracker``)."""
    rclpy.init(args=args if args is not None else sys.argv)
    try:
        node = TrackerNode()
    except (ValueError, ParameterException) as exc:  # invalid parameters: one readable line, exit 2
        print(f"{NODE_NAME}: invalid parameters: {one_line(exc)}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        rclpy.try_shutdown()
        return 0
    spin_until_shutdown(node)
    return 0


if __name__ == "__main__":
    sys.exit(main())
