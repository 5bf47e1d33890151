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
Message-level tracking pipeline (ROS-free): images, gyro and camera info in, tracked boxes out.

The one place where per-message data flows into :class:`~iemd_ros.tracking.IemdTracker` and
:class:`~iemd_ros.gyro.GyroPredictor`; the ROS node (:mod:`iemd_ros.ros.node`) and the bag replay
(:mod:`iemd_ros.bags.replay`) both feed it, so they produce the same boxes from the same messages::

    pipe = TrackingPipeline(PipelineConfig())
    pipe.set_camera(camera)                      # from CameraInfo (camera_model_from_msg)
    pipe.add_imu(t_ns, (wx, wy, wz))             # every Imu message (IMU frame, rad/s)
    pipe.init(frame, (x, y, w, h), t_ns)         # start (or restart) on a frame: its FrameResult
    result = pipe.process(frame, t_ns)           # FrameResult, once ImuWait lets the frame go
    statuses(pipe.diagnostics())                 # OK/WARN/ERROR summaries for /diagnostics

Several targets: ``init(frame, box, t_ns, target_id="car")`` adds a target (or restarts the one of
that id), ``drop("car")`` forgets one, ``reset()`` all; :meth:`TrackingPipeline.process_all` tracks
every target into a frame and returns one FrameResult per target.  The targets share the IMU
buffer, and the gyro rotation between two frames is integrated once for all of them (only the local
fit of the prior is per box).

Gyro prior (paper, section 5.2): the rotation is integrated from the previous frame the tracker
updated on to the new frame, and the lens-aware ``K R^T K^-1`` prior is fitted at the window the
tracker holds; while the target is lost that window is its predicted place, so it keeps moving with
the camera, out of the image and back.

Everything that decides a result depends only on the messages (stamps and contents), never on the
wall clock, so replaying the same messages twice gives identical results; only
``FrameResult.processing_ms`` and the ``*_ms`` diagnostic values are wall-clock measurements, and a
live pipeline's watchdog, which abandons an update that overruns ``watchdog_ms`` (an offline one,
``live=False``, has none).

Thread safety: :meth:`add_imu`, :meth:`set_camera` and the ``note_*`` methods may be called from
other threads while :meth:`process` runs; they never wait for a tracker update to finish.
"""
from __future__ import annotations

from collections import deque
from dataclasses import replace
import functools
import math
from pathlib import Path
import threading
import time

from iemd_ros.gyro import CameraModel, GyroPredictor
from iemd_ros.gyro.frames import frame_name
from iemd_ros.gyro.imu import SampleStatus
from iemd_ros.gyro.predictor import warm_up as warm_up_gyro
from iemd_ros.pipeline.config import PipelineConfig
from iemd_ros.pipeline.diagnostics import rate_hz, Status, statuses
from iemd_ros.pipeline.results import (
    DEFAULT_TARGET,
    ExtrinsicSource,
    FrameResult,
    INIT_REASON,
    Rejection,
    TrackState,
)
from iemd_ros.pipeline.watchdog import Abandoned, Watchdog
from iemd_ros.tracking import IemdTracker
from iemd_ros.tracking.tracker import warm_up as warm_up_tracker
import numpy as np

__all__ = ['TrackingPipeline', 'warm_up_kernels', 'kernels_cached', 'kernel_cache_dir']

_WINDOW = 30  # recent frames / IMU messages the diagnostics look at


def kernel_cache_dir() -> Path:
    """
    Where numba caches the kernels.

    The ``__pycache__`` folders of the installed package (its root here).

    Returns
    -------
    Path
        The package's folder.

    """
    return Path(__file__).resolve().parents[1]


def kernels_cached() -> bool:
    """
    Whether numba's cache beside the package holds kernels already.

    (else the first pipeline of a process compiles them, 10-30 s).

    Returns
    -------
    bool
        True when a cache index is there.

    """
    return any(kernel_cache_dir().glob('*/__pycache__/*.nbi'))


@functools.cache
def warm_up_kernels() -> bool:
    """
    Return the tracker's and the gyro's numba kernels.

    Compiled (or loaded from numba's cache) once per process, at the first pipeline's start-up, not
    on the first frames.

    Returns
    -------
    bool
        Whether they were in the cache already.

    """
    cached = kernels_cached()
    warm_up_tracker()
    warm_up_gyro()
    return cached


def _ms(ns: float) -> str:
    return f'{ns / 1e6:.1f} ms'


class _Target:
    """One target's tracker state: the tracker, the window it holds and its state."""

    def __init__(self, target_id: str, tracker: IemdTracker, ref: tuple[int, tuple, np.ndarray]):
        self.id = target_id
        self.tracker = tracker
        # (stamp, window box, frame) of the last frame not lost: restarts
        self.ref = ref
        # (stamp, box) the tracker holds, lost or not: the gyro prior's start
        self.window = ref[:2]
        self.state = TrackState.TRACKING
        self.lost_run = 0
        self.lost_since: int | None = None  # stamp of the first frame of the current lost run
        self.last_result: FrameResult | None = None

    def restart(self, tracker: IemdTracker) -> None:
        """Restart at the window it holds with ``tracker``, on the frame that window is of."""
        _, box, frame = self.ref
        self.tracker = tracker
        self.tracker.init(frame, box)
        self.state, self.lost_run, self.lost_since, self.window = (
            TrackState.TRACKING, 0, None, self.ref[:2])


class TrackingPipeline:
    """
    Tracker + gyro predictor fed message by message (see the module docstring).

    The first pipeline of a process compiles the tracker's and the gyro's numba kernels (or loads
    them from numba's cache) at its start-up, not on the first frames.

    Parameters
    ----------
    config : PipelineConfig, optional
        Default ``PipelineConfig()``.
    camera : CameraModel, optional
        The calibration, if known (else :meth:`set_camera` later).
    live : bool, optional
        Frames arrive as they are taken (the node; default): the trackers learn after a result
        has gone back and run a frame's models side by side on threads, and the ``watchdog_ms``
        watchdog bounds each update.  False, for recorded frames processed back to back (the
        replay): everything runs in the caller's thread and no update is abandoned, so no result
        depends on the wall clock; the results are the same, at a higher frame rate
        (docs/decisions.md#offline-inline).

    Raises
    ------
    ValueError
        For a ``config`` that is not a PipelineConfig.

    """

    def __init__(
        self,
        config: PipelineConfig | None = None,
        camera: CameraModel | None = None,
        *,
        live: bool = True,
    ):
        warm_up_kernels()
        self._live = bool(live)
        self._cfg = config if config is not None else PipelineConfig()
        if not isinstance(self._cfg, PipelineConfig):
            raise ValueError('config must be a PipelineConfig')
        self._lock = threading.RLock()  # IMU / camera / counters (held briefly)
        self._track_lock = threading.RLock()  # tracker state (held during a tracker update)
        # camera-IMU rotation from TF (None: gyro.R_cam_imu)
        self._tf_rotation: np.ndarray | None = None
        # (IMU frame, camera frame) as the messages name them
        self._frames = ('', '')
        # buffers the IMU from the start; K comes later
        self._predictor = GyroPredictor(None, self._gyro_config())
        self._targets: dict[str, _Target] = {}
        self._last_stamp: int | None = None
        self.counters = {
            'frames_received': 0,
            'frames_processed': 0,
            'frames_uninitialized': 0,
            'frames_dropped': 0,
            'frames_rejected': 0,
            'images_malformed': 0,
            'frames_lost': 0,
            'frames_held': 0,
            'gyro_used': 0,
            'gyro_unused': 0,
            'imu_received': 0,
            'imu_rejected': 0,
            'imu_out_of_order': 0,
            'imu_saturated': 0,
            'clock_resets': 0,
            'camera_infos': 0,
            'camera_infos_rejected': 0,
            'inits': 0,
            'resets': 0,
            'updates_abandoned': 0,
        }
        self._last = {
            'frame_reason': '',
            'gyro_reason': '',
            'imu_reason': '',
            'image_error': '',
            'camera_error': '',
            'drop_reason': '',
            'camera_misfit': '',
            'watchdog_reason': '',
        }
        self._watchdog = Watchdog() if self._live else None  # offline updates are not bounded
        self._last_result: FrameResult | None = None  # the latest tracked result of any target
        self._image_bad = False  # the latest image message was malformed
        self._stamp_rejected = False  # the latest frame was rejected for its stamp
        self._imu_bad_run = 0  # consecutive rejected IMU messages
        self._recent = deque(maxlen=_WINDOW)  # (stamp, outcome) of received frames
        # (stamp, processing_ms, gyro_used) of tracked frames
        self._recent_proc = deque(maxlen=_WINDOW)
        if camera is not None:
            self.set_camera(camera)

    # ------------------------------------------------------------------ configuration
    @property
    def config(self) -> PipelineConfig:
        """Return the current configuration."""
        return self._cfg

    @property
    def state(self) -> TrackState:
        """
        Return the tracking state.

        Uninitialized without a target, tracking while any target is tracked.

        Else lost.
        """
        with self._lock:
            return self._overall_state()

    def _overall_state(self) -> TrackState:
        states = {t.state for t in self._targets.values()}
        if not states:
            return TrackState.UNINITIALIZED
        return TrackState.TRACKING if TrackState.TRACKING in states else TrackState.LOST

    @property
    def targets(self) -> list[str]:
        """Return the ids of the targets, in the order they were added."""
        with self._lock:
            return list(self._targets)

    def target_state(self, target_id: str) -> TrackState:
        """
        Return the state of one target (uninitialized when there is no such target).

        Parameters
        ----------
        target_id : str
            The target's id.

        Returns
        -------
        TrackState
            Its state.

        """
        with self._lock:
            target = self._targets.get(target_id)
            return TrackState.UNINITIALIZED if target is None else target.state

    @property
    def camera(self) -> CameraModel | None:
        """Return the camera model of the gyro prior (None until one is set)."""
        return self._predictor.camera

    def configure(self, config: PipelineConfig) -> str:
        """
        Apply a new configuration.

        A changed tracker configuration restarts the tracker at its current window on the frame
        that window belongs to (the template is taken again there); a changed gyro configuration
        rebuilds the predictor, keeping the buffered IMU samples.

        Parameters
        ----------
        config : PipelineConfig
            The new configuration.

        Returns
        -------
        str
            A one-line summary of what changed.

        Raises
        ------
        ValueError
            For a ``config`` that is not a PipelineConfig.

        """
        if not isinstance(config, PipelineConfig):
            raise ValueError('config must be a PipelineConfig')
        with self._track_lock, self._lock:
            old, self._cfg = self._cfg, config
            notes = []
            if config.gyro.to_dict() != old.gyro.to_dict():
                self._rebuild_predictor()
                notes.append('gyro predictor rebuilt (IMU samples kept)')
            if config.tracker != old.tracker:
                for target in self._targets.values():
                    target.restart(self._new_tracker())
                notes.append(
                    'tracker restarted at its current window'
                    if self._targets
                    else 'tracker configuration stored'
                )
            return '; '.join(notes) or 'no change'

    # ------------------------------------------------------------------ inputs
    def set_camera(self, camera: CameraModel) -> bool:
        """
        Use ``camera`` (K, D) for the gyro prior.

        Parameters
        ----------
        camera : CameraModel
            The calibration.

        Returns
        -------
        bool
            True when it differs from the current one.

        Raises
        ------
        ValueError
            For a ``camera`` that is not a CameraModel.

        """
        if not isinstance(camera, CameraModel):
            raise ValueError(f'camera must be a CameraModel, got {type(camera).__name__}')
        with self._lock:
            self.counters['camera_infos'] += 1
            self._last['camera_error'] = ''
            cur = self._predictor.camera
            if (
                cur is not None
                and np.array_equal(cur.K, camera.K)
                and np.array_equal(cur.D, camera.D)
                and (cur.width, cur.height) == (camera.width, camera.height)
            ):
                return False
            self._predictor.camera = camera
            return True

    def note_bad_camera_info(self, reason: str) -> None:
        """
        Record a CameraInfo message that could not be used (the previous camera, if any, stays).

        Parameters
        ----------
        reason : str
            Why it could not be used.

        """
        with self._lock:
            self.counters['camera_infos_rejected'] += 1
            self._last['camera_error'] = reason

    def _rebuild_predictor(self) -> None:
        """
        Build a new GyroPredictor for the current gyro config.

        Fed the samples buffered so far.
        """
        t, w = self._predictor.buffer.samples()
        self._predictor = self._new_predictor()
        if len(t):
            self._predictor.add_imu(t, w)

    def add_imu(self, t_ns: int, gyro_xyz) -> bool:
        """
        Add one gyro sample.

        Non-finite rates and saturated samples are rejected and counted (the IMU buffer screens
        them); an accepted stamp earlier than the newest one is counted (the buffer puts it in
        order) and, if earlier by more than ``clock_reset_ms``, restarts the IMU buffer (a clock
        reset).  ``last_reasons()['imu_reason']`` says why.

        Parameters
        ----------
        t_ns : int
            Stamp, IMU clock, ns.
        gyro_xyz : array_like
            IMU-frame rate in rad/s, 3 values.

        Returns
        -------
        bool
            False if the sample was rejected.

        Raises
        ------
        ValueError
            If ``gyro_xyz`` is not 3 values.

        """
        t = int(t_ns)
        w = np.asarray(gyro_xyz, dtype=float).ravel()
        with self._lock:
            c = self.counters
            c['imu_received'] += 1
            newest = self._predictor.buffer.t_newest_ns
            back = 0 if newest is None else newest - t
            reset = back > self._cfg.clock_reset_ms * 1e6
            # on a clock reset the sample goes to a new predictor, kept only if the sample is
            # accepted
            predictor = self._new_predictor() if reset else self._predictor
            status = int(predictor.add_imu(t, w)[0])
            if status == SampleStatus.NOT_FINITE:
                return self._reject_imu(
                    'imu_rejected',
                    f'IMU sample at {t} ns rejected: angular velocity '
                    f'{w.tolist()} is not 3 finite values',
                )
            if status == SampleStatus.SATURATED:
                return self._reject_imu(
                    'imu_saturated',
                    f'IMU sample at {t} ns rejected: |w| reaches the '
                    f'saturation limit {self._cfg.gyro.saturation} rad/s',
                )
            if reset:
                c['clock_resets'] += 1
                self._last['imu_reason'] = (
                    f'IMU clock jumped back by {_ms(back)}: IMU buffer restarted'
                )
                # holding the first sample on the new clock
                self._predictor = predictor
            elif back > 0:
                # The buffer's out_of_order count tests the same (an accepted stamp below the
                # newest accepted one), but it restarts with every new predictor (IMU clock reset,
                # image clock reset with the IMU still on the old clock, gyro reconfiguration:
                # samples re-fed in order); this one counts over the pipeline's life, like the
                # other /diagnostics counters.
                c['imu_out_of_order'] += 1
                self._last['imu_reason'] = (
                    f'IMU stamp went back by {_ms(back)} (sample put in order)'
                )
            self._imu_bad_run = 0
            return True

    def _reject_imu(self, counter: str, reason: str) -> bool:
        """Count a rejected IMU message under ``counter``; returns False (add_imu's answer)."""
        self.counters[counter] += 1
        self._imu_bad_run += 1
        self._last['imu_reason'] = reason
        return False

    def add_imu_message(
        self, t_ns: int, angular_velocity_xyz, angular_velocity_covariance0: float
    ) -> bool:
        """
        Add a sensor_msgs/Imu's rates: REP 145's covariance[0] = -1 means "no angular velocity".

        Parameters
        ----------
        t_ns : int
            The message's stamp, ns.
        angular_velocity_xyz : array_like
            Its angular velocity, rad/s.
        angular_velocity_covariance0 : float
            Its ``angular_velocity_covariance[0]``.

        Returns
        -------
        bool
            False if the message was rejected (no angular velocity, or as :meth:`add_imu`).

        Raises
        ------
        ValueError
            If the angular velocity is not 3 values.

        """
        if angular_velocity_covariance0 == -1.0:
            self.note_bad_imu(
                'IMU message has angular_velocity_covariance[0] = -1: no angular velocity'
            )
            return False
        return self.add_imu(t_ns, angular_velocity_xyz)

    def note_bad_imu(self, reason: str) -> None:
        """
        Count an IMU message that carries no usable rate (e.g. covariance[0] = -1: no gyro).

        Parameters
        ----------
        reason : str
            Why it carries none.

        """
        with self._lock:
            self.counters['imu_received'] += 1
            self._reject_imu('imu_rejected', reason)

    def _new_predictor(self) -> GyroPredictor:
        """Return an empty GyroPredictor for the current camera and gyro configuration."""
        return GyroPredictor(self._predictor.camera, self._gyro_config())

    def _gyro_config(self):
        """``gyro.*`` with the camera-IMU rotation from TF when one is known."""
        if self._tf_rotation is None:
            return self._cfg.gyro
        return replace(
            self._cfg.gyro,
            R_cam_imu=tuple(float(v) for v in np.clip(self._tf_rotation, -1, 1).ravel()),
        )

    def set_extrinsic(self, rotation, imu_frame: str = '', camera_frame: str = '') -> bool:
        """
        Use the camera-IMU rotation found between the IMU's and the image's frames.

        (TF) instead of ``gyro.R_cam_imu``; None goes back to the parameter.

        A changed rotation rebuilds the gyro predictor, keeping the buffered IMU samples (they are
        integrated in the camera frame through it).

        Parameters
        ----------
        rotation : array_like or None
            3x3 orientation of the IMU frame in the camera frame (``w_cam = R w_imu``), or None.
        imu_frame, camera_frame : str, optional
            The frames as the messages name them (the diagnostics say which they are).

        Returns
        -------
        bool
            True when the rotation in use changed.

        Raises
        ------
        ValueError
            For a rotation that is not a proper 3x3 rotation matrix.

        """
        R = None if rotation is None else np.asarray(rotation, dtype=float)
        if R is not None and (
            R.shape != (3, 3)
            or not np.allclose(R @ R.T, np.eye(3), atol=1e-6)
            or np.linalg.det(R) < 0
        ):
            raise ValueError(
                'the camera-IMU rotation must be a proper 3x3 rotation, got '
                f'{np.asarray(rotation).tolist()}'
            )
        with self._lock:
            self._frames = (str(imu_frame), str(camera_frame))
            old = self._tf_rotation
            if (old is None and R is None) or (
                old is not None and R is not None and np.array_equal(old, R)
            ):
                return False
            self._tf_rotation = R
            self._rebuild_predictor()
            return True

    @property
    def extrinsic(self) -> tuple[ExtrinsicSource, np.ndarray]:
        """Where the camera-IMU rotation in use comes from, and the rotation."""
        with self._lock:
            source = ExtrinsicSource.PARAMETER if self._tf_rotation is None else ExtrinsicSource.TF
            return source, self._predictor.calibration.R_cam_imu.copy()

    def note_dropped(
        self, stamp_ns: int, reason: str = 'a newer frame arrived before this one was processed'
    ) -> None:
        """
        Count a frame the caller skipped (e.g. stale: processing fell behind).

        Parameters
        ----------
        stamp_ns : int
            The frame's stamp, ns.
        reason : str, optional
            Why it was skipped.

        """
        with self._lock:
            self.counters['frames_received'] += 1
            self.counters['frames_dropped'] += 1
            self._last['drop_reason'] = reason
            self._recent.append((int(stamp_ns), 'dropped'))

    def note_bad_image(self, reason: str, stamp_ns: int | None = None) -> FrameResult | None:
        """
        Count an image message that could not be converted.

        (wrong encoding, step or size, or no decode).

        Parameters
        ----------
        reason : str
            Why it could not be converted.
        stamp_ns : int, optional
            The message's stamp, if known.

        Returns
        -------
        FrameResult or None
            The frame's result, rejected as malformed; None without a stamp.

        """
        with self._lock:
            self.counters['frames_received'] += 1
            self.counters['images_malformed'] += 1
            self._last['image_error'] = reason
            self._image_bad = True
            if stamp_ns is None:
                return None
            self._recent.append((int(stamp_ns), 'malformed'))
            return FrameResult(
                stamp_ns=int(stamp_ns),
                state=self._overall_state(),
                rejection=Rejection.MALFORMED,
                reason=f'malformed: {reason}',
            )

    # ------------------------------------------------------------------ tracking
    def gyro_ready(self, stamp_ns: int) -> bool:
        """
        Return True when processing the frame now loses nothing.

        The gyro covers it, or no prior can be used anyway (gyro off, no camera, no target).
        False: waiting for IMU samples may help.

        Parameters
        ----------
        stamp_ns : int
            The frame's stamp, camera clock, ns.

        Returns
        -------
        bool
            Whether the frame may go now.

        """
        with self._lock:
            if not self._cfg.use_gyro or self._predictor.camera is None or not self._targets:
                return True
            return self._predictor.ready(int(stamp_ns))

    def init(
        self, frame: np.ndarray, box, stamp_ns: int, target_id: str = DEFAULT_TARGET
    ) -> FrameResult:
        """
        (Re)start tracking the target ``box`` in ``frame`` stamped ``stamp_ns``.

        A new ``target_id`` adds a target; an existing one is restarted on this box (the other
        targets go on).

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 frame.
        box : sequence of 4 float
            (x, y, w, h), 0-based top-left corner and size in pixels.
        stamp_ns : int
            The frame's stamp, camera clock, ns.
        target_id : str, optional
            The target's id (default :data:`DEFAULT_TARGET`).

        Returns
        -------
        FrameResult
            The frame's result: ``box``, score 1, ``is_init``, ``reason`` :data:`INIT_REASON`.

        Raises
        ------
        ValueError
            For a bad frame or box (the previous target of that id, if any, is kept then), or an id
            that is not text.

        """
        if not isinstance(target_id, str):
            raise ValueError(f'target_id must be text, got {target_id!r}')
        with self._track_lock:
            tracker = self._new_tracker()
            tracker.init(frame, box)
            box = tuple(float(v) for v in box)
            with self._lock:
                self._targets[target_id] = _Target(target_id, tracker, (int(stamp_ns), box, frame))
                self.counters['inits'] += 1
                self._last['frame_reason'] = self._last['watchdog_reason'] = ''
                if self._last_stamp is None or int(stamp_ns) > self._last_stamp:
                    self._last_stamp = int(stamp_ns)
        return FrameResult(
            stamp_ns=int(stamp_ns),
            state=TrackState.TRACKING,
            box=box,
            score=1.0,
            reason=INIT_REASON,
            is_init=True,
            target_id=target_id,
        )

    def drop(self, target_id: str) -> bool:
        """
        Forget one target; the others go on.

        Parameters
        ----------
        target_id : str
            The target's id.

        Returns
        -------
        bool
            False when there was no such target.

        """
        with self._track_lock, self._lock:
            return self._targets.pop(target_id, None) is not None

    def reset(self) -> None:
        """Forget every target (state "uninitialized"); IMU and camera are kept."""
        with self._track_lock, self._lock:
            self._targets.clear()
            self._last_result = None
            self._last['watchdog_reason'] = ''
            self.counters['resets'] += 1

    def process(self, frame: np.ndarray, stamp_ns: int) -> FrameResult:
        """
        Track the one target into ``frame`` (:meth:`process_all` for several).

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 frame.
        stamp_ns : int
            The frame's stamp, camera clock, ns.

        Returns
        -------
        FrameResult
            The frame's result; see :class:`FrameResult`.

        Raises
        ------
        ValueError
            For a bad frame, or when there are several targets.

        """
        results = self.process_all(frame, stamp_ns)
        if len(results) != 1:
            raise ValueError(
                f'process() tracks one target, there are {len(results)}: use process_all()'
            )
        return results[0]

    def process_all(self, frame: np.ndarray, stamp_ns: int) -> list[FrameResult]:
        """
        Track every target into ``frame``.

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 frame.
        stamp_ns : int
            The frame's stamp, camera clock, ns.

        Returns
        -------
        list of FrameResult
            One per target, in the order of :attr:`targets`; a single result (without a box) when
            the frame is rejected for its stamp or there is no target.

        Raises
        ------
        ValueError
            For a bad frame.

        """
        t = int(stamp_ns)
        with self._track_lock:
            with self._lock:
                self.counters['frames_received'] += 1
                self._image_bad = False
                rejected = self._check_stamp(t)
                self._stamp_rejected = bool(rejected)
                if rejected:
                    self.counters['frames_rejected'] += 1
                    self._recent.append((t, 'rejected'))
                    self._last['frame_reason'] = rejected
                    return [
                        FrameResult(
                            stamp_ns=t,
                            state=self._overall_state(),
                            rejection=Rejection.STAMP,
                            reason=rejected,
                        )
                    ]
                self._last_stamp = t
                if not self._targets:
                    self.counters['frames_uninitialized'] += 1
                    self._recent.append((t, 'uninitialized'))
                    return [
                        FrameResult(
                            stamp_ns=t,
                            state=TrackState.UNINITIALIZED,
                            reason='no target: waiting for an initial box',
                        )
                    ]
                targets = list(self._targets.values())
                priors = self._gyro_priors(t, frame, targets)
            start = time.perf_counter()
            results = [
                self._track(target, frame, t, *prior) for target, prior in zip(targets, priors)
            ]
            with self._lock:
                # not all abandoned by the watchdog
                if any(r.rejection is None for r in results):
                    self.counters['frames_processed'] += 1
                    self._recent.append((t, self._overall_state().value))
                    self._recent_proc.append(
                        (t, (time.perf_counter() - start) * 1e3, any(r.gyro_used for r in results))
                    )
            return results

    def _track(self, target: _Target, frame, t: int, prior, gyro_box, gyro_reason) -> FrameResult:
        """One target's update into the frame at ``t`` (under the track lock)."""
        start = time.perf_counter()
        # the models learn for the time since the window's frame, not for one frame
        # (docs/decisions.md#frame-interval-learning)
        t_ref = target.window[0]
        interval = (t - t_ref) / 1e9 if t > t_ref else None
        try:
            try:
                result = self._update(target, frame, prior, interval)
            except ValueError as exc:
                if prior is None:
                    raise
                gyro_reason = f'gyro prior not usable ({exc}); tracked without it'
                prior, gyro_box = None, None
                result = self._update(target, frame, None, interval)
        except Abandoned as exc:
            return self._abandon(target, t, exc)
        ms = (time.perf_counter() - start) * 1e3
        with self._lock:
            return self._record(
                target, frame, t, result, prior is not None, gyro_reason, gyro_box, ms
            )

    def _new_tracker(self) -> IemdTracker:
        """Return a tracker of the configured parameters, threaded when the pipeline is live."""
        return IemdTracker(self._cfg.tracker, threads=self._live)

    def _update(self, target: _Target, frame, prior, interval):
        """
        Return the tracker's update, under the watchdog when live.

        (:class:`Abandoned` when it overruns ``watchdog_ms``).
        """
        tracker = target.tracker
        if not self._live:
            return tracker.update(frame, prior=prior, interval=interval)
        return self._watchdog.run(
            lambda: tracker.update(frame, prior=prior, interval=interval),
            self._cfg.watchdog_ms / 1e3,
        )

    def _abandon(self, target: _Target, t: int, exc: Abandoned) -> FrameResult:
        """
        Return the result of the frame at ``t`` whose update was abandoned.

        (or not started: ``exc.ran`` False); the tracker is rebuilt at its last good window (the
        init frame or the last frame not lost), the abandoned one is left to its thread.
        """
        t_ref, box, ref_frame = target.ref
        if exc.ran:
            tracker = self._new_tracker()
            tracker.init(ref_frame, box)
            target.window = target.ref[:2]
            reason = (
                f'tracker update abandoned after {self._cfg.watchdog_ms:g} ms (watchdog_ms); the '
                'tracker is '
                f'rebuilt at its window of the frame stamped {t_ref} ns'
            )
        else:
            tracker = target.tracker
            reason = (f'tracker update {exc} (watchdog_ms {self._cfg.watchdog_ms:g} ms): '
                      'frame not tracked')
        with self._lock:
            target.tracker = tracker
            self.counters['updates_abandoned'] += exc.ran
            self._last['watchdog_reason'] = self._last['frame_reason'] = reason
            self._recent.append((t, Rejection.ABANDONED.value))
            return FrameResult(
                stamp_ns=t,
                state=target.state,
                rejection=Rejection.ABANDONED,
                reason=reason,
                target_id=target.id,
            )

    def _check_stamp(self, t: int) -> str:
        """
        Return "" if a frame stamped ``t`` can be processed.

        Else why not (handles clock resets).
        """
        last = self._last_stamp
        if last is None or t > last:
            return ''
        back = last - t
        if back > self._cfg.clock_reset_ms * 1e6:
            self.counters['clock_resets'] += 1
            self._last['frame_reason'] = (
                f'image clock jumped back by {_ms(back)}: treated as a clock reset'
            )
            self._recent.clear()  # the rates count from the reset
            self._recent_proc.clear()
            for target in self._targets.values():
                # no rotation can be integrated across it
                target.ref = (t, target.ref[1], target.ref[2])
                target.window = (t, target.window[1])
            newest = self._predictor.buffer.t_newest_ns
            if (
                newest is not None
                and newest > self._predictor.imu_time(t) + self._cfg.clock_reset_ms * 1e6
            ):
                self._predictor = self._new_predictor()  # the IMU is still on the old clock
            return ''
        if back == 0:
            return f"image stamp {t} ns repeats the previous frame's"
        return f'image stamp went back by {_ms(back)} (previous frame {last} ns)'

    def _gyro_priors(self, t: int, frame: np.ndarray, targets: list[_Target]) -> list[tuple]:
        """
        (prior or None, predicted box or None, reason) of each target for the frame at ``t``.

        The rotation is integrated once per window stamp (once for all targets tracked on the
        previous frame).
        """
        if not self._cfg.use_gyro:
            return [(None, None, 'gyro disabled (use_gyro is false)')] * len(targets)
        camera = self._predictor.camera
        if camera is None:
            return [(None, None, 'no camera_info received: the gyro prior needs K')] * len(targets)
        try:
            camera.check_image(frame.shape[1], frame.shape[0])
            self._last['camera_misfit'] = ''
        except ValueError as exc:
            self._last['camera_misfit'] = str(exc)
            return [(None, None, f'no gyro prior: {exc}')] * len(targets)
        rotations: dict[int, object] = {}
        out = []
        for target in targets:
            t_ref, box = target.window
            if t == t_ref:
                out.append((None, None, "frame has the window's own stamp"))
                continue
            try:
                if t_ref not in rotations:
                    rotations[t_ref] = self._predictor.homography(t_ref, t)
                pred = self._predictor.at_box(rotations[t_ref], box)
            # e.g. a rotation that cannot be integrated: the frame goes on without it
            except ValueError as exc:
                out.append((None, None, f'no gyro prior: {exc}'))
                continue
            if pred.prior is None:
                out.append((None, None, pred.reason))
                continue
            gyro_box = tuple(float(v) for v in pred.box) if pred.box is not None else None
            out.append((pred.prior, gyro_box, pred.reason))
        return out

    def _record(
        self, target: _Target, frame, t, result, gyro_used, gyro_reason, gyro_box, ms
    ) -> FrameResult:
        c = self.counters
        c['gyro_used' if gyro_used else 'gyro_unused'] += 1
        box = tuple(float(v) for v in result.box)
        target.window = (t, box)  # lost, the box is the predicted place: the gyro keeps moving it
        if result.lost:
            c['frames_lost'] += 1
            target.lost_run += 1
            target.lost_since = t if target.lost_since is None else target.lost_since
            target.state = TrackState.LOST
        else:
            target.lost_run, target.lost_since = 0, None
            target.state = TrackState.TRACKING
            c['frames_held'] += bool(result.held)
            target.ref = (t, box, frame)
        emd = float(result.emd)
        score = (
            math.exp(-emd / self._cfg.score_emd_scale)
            if not result.lost and math.isfinite(emd)
            else 0.0
        )
        self._last['gyro_reason'] = gyro_reason
        self._last['frame_reason'] = result.reason
        self._last['watchdog_reason'] = ''
        predicted = (
            None if result.predicted_box is None else tuple(float(v) for v in result.predicted_box)
        )
        out = FrameResult(
            stamp_ns=t,
            state=target.state,
            box=box,
            emd=emd,
            score=score,
            iterations=int(result.iterations),
            lost=bool(result.lost),
            held=bool(result.held),
            cause=result.cause,
            reason=result.reason,
            gyro_used=gyro_used,
            gyro_reason=gyro_reason,
            gyro_box=gyro_box,
            predicted_box=predicted,
            scale=float(result.scale),
            starts=int(result.starts),
            codings=int(result.codings),
            solver_warnings=int(result.solver_warnings),
            processing_ms=ms,
            angle=float(result.angle),
            target_id=target.id,
        )
        target.last_result = self._last_result = out
        return out

    # ------------------------------------------------------------------ diagnostics
    def last_reasons(self) -> dict:
        """
        Latest explanations.

        Returns
        -------
        dict
            The texts frame_reason, gyro_reason, imu_reason, image_error, camera_error, drop_reason
            and camera_misfit.

        """
        with self._lock:
            return dict(self._last)

    def diagnostics(self) -> dict:
        """
        Snapshot of the pipeline's state for the diagnostics.

        Returns
        -------
        dict
            Counters, state, latest reasons and recent rates (stamps-based) and timings.

        """
        with self._lock:
            d = dict(self.counters)
            d.update(self._last)
            d['state'] = self._overall_state().value
            d['lost_run'] = min((t.lost_run for t in self._targets.values()), default=0)
            lost = [t.lost_since for t in self._targets.values() if t.lost_since is not None]
            d['lost_s'] = (
                (self._last_stamp - max(lost)) / 1e9
                if lost and len(lost) == len(self._targets) and self._last_stamp is not None
                else 0.0
            )
            d['targets'] = ', '.join(
                f'{t.id or "(default)"}: {t.state.value}' for t in self._targets.values()
            )
            source = ExtrinsicSource.PARAMETER if self._tf_rotation is None else ExtrinsicSource.TF
            imu_frame, camera_frame = self._frames
            d['extrinsic_source'] = source.value
            d['imu_frame'], d['camera_frame'] = imu_frame, camera_frame
            d['R_cam_imu'] = np.round(self._predictor.calibration.R_cam_imu, 6).ravel().tolist()
            d['frames_unrelated'] = bool(
                source is ExtrinsicSource.PARAMETER
                and imu_frame
                and camera_frame
                and frame_name(imu_frame) != frame_name(camera_frame)
            )
            d['parameter_is_identity'] = bool(np.array_equal(self._cfg.gyro.rotation, np.eye(3)))
            camera = self._predictor.camera
            d['camera'] = 'none' if camera is None else repr(camera)
            proc = list(self._recent_proc)
            d['processing_rate_hz'] = rate_hz([s for s, _, _ in proc])
            d['input_rate_hz'] = rate_hz([s for s, _ in self._recent])
            d['processing_ms_mean'] = float(np.mean([m for _, m, _ in proc])) if proc else math.nan
            d['processing_ms_max'] = float(np.max([m for _, m, _ in proc])) if proc else math.nan
            d['recent_dropped'] = sum(o == 'dropped' for _, o in self._recent)
            d['recent_frames'] = len(self._recent)
            d['recent_gyro_used'] = sum(g for _, _, g in proc)
            d['recent_processed'] = len(proc)
            r = self._last_result
            d['emd'] = math.nan if r is None else r.emd
            d['iterations'] = 0 if r is None else r.iterations
            d['held'] = r is not None and r.held
            d['imu_stored'] = len(self._predictor.buffer)
            # held until camera_info
            d['imu_pending'] = d['imu_stored'] if camera is None else 0
            d['bias_status'] = self._predictor.bias_estimator.status
            d['imu_bad_run'] = self._imu_bad_run
            d['image_bad'] = self._image_bad
            d['stamp_rejected'] = self._stamp_rejected
            d['use_gyro'] = self._cfg.use_gyro
            d['has_camera'] = camera is not None
            d['last_gyro_used'] = None if r is None else r.gyro_used
            return d

    def statuses(self) -> list[Status]:
        """
        Return the OK/WARN/ERROR statuses of this moment.

        (:func:`iemd_ros.pipeline.diagnostics.statuses`).

        Returns
        -------
        list of Status
            Tracking, image input, IMU and camera_info.

        """
        return statuses(self.diagnostics())
