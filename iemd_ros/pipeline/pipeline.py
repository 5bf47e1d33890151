"""Message-level tracking pipeline (ROS-free): images, gyro and camera info in, tracked boxes out.

The one place where per-message data flows into :class:`~iemd_ros.IemdTracker` and
:class:`~iemd_ros.gyro.predictor.GyroPredictor`; used by the ROS node (:mod:`iemd_ros.ros.node`) and by the bag
replay, so both produce the same boxes from the same messages:

    pipe = TrackingPipeline(PipelineConfig())
    pipe.set_camera(camera)                      # from CameraInfo (conversions.camera_model_from_msg)
    pipe.add_imu(t_ns, (wx, wy, wz))             # every Imu message (IMU frame, rad/s)
    pipe.init(frame, (x, y, w, h), t_ns)         # start (or restart) on a frame: its FrameResult
    if pipe.gyro_ready(t_ns) or waited_long_enough:
        result = pipe.process(frame, t_ns)       # FrameResult
    pipe.statuses()                              # OK/WARN/ERROR summaries for /diagnostics

Gyro prior (paper, section 5.2): the rotation is integrated from the frame whose window the tracker
holds -- the init frame or the last frame that was not lost (a lost frame leaves the window where it
was) -- to the new frame, and the lens-aware ``K R^T K^-1`` prior is fitted at that window.

Everything that decides a result depends only on the messages (stamps and contents), never on the
wall clock, so replaying the same messages twice gives identical results; only
``FrameResult.processing_ms`` and the ``*_ms`` diagnostic values are wall-clock measurements.
Waiting for IMU coverage is the caller's choice: :meth:`TrackingPipeline.gyro_ready` says whether a
frame would get a prior now; a live node waits up to ``imu_wait_ms`` of wall time, an offline
replay can read ahead in the bag.

Thread safety: :meth:`add_imu`, :meth:`set_camera` and the ``note_*`` methods may be called from
other threads while :meth:`process` runs; they never wait for a tracker update to finish.
"""
from __future__ import annotations

import functools
import math
import threading
import time
from collections import deque
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np

from iemd_ros.gyro.camera import CameraModel
from iemd_ros.gyro.predictor import GyroConfig, GyroPredictor, compile_gyro_jit
from iemd_ros.gyro.imu import SampleStatus
from iemd_ros.tracking.tracker import IemdTracker, TrackerConfig, compile_jit

__all__ = ["PipelineConfig", "FrameResult", "Status", "TrackingPipeline", "OK", "WARN", "ERROR", "INIT_REASON",
           "gyro_config_from_dict", "gyro_config_to_dict"]

# levels of diagnostic_msgs/DiagnosticStatus
OK, WARN, ERROR = 0, 1, 2
INIT_REASON = "target initialized on this frame"   # FrameResult.reason of the frame init() started on

_WINDOW = 30            # recent frames / IMU messages the statuses look at
_LOST_ERROR_FRAMES = 30  # lost this many frames in a row: ERROR
_IMU_ERROR_RUN = 10      # this many rejected IMU messages in a row: ERROR


def gyro_config_from_dict(values: dict) -> GyroConfig:
    """GyroConfig from plain values (lists for ``R_cam_imu`` (9 or 3x3) and ``bias``; ``saturation``
    <= 0 or None means no limit).  Raises ValueError on unknown keys or invalid values."""
    known = {f.name for f in fields(GyroConfig)}
    unknown = set(values) - known
    if unknown:
        raise ValueError(f"unknown gyro parameters: {', '.join(sorted(unknown))}")
    v = dict(values)
    if v.get("R_cam_imu") is not None:
        R = np.asarray(v["R_cam_imu"], dtype=float)
        if R.size != 9:
            raise ValueError(f"gyro R_cam_imu must have 9 values (row-major 3x3), got {R.size}")
        v["R_cam_imu"] = R.reshape(3, 3)
    if v.get("bias") is not None:
        v["bias"] = np.asarray(v["bias"], dtype=float)
    if v.get("saturation") is not None and float(v["saturation"]) <= 0:
        v["saturation"] = None
    for key in ("time_offset_ns", "still_bias_samples", "max_gap_ns", "buffer_ns", "buffer_samples"):
        if key in v:
            if float(v[key]) != int(v[key]):
                raise ValueError(f"gyro {key} must be an integer, got {v[key]!r}")
            v[key] = int(v[key])
    return GyroConfig(**v)


def gyro_config_to_dict(cfg: GyroConfig) -> dict:
    """Plain-value form of a GyroConfig (round-trips through :func:`gyro_config_from_dict`)."""
    d = asdict(cfg)
    d["R_cam_imu"] = (np.eye(3) if cfg.R_cam_imu is None else np.asarray(cfg.R_cam_imu, float)).ravel().tolist()
    d["bias"] = (np.zeros(3) if cfg.bias is None else np.asarray(cfg.bias, float)).tolist()
    d["saturation"] = 0.0 if cfg.saturation is None else float(cfg.saturation)
    return d


NODE_NAME = "iemd_tracker"  # the tracker node's default name (iemd_ros.ros.node), as parameter files name it
_WILDCARD_NODES = ("*", "**")  # node names of a parameter file's sections that apply to every node


def _parameter_sections(tree: dict, names: tuple = ()):
    """(node path, node name, its ``ros__parameters``) of every section of a ROS parameter file, namespaces
    included (the node name is the path's last part: ``**`` or ``*`` for wildcards)."""
    for key, value in tree.items():
        if key == "ros__parameters":
            where = "/".join(names)
            yield where, where.rsplit("/", 1)[-1], value
        elif isinstance(value, dict):
            yield from _parameter_sections(value, names + (str(key),))


def _dotted(params: dict, prefix: str = "") -> dict:
    """A section's ``ros__parameters`` with nested groups flattened to dotted names (``tracker: {n_iter: 7}``
    -> ``tracker.n_iter: 7``), as rcl reads a parameter file, so that sections merge parameter by parameter."""
    flat: dict = {}
    for key, value in params.items():
        if isinstance(value, dict):
            flat.update(_dotted(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


@dataclass
class PipelineConfig:
    """Tracker + gyro settings and the pipeline's own.

    ``use_gyro``: pass the gyro prior to the tracker.  ``imu_wait_ms``: how long a live caller may
    hold a frame for IMU coverage before processing it without the prior.  ``clock_reset_ms``: a
    stamp this much earlier than the previous one is a clock reset (bag loop, simulation restart):
    the IMU buffer restarts and tracking goes on without a prior for that frame; smaller steps back
    reject the frame.  ``score_emd_scale``: detection score ``exp(-EMD / score_emd_scale)``.
    """

    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    gyro: GyroConfig = field(default_factory=GyroConfig)
    use_gyro: bool = True
    imu_wait_ms: float = 15.0
    clock_reset_ms: float = 1000.0
    score_emd_scale: float = 0.25

    def __post_init__(self):
        if not isinstance(self.tracker, TrackerConfig):
            raise ValueError("tracker must be a TrackerConfig")
        if not isinstance(self.gyro, GyroConfig):
            raise ValueError("gyro must be a GyroConfig")
        if not (0 <= self.imu_wait_ms <= 1000):
            raise ValueError(f"imu_wait_ms must be in [0, 1000], got {self.imu_wait_ms}")
        if not self.clock_reset_ms > 0:
            raise ValueError(f"clock_reset_ms must be > 0, got {self.clock_reset_ms}")
        if not self.score_emd_scale > 0:
            raise ValueError(f"score_emd_scale must be > 0, got {self.score_emd_scale}")
        if not isinstance(self.use_gyro, (bool, np.bool_)):
            raise ValueError(f"use_gyro must be true or false, got {self.use_gyro!r}")
        self.use_gyro = bool(self.use_gyro)

    @classmethod
    def from_dict(cls, values: dict) -> "PipelineConfig":
        """From ``{"tracker": {...}, "gyro": {...}, "use_gyro": ..., ...}`` (missing keys: defaults)."""
        v = dict(values)
        unknown = set(v) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f"unknown pipeline parameters: {', '.join(sorted(unknown))}")
        for group in ("tracker", "gyro"):
            if not isinstance(v.get(group, {}), dict):
                raise ValueError(f"{group} must be a mapping of its parameters, got {v[group]!r}")
        try:
            v["tracker"] = TrackerConfig.from_dict(v.get("tracker", {}))
            v["gyro"] = gyro_config_from_dict(v.get("gyro", {}))
            return cls(**v)
        except TypeError as exc:  # a value of the wrong type, e.g. text for a number
            raise ValueError(f"invalid pipeline parameters: {exc}") from None

    @classmethod
    def from_parameters(cls, params: dict) -> "PipelineConfig":
        """From the node's ROS parameters, by their dotted names as the node declares them (``tracker.n_iter``;
        :meth:`from_yaml` flattens a file's groups ``tracker: {n_iter: 10}`` to them).  Node-only parameters
        (``initial_box``, ``class_id``, ...) are ignored."""
        keys = {f.name for f in fields(cls)}
        values: dict = {"tracker": {}, "gyro": {}}
        for key, value in params.items():
            group, dot, name = str(key).partition(".")
            if group in ("tracker", "gyro"):
                if not dot:
                    raise ValueError(f"{group} must be a group of parameters ({group}.<name>), got {value!r}")
                values[group][name] = value
            elif group in keys:
                if dot:
                    raise ValueError(f"{group} is a single parameter, not a group: got {key!r}")
                values[group] = value
        return cls.from_dict(values)

    @classmethod
    def from_yaml(cls, path, node_name: str = NODE_NAME) -> "PipelineConfig":
        """From a YAML file: either ``{tracker: {...}, gyro: {...}, use_gyro: ..., imu_wait_ms: ...}``
        (:meth:`from_dict`) or a ROS parameter file (``config/tracker.yaml``), read as the node named
        ``node_name`` would: the ``ros__parameters`` of wildcard sections (``/**``) and then of its
        own section (optionally under namespaces), by :meth:`from_parameters`.  A file with one named
        section is read whatever that name (a renamed node's file); of several, the one named ``node_name``.
        ValueError for a file that cannot be read, has several named sections and none for the node, or
        holds invalid values."""
        import yaml  # noqa: PLC0415 - only the command-line tools read configuration files

        path = Path(path)
        try:
            values = yaml.safe_load(path.read_text()) or {}
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
            raise ValueError(f"cannot read config {path}: {exc}") from None
        if not isinstance(values, dict):
            raise ValueError(f"config {path} must be a mapping")
        sections = list(_parameter_sections(values))
        if not sections:
            return cls.from_dict(values)
        wildcard = [params for _, node, params in sections if node in _WILDCARD_NODES]
        named = [(where, node, params) for where, node, params in sections if node not in _WILDCARD_NODES]
        if len(named) > 1:
            own = [section for section in named if section[1] == node_name]
            if len(own) != 1:
                raise ValueError(f"config {path} holds parameters of {len(named)} nodes "
                                 f"({', '.join(where for where, _, _ in named)}) and not one named {node_name}")
            named = own
        merged: dict = {}
        for params in wildcard + [params for _, _, params in named]:
            if not isinstance(params, dict):
                raise ValueError(f"config {path}: ros__parameters must be a mapping, got {params!r}")
            merged.update(_dotted(params))
        try:
            return cls.from_parameters(merged)
        except ValueError as exc:
            raise ValueError(f"config {path}: {exc}") from None

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["tracker"] = self.tracker.to_dict()
        d["gyro"] = gyro_config_to_dict(self.gyro)
        return d


@dataclass
class FrameResult:
    """Outcome of one frame.

    ``state``: "tracking", "lost" or "uninitialized"; ``rejected``: why the frame was not processed
    ("" when it was).  ``box``/``angle``/``emd``/``iterations``/``reason`` come from the tracker
    (:class:`~iemd_ros.tracking.tracker.TrackResult`; the best window searched, also when lost): ``angle``
    (radians) is the window's turn, which the gyro priors change (mostly the camera's roll), and
    ``box`` ``(x, y, w, h)`` the axis-aligned bounding box of the turned window.
    ``score`` = ``exp(-emd / score_emd_scale)`` while tracking, else 0.  ``gyro_box``: the gyro's
    predicted window; ``predicted_box``: the tracker's starting window (after the gyro prior; a
    bounding box as ``box``).  ``processing_ms`` is wall-clock time.
    """

    stamp_ns: int
    state: str
    box: tuple | None = None
    emd: float = math.nan
    score: float = 0.0
    iterations: int = 0
    lost: bool = False
    reason: str = ""
    rejected: str = ""
    gyro_used: bool = False
    gyro_reason: str = ""
    gyro_box: tuple | None = None
    predicted_box: tuple | None = None
    scale: float = 1.0
    starts: int = 0
    processing_ms: float = 0.0
    angle: float = 0.0
    is_init: bool = False   # the result of the frame TrackingPipeline.init started on

    @property
    def tracking(self) -> bool:
        return self.state == "tracking" and not self.rejected

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Status:
    """One diagnostic status (levels as diagnostic_msgs: OK 0, WARN 1, ERROR 2)."""

    name: str
    level: int
    message: str
    values: dict


@functools.cache
def _compile_jit_once() -> None:
    """The tracker's and the gyro's JIT (:func:`~iemd_ros.tracking.tracker.compile_jit`,
    :func:`~iemd_ros.gyro.predictor.compile_gyro_jit`), once per process: at the first pipeline's start-up, not
    on the first frames; later pipelines (~7 ms of warm-up each otherwise) skip it."""
    compile_jit()
    compile_gyro_jit()


def _ms(ns: float) -> str:
    return f"{ns / 1e6:.1f} ms"


class TrackingPipeline:
    """Tracker + gyro predictor fed message by message (see the module docstring)."""

    def __init__(self, config: PipelineConfig | None = None, camera: CameraModel | None = None):
        _compile_jit_once()  # the JIT at the first start-up, not on the first frames
        self._cfg = config if config is not None else PipelineConfig()
        if not isinstance(self._cfg, PipelineConfig):
            raise ValueError("config must be a PipelineConfig")
        self._lock = threading.RLock()        # IMU / camera / counters (held briefly)
        self._track_lock = threading.RLock()  # tracker state (held during a tracker update)
        self._predictor = GyroPredictor(None, self._cfg.gyro)   # buffers the IMU from the start; K comes later
        self._tracker: IemdTracker | None = None
        self._state = "uninitialized"
        self._ref: tuple[int, tuple, np.ndarray] | None = None   # (stamp, window box, frame) the window is in
        self._last_stamp: int | None = None
        self._lost_run = 0
        self.counters = dict(frames_received=0, frames_processed=0, frames_uninitialized=0, frames_dropped=0,
                             frames_rejected=0, images_malformed=0, frames_lost=0, frames_held=0, gyro_used=0, gyro_unused=0,
                             imu_received=0, imu_rejected=0, imu_out_of_order=0, imu_saturated=0,
                             clock_resets=0, camera_infos=0, camera_infos_rejected=0, inits=0, resets=0)
        self._last = dict(frame_reason="", gyro_reason="", imu_reason="", image_error="", camera_error="",
                          drop_reason="")
        self._last_result: FrameResult | None = None
        self._image_bad = False          # the latest image message was malformed
        self._imu_bad_run = 0            # consecutive rejected IMU messages
        self._recent = deque(maxlen=_WINDOW)     # (stamp, outcome) of received frames
        self._recent_proc = deque(maxlen=_WINDOW)  # (stamp, processing_ms, gyro_used) of tracked frames
        if camera is not None:
            self.set_camera(camera)

    # ------------------------------------------------------------------ configuration
    @property
    def config(self) -> PipelineConfig:
        return self._cfg

    @property
    def state(self) -> str:
        return self._state

    @property
    def camera(self) -> CameraModel | None:
        return self._predictor.camera

    def configure(self, config: PipelineConfig) -> str:
        """Apply a new configuration; returns a one-line summary of what changed.

        A changed tracker configuration restarts the tracker at its current window on the frame that
        window belongs to (the template is taken again there); a changed gyro configuration rebuilds
        the predictor, keeping the buffered IMU samples.
        """
        if not isinstance(config, PipelineConfig):
            raise ValueError("config must be a PipelineConfig")
        with self._track_lock, self._lock:
            old, self._cfg = self._cfg, config
            notes = []
            if not _same_gyro(config.gyro, old.gyro):
                self._rebuild_predictor()
                notes.append("gyro predictor rebuilt (IMU samples kept)")
            if config.tracker != old.tracker:
                if self._tracker is not None and self._ref is not None:
                    stamp, box, frame = self._ref
                    self._tracker = IemdTracker(config.tracker)
                    self._tracker.init(frame, box)
                    self._state, self._lost_run = "tracking", 0
                    notes.append("tracker restarted at its current window")
                else:
                    notes.append("tracker configuration stored")
            return "; ".join(notes) or "no change"

    # ------------------------------------------------------------------ inputs
    def set_camera(self, camera: CameraModel) -> bool:
        """Use ``camera`` (K, D) for the gyro prior; returns True when it differs from the current one."""
        if not isinstance(camera, CameraModel):
            raise ValueError(f"camera must be a CameraModel, got {type(camera).__name__}")
        with self._lock:
            self.counters["camera_infos"] += 1
            self._last["camera_error"] = ""
            cur = self._predictor.camera
            if cur is not None and np.array_equal(cur.K, camera.K) and np.array_equal(cur.D, camera.D) \
                    and (cur.width, cur.height) == (camera.width, camera.height):
                return False
            self._predictor.camera = camera
            return True

    def note_bad_camera_info(self, reason: str) -> None:
        """Record a CameraInfo message that could not be used (the previous camera, if any, stays)."""
        with self._lock:
            self.counters["camera_infos_rejected"] += 1
            self._last["camera_error"] = reason

    def _rebuild_predictor(self) -> None:
        """New GyroPredictor for the current gyro config, fed the samples buffered so far."""
        t, w = self._predictor.buffer.samples()
        self._predictor = self._new_predictor()
        if len(t):
            self._predictor.add_imu(t, w)

    def add_imu(self, t_ns: int, gyro_xyz) -> bool:
        """Add one gyro sample (IMU clock, ns; IMU-frame rate in rad/s).  Returns False if rejected.

        Non-finite rates and saturated samples are rejected and counted (the IMU buffer screens them);
        an accepted stamp earlier than the newest one is counted (the buffer puts it in order) and, if
        earlier by more than ``clock_reset_ms``, restarts the IMU buffer (a clock reset).
        ``last_reasons()['imu_reason']`` says why.  ValueError if ``gyro_xyz`` is not 3 values.
        """
        t = int(t_ns)
        w = np.asarray(gyro_xyz, dtype=float).ravel()
        with self._lock:
            c = self.counters
            c["imu_received"] += 1
            newest = self._predictor.buffer.t_newest_ns
            back = 0 if newest is None else newest - t
            reset = back > self._cfg.clock_reset_ms * 1e6
            # on a clock reset the sample goes to a new predictor, kept only if the sample is accepted
            predictor = self._new_predictor() if reset else self._predictor
            status = int(predictor.add_imu(t, w)[0])
            if status == SampleStatus.NOT_FINITE:
                return self._reject_imu("imu_rejected", f"IMU sample at {t} ns rejected: angular velocity "
                                                        f"{w.tolist()} is not 3 finite values")
            if status == SampleStatus.SATURATED:
                return self._reject_imu("imu_saturated", f"IMU sample at {t} ns rejected: |w| reaches the "
                                                         f"saturation limit {self._cfg.gyro.saturation} rad/s")
            if reset:
                c["clock_resets"] += 1
                self._last["imu_reason"] = f"IMU clock jumped back by {_ms(back)}: IMU buffer restarted"
                self._predictor = predictor                   # holding the first sample on the new clock
            elif back > 0:
                # The buffer's out_of_order count tests the same (an accepted stamp below the newest
                # accepted one), but it restarts with every new predictor (IMU clock reset, image clock
                # reset with the IMU still on the old clock, gyro reconfiguration: samples re-fed in
                # order); this one counts over the pipeline's life, like the other /diagnostics counters.
                c["imu_out_of_order"] += 1
                self._last["imu_reason"] = f"IMU stamp went back by {_ms(back)} (sample put in order)"
            self._imu_bad_run = 0
            return True

    def _reject_imu(self, counter: str, reason: str) -> bool:
        """Count a rejected IMU message under ``counter``; returns False (add_imu's answer)."""
        self.counters[counter] += 1
        self._imu_bad_run += 1
        self._last["imu_reason"] = reason
        return False

    def add_imu_message(self, t_ns: int, angular_velocity_xyz, angular_velocity_covariance0: float) -> bool:
        """A sensor_msgs/Imu's rates: REP 145's covariance[0] = -1 means "no angular velocity"."""
        if angular_velocity_covariance0 == -1.0:
            self.note_bad_imu("IMU message has angular_velocity_covariance[0] = -1: no angular velocity")
            return False
        return self.add_imu(t_ns, angular_velocity_xyz)

    def note_bad_imu(self, reason: str) -> None:
        """Count an IMU message that carries no usable rate (e.g. covariance[0] = -1: no gyro)."""
        with self._lock:
            self.counters["imu_received"] += 1
            self._reject_imu("imu_rejected", reason)

    def _new_predictor(self) -> GyroPredictor:
        """An empty GyroPredictor for the current camera and gyro configuration."""
        return GyroPredictor(self._predictor.camera, self._cfg.gyro)

    def note_dropped(self, stamp_ns: int, reason: str = "a newer frame arrived before this one was processed") -> None:
        """Count a frame the caller skipped (e.g. stale: processing fell behind)."""
        with self._lock:
            self.counters["frames_received"] += 1
            self.counters["frames_dropped"] += 1
            self._last["drop_reason"] = reason
            self._recent.append((int(stamp_ns), "dropped"))

    def note_bad_image(self, reason: str, stamp_ns: int | None = None) -> None:
        """Count an image message that could not be converted (wrong encoding, step or size)."""
        with self._lock:
            self.counters["frames_received"] += 1
            self.counters["images_malformed"] += 1
            self._last["image_error"] = reason
            self._image_bad = True
            if stamp_ns is not None:
                self._recent.append((int(stamp_ns), "malformed"))

    # ------------------------------------------------------------------ tracking
    def gyro_ready(self, stamp_ns: int) -> bool:
        """True when processing the frame now loses nothing: the gyro covers it, or no prior can be
        used anyway (gyro off, no camera, no target).  False: waiting for IMU samples may help."""
        with self._lock:
            if not self._cfg.use_gyro or self._predictor.camera is None or self._ref is None:
                return True
            return self._predictor.ready(int(stamp_ns))

    def init(self, frame: np.ndarray, box, stamp_ns: int) -> FrameResult:
        """(Re)start tracking the target ``box`` = (x, y, w, h) in ``frame`` stamped ``stamp_ns``.

        Returns the frame's result: ``box``, score 1, ``is_init``, ``reason`` :data:`INIT_REASON`.  Raises
        ValueError for a bad frame or box (the previous target, if any, is kept then).
        """
        with self._track_lock:
            tracker = IemdTracker(self._cfg.tracker)
            tracker.init(frame, box)
            box = tuple(float(v) for v in box)
            with self._lock:
                self._tracker = tracker
                self._ref = (int(stamp_ns), box, frame)
                self._state, self._lost_run = "tracking", 0
                self.counters["inits"] += 1
                self._last["frame_reason"] = ""
                if self._last_stamp is None or int(stamp_ns) > self._last_stamp:
                    self._last_stamp = int(stamp_ns)
        return FrameResult(int(stamp_ns), "tracking", box, score=1.0, reason=INIT_REASON, is_init=True)

    def reset(self) -> None:
        """Forget the target (state "uninitialized"); IMU and camera are kept."""
        with self._track_lock, self._lock:
            self._tracker, self._ref = None, None
            self._state, self._lost_run = "uninitialized", 0
            self._last_result = None
            self.counters["resets"] += 1

    def process(self, frame: np.ndarray, stamp_ns: int) -> FrameResult:
        """Track into ``frame`` (stamped ``stamp_ns``, camera clock); see :class:`FrameResult`."""
        t = int(stamp_ns)
        with self._track_lock:
            with self._lock:
                self.counters["frames_received"] += 1
                self._image_bad = False
                rejected = self._check_stamp(t)
                if rejected:
                    self.counters["frames_rejected"] += 1
                    self._recent.append((t, "rejected"))
                    self._last["frame_reason"] = rejected
                    return FrameResult(t, self._state, rejected=rejected)
                self._last_stamp = t
                if self._tracker is None:
                    self.counters["frames_uninitialized"] += 1
                    self._recent.append((t, "uninitialized"))
                    return FrameResult(t, "uninitialized", reason="no target: waiting for an initial box")
                prior, gyro_box, gyro_reason = self._gyro_prior(t)
            start = time.perf_counter()
            try:
                result = self._tracker.update(frame, prior=prior)
            except ValueError as exc:
                if prior is None:
                    raise
                gyro_reason = f"gyro prior not usable ({exc}); tracked without it"
                prior, gyro_box = None, None
                result = self._tracker.update(frame)
            ms = (time.perf_counter() - start) * 1e3
            with self._lock:
                return self._record(frame, t, result, prior is not None, gyro_reason, gyro_box, ms)

    def _check_stamp(self, t: int) -> str:
        """"" if a frame stamped ``t`` can be processed, else why not (handles clock resets)."""
        last = self._last_stamp
        if last is None or t > last:
            return ""
        back = last - t
        if back > self._cfg.clock_reset_ms * 1e6:
            self.counters["clock_resets"] += 1
            self._last["frame_reason"] = f"image clock jumped back by {_ms(back)}: treated as a clock reset"
            if self._ref is not None:
                self._ref = (t, self._ref[1], self._ref[2])     # no rotation can be integrated across it
            newest = self._predictor.buffer.t_newest_ns
            if newest is not None and newest > self._predictor.imu_time(t) + self._cfg.clock_reset_ms * 1e6:
                self._predictor = self._new_predictor()   # the IMU is still on the old clock
            return ""
        if back == 0:
            return f"image stamp {t} ns repeats the previous frame's"
        return f"image stamp went back by {_ms(back)} (previous frame {last} ns)"

    def _gyro_prior(self, t: int):
        """(prior or None, predicted box or None, reason) for the frame at ``t``."""
        if not self._cfg.use_gyro:
            return None, None, "gyro disabled (use_gyro is false)"
        if self._predictor.camera is None:
            return None, None, "no camera_info received: the gyro prior needs K"
        t_ref, box, _ = self._ref
        if t == t_ref:
            return None, None, "frame has the window's own stamp"
        pred = self._predictor.predict(t_ref, t, box=box)
        if pred.prior is None:
            return None, None, pred.reason
        gyro_box = tuple(float(v) for v in pred.box) if pred.box is not None else None
        return pred.prior, gyro_box, pred.reason

    def _record(self, frame, t, result, gyro_used, gyro_reason, gyro_box, ms) -> FrameResult:
        c = self.counters
        c["frames_processed"] += 1
        c["gyro_used" if gyro_used else "gyro_unused"] += 1
        box = tuple(float(v) for v in result.box)
        if result.lost:
            c["frames_lost"] += 1
            self._lost_run += 1
            self._state = "lost"
        else:
            self._lost_run = 0
            self._state = "tracking"
            c["frames_held"] += bool(result.held)
            self._ref = (t, box, frame)
        emd = float(result.emd)
        score = math.exp(-emd / self._cfg.score_emd_scale) if not result.lost and math.isfinite(emd) else 0.0
        self._last["gyro_reason"] = gyro_reason
        self._last["frame_reason"] = result.reason
        self._recent.append((t, self._state))
        self._recent_proc.append((t, ms, gyro_used))
        out = FrameResult(t, self._state, box, emd, score, int(result.iterations), bool(result.lost), result.reason,
                          "", gyro_used, gyro_reason, gyro_box,
                          None if result.predicted_box is None else tuple(float(v) for v in result.predicted_box),
                          float(result.scale), int(result.starts), ms, float(result.angle))
        self._last_result = out
        return out

    # ------------------------------------------------------------------ diagnostics
    def last_reasons(self) -> dict:
        """Latest explanations: frame_reason, gyro_reason, imu_reason, image_error, camera_error, drop_reason."""
        with self._lock:
            return dict(self._last)

    def diagnostics(self) -> dict:
        """Snapshot: counters, state, latest reasons and recent rates (stamps-based) and timings."""
        with self._lock:
            d = dict(self.counters)
            d.update(self._last)
            d["state"] = self._state
            d["lost_run"] = self._lost_run
            camera = self._predictor.camera
            d["camera"] = "none" if camera is None else repr(camera)
            proc = list(self._recent_proc)
            d["processing_rate_hz"] = _rate([s for s, _, _ in proc])
            d["input_rate_hz"] = _rate([s for s, _ in self._recent])
            d["processing_ms_mean"] = float(np.mean([m for _, m, _ in proc])) if proc else math.nan
            d["processing_ms_max"] = float(np.max([m for _, m, _ in proc])) if proc else math.nan
            d["recent_dropped"] = sum(o == "dropped" for _, o in self._recent)
            d["recent_frames"] = len(self._recent)
            d["recent_gyro_used"] = sum(g for _, _, g in proc)
            d["recent_processed"] = len(proc)
            r = self._last_result
            d["emd"] = math.nan if r is None else r.emd
            d["iterations"] = 0 if r is None else r.iterations
            d["imu_stored"] = len(self._predictor.buffer)
            d["imu_pending"] = d["imu_stored"] if camera is None else 0     # held until camera_info
            d["bias_status"] = self._predictor.bias_estimator.status
            d["imu_bad_run"] = self._imu_bad_run
            d["image_bad"] = self._image_bad
            return d

    def statuses(self, prefix: str = "iemd_tracker") -> list[Status]:
        """OK/WARN/ERROR summaries: tracking, image input, IMU/gyro, camera_info."""
        with self._lock:     # everything from one moment (RLock: diagnostics() takes it again)
            d = self.diagnostics()
            cfg, last, model = self._cfg, self._last_result, self._predictor.camera
        fmt = {k: (f"{v:.3f}" if isinstance(v, float) else str(v)) for k, v in d.items()}

        def vals(*keys):
            return {k: fmt[k] for k in keys}

        # tracking
        if d["state"] == "uninitialized":
            trk = (WARN, "no target: set the initial_box parameter or publish on ~/init")
        elif d["state"] == "lost":
            lvl = ERROR if d["lost_run"] >= _LOST_ERROR_FRAMES else WARN
            trk = (lvl, f"target lost for {d['lost_run']} frame(s): {d['frame_reason']}")
        else:
            trk = (OK, f"tracking (EMD {d['emd']:.4f}, {d['iterations']} iterations)")
        tracking = Status(f"{prefix}: tracking", *trk,
                          vals("state", "emd", "iterations", "lost_run", "frames_lost", "frames_held", "processing_ms_mean",
                               "processing_ms_max", "processing_rate_hz", "inits", "resets", "frame_reason"))
        # image input
        if d["image_bad"]:
            img = (ERROR, f"latest image rejected: {d['image_error']}")
        elif d["frames_received"] == 0:
            img = (WARN, "no image received yet")
        elif d["recent_frames"] and d["recent_dropped"] > d["recent_frames"] // 2:
            img = (WARN, f"processing falls behind: {d['recent_dropped']} of the last {d['recent_frames']} "
                         "frames dropped (the newest is kept)")
        elif d["frames_rejected"] and d["frame_reason"].startswith("image stamp"):
            img = (WARN, f"latest rejected frame: {d['frame_reason']}")
        else:
            img = (OK, f"{d['input_rate_hz']:.1f} Hz in, {d['processing_rate_hz']:.1f} Hz processed")
        image = Status(f"{prefix}: image input", *img,
                       vals("frames_received", "frames_processed", "frames_dropped", "frames_rejected",
                            "images_malformed", "input_rate_hz", "processing_rate_hz", "recent_dropped",
                            "image_error", "drop_reason", "clock_resets"))
        # IMU / gyro
        if not cfg.use_gyro:
            imu = (OK, "gyro prior disabled (use_gyro is false)")
        elif d["imu_bad_run"] >= _IMU_ERROR_RUN:
            imu = (ERROR, f"the last {d['imu_bad_run']} IMU samples were rejected: {d['imu_reason']}")
        elif d["imu_received"] == 0:
            imu = (WARN, "no IMU message received: tracking without the gyro prior")
        elif d["imu_bad_run"]:
            imu = (WARN, d["imu_reason"])
        elif d["recent_processed"] and last is not None and not last.gyro_used:
            imu = (WARN, f"latest frame tracked without the gyro prior: {d['gyro_reason']}")
        else:
            imu = (OK, f"gyro prior used on {d['recent_gyro_used']} of the last {d['recent_processed']} frames")
        keys = ["imu_received", "imu_rejected", "imu_out_of_order", "imu_saturated", "imu_stored", "imu_pending",
                "gyro_used", "gyro_unused", "recent_gyro_used", "gyro_reason", "imu_reason", "bias_status"]
        imu_status = Status(f"{prefix}: imu", *imu, vals(*keys))
        # camera_info
        if model is None:
            if d["camera_error"]:
                cam = (ERROR, f"camera_info rejected: {d['camera_error']}")
            elif cfg.use_gyro:
                cam = (WARN, "no camera_info received: the gyro prior needs K")
            else:
                cam = (OK, "no camera_info (not needed: gyro disabled)")
        elif d["camera_error"]:
            cam = (WARN, f"latest camera_info rejected ({d['camera_error']}); keeping the previous one")
        else:
            cam = (OK, "camera model received")
        camera = Status(f"{prefix}: camera_info", *cam, vals("camera", "camera_infos", "camera_infos_rejected",
                                                              "camera_error"))
        return [tracking, image, imu_status, camera]


def _rate(stamps) -> float:
    """Frames per second of message stamps (ns) over their span; nan with fewer than two."""
    if len(stamps) < 2:
        return math.nan
    span = (max(stamps) - min(stamps)) * 1e-9
    return (len(stamps) - 1) / span if span > 0 else math.nan


def _same_gyro(a: GyroConfig, b: GyroConfig) -> bool:
    return gyro_config_to_dict(a) == gyro_config_to_dict(b)
