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
Offline replay of a bag through the tracking pipeline, as fast as the CPU allows (``iemd-replay``).

``BAG``: a rosbag2 folder (sqlite3 or mcap) or a ROS 1 ``.bag`` file (rosbags' AnyReader).  The
image, IMU and camera-info topics are auto-detected when the bag has one of each type, else named
(:func:`iemd_ros.bags.io.select_topics`).  The messages go, in the bag's (log-time) order, through
:class:`~iemd_ros.pipeline.TrackingPipeline` -- the same synchronization, gyro prediction and
tracker as the node -- deterministically: the pipeline runs offline (``live=False``: the tracker in
this thread, no watchdog), nothing depends on the wall clock, so the same bag gives the same CSV
byte for byte.  OpenCV runs single-threaded while a replay runs (:data:`OPENCV_THREADS`; its
setting is restored after).

IMU synchronization is the node's :class:`~iemd_ros.pipeline.ImuWait` on the bag's log times: a
frame is held until the gyro covers it or until ``imu_wait_ms`` of bag time has passed after it (a
message logged later than that is applied after the frame).  This is what the node does with the
bag played at 1x when its processing keeps up; the live node may in addition drop frames that
arrive while it is busy, the offline replay never drops.

The tracker starts from ``init_box`` (0-based pixels, top-left + size) on the first image that can
be decoded, as the node does with its ``initial_box``.

Outputs: the CSV (:data:`CSV_HEADER`, one row per image, floats in shortest round-trip form; the
init frame's row holds the init box with state ``init`` and an empty emd; a frame the pipeline
could not use has an empty box and state ``rejected``/``malformed``; ``held`` is 1 on a tracked
frame whose models did not learn), optionally a rosbag2 (mcap) with
``vision_msgs/Detection2DArray``, the ``foxglove_msgs/ImageAnnotations`` overlay, the annotated
frame as a JPEG ``sensor_msgs/CompressedImage`` and ``diagnostic_msgs/DiagnosticArray``, stamped
and logged like the images (open it in Foxglove: the Image panel shows the debug image, or the
input's image with the annotations drawn over it), and an annotated MP4 (``mp4v``).
"""
from __future__ import annotations

from collections import deque
import csv
from dataclasses import dataclass, field, replace
import math
from pathlib import Path
import sys
import time

import cv2
from iemd_ros.bags.io import (
    BagError,
    BagMessages,
    BagWriter,
    deserialize,
    iter_messages,
    open_bag,
    select_topics,
    Topics,
)
from iemd_ros.common.boxes import check_box
from iemd_ros.common.progress import Progress
from iemd_ros.gyro import CameraModel
from iemd_ros.messages.conversions import (
    array_to_compressed_fields,
    camera_model_from_msg,
    CLASS_ID,
    DETECTION_ID,
    image_from_msg,
    imu_sample,
    stamp_ns,
)
from iemd_ros.messages.outputs import (
    ANNOTATIONS_TYPE,
    COMPRESSED_IMAGE_TYPE,
    detection_array,
    DETECTIONS_TYPE,
    diagnostic_array,
    DIAGNOSTICS_TYPE,
    header,
    image_annotations,
)
from iemd_ros.pipeline import FrameResult, ImuWait, PipelineConfig, TrackingPipeline, TrackState
from iemd_ros.pipeline.drawing import box_colour, draw_result
import numpy as np

__all__ = [
    'Replay',
    'ReplayResult',
    'replay',
    'parse_box',
    'write_csv',
    'CSV_HEADER',
    'DETECTIONS_TOPIC',
    'DIAGNOSTICS_TOPIC',
    'ANNOTATIONS_TOPIC',
    'DEBUG_IMAGE_TOPIC',
]

CSV_HEADER = ('stamp_ns', 'x', 'y', 'w', 'h', 'emd', 'state', 'held')
# as the node publishes them (``detections`` in the root namespace, class_id "target", id "iemd")
DETECTIONS_TOPIC = '/detections'
DIAGNOSTICS_TOPIC = '/diagnostics'
ANNOTATIONS_TOPIC = '/iemd_tracker/annotations'
DEBUG_IMAGE_TOPIC = '/iemd_tracker/debug_image/compressed'
HARDWARE_ID = 'iemd_replay'
# OpenCV's threads while a replay runs: the tracker runs in this thread, and OpenCV's pool only
# adds synchronization to its small calls (docs/decisions.md#replay-opencv-threads)
OPENCV_THREADS = 1


@dataclass
class ReplayResult:
    """
    Per-image results and run statistics.

    Parameters
    ----------
    bag : str
        The bag replayed.
    topics : Topics
        The topics used.
    results : list of FrameResult
        One per image (the init frame's has ``is_init``; frames skipped with ``drop_stamps`` have
        none).
    wall_s : float
        Wall time of the whole replay (reading, decoding, tracking, writing), s.
    track_s : float
        Sum of the tracker's processing_ms (updates), s.
    warnings : list of str, optional
        The warnings given.
    diagnostics : dict, optional
        The pipeline's :meth:`~iemd_ros.pipeline.TrackingPipeline.diagnostics` at the end of the
        replay.
    dropped : list of int, optional
        Stamps skipped on request (``drop_stamps``).
    init_s : float, optional
        Time of the tracker's init on the first frame (one-off), s.

    """

    bag: str
    topics: Topics
    results: list[FrameResult]
    wall_s: float  # whole replay (reading, decoding, tracking, writing)
    track_s: float  # sum of the tracker's processing_ms (updates)
    warnings: list[str] = field(default_factory=list)
    diagnostics: dict = field(default_factory=dict)
    # stamps skipped on request (``drop_stamps``)
    dropped: list[int] = field(default_factory=list)
    init_s: float = 0.0  # the tracker's init on the first frame (one-off)

    @property
    def boxes(self) -> np.ndarray:
        """(N, 4) boxes, NaN where a frame gave none."""
        return np.array(
            [r.box if r.box is not None else (np.nan,) * 4 for r in self.results], dtype=float
        )

    @property
    def stamps_ns(self) -> np.ndarray:
        """(N,) stamps of the results, int64."""
        return np.array([r.stamp_ns for r in self.results], dtype=np.int64)

    @property
    def duration_s(self) -> float:
        """Bag time spanned by the images (first to last stamp plus one median frame interval)."""
        s = self.stamps_ns
        if len(s) < 2:
            return 0.0
        return float(s[-1] - s[0] + np.median(np.diff(s))) * 1e-9

    @property
    def realtime_factor(self) -> float:
        """Bag time / wall time (> 1: faster than real time)."""
        return self.duration_s / self.wall_s if self.wall_s > 0 else math.inf

    @property
    def gyro_used(self) -> int:
        """Return number of frames tracked with the gyro prior."""
        return sum(r.gyro_used for r in self.results)


def parse_box(box) -> tuple[float, float, float, float]:
    """
    Return the init box as 4 floats.

    Parameters
    ----------
    box : str or sequence of 4 float
        ``"X,Y,W,H"`` or 4 numbers.

    Returns
    -------
    tuple of float
        (x, y, w, h), finite with w, h > 0.

    Raises
    ------
    ValueError
        Naming ``--init``, for anything else.

    """
    return check_box(box.split(',') if isinstance(box, str) else box, '--init', shown=box)


def _fmt(v) -> str:
    return '' if v is None or (isinstance(v, float) and math.isnan(v)) else repr(float(v))


def csv_rows(results: list[FrameResult]):
    """
    Yield the CSV rows of :data:`CSV_HEADER` of ``results``.

    Parameters
    ----------
    results : list of FrameResult
        Per-image results.

    Yields
    ------
    list of str
        One row per result (see the module docstring).

    """
    for r in results:
        box = r.box if r.box is not None else (None,) * 4
        if r.is_init:
            state = 'init'
        elif r.rejection is not None:
            state = r.rejection.value
        else:
            state = r.state.value
        emd = None if r.is_init or r.rejection is not None else r.emd
        yield [str(int(r.stamp_ns)), *(_fmt(v) for v in box), _fmt(emd), state, str(int(r.held))]


def write_csv(path, results: list[FrameResult]) -> None:
    """
    Write the CSV of ``results``: :data:`CSV_HEADER`, then :func:`csv_rows`.

    Parameters
    ----------
    path : str or path-like
        The file written (its folder is created if needed).
    results : list of FrameResult
        Per-image results.

    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open('w', newline='') as f:
        w = csv.writer(f, lineterminator='\n')
        w.writerow(CSV_HEADER)
        w.writerows(csv_rows(results))


# ----------------------------------------------------------------------------------------------
# outputs
class _OutBag:
    """
    Detections, annotations, the annotated frame (JPEG) and diagnostics as a rosbag2 (mcap).

    Stamped and logged like the images.
    """

    def __init__(self, path, frame_topic: str):
        self.bag = BagWriter(path, 'mcap', {'iemd_ros.replay_of': frame_topic})
        self.bag.__enter__()
        for topic, msgtype in (
            (DETECTIONS_TOPIC, DETECTIONS_TYPE),
            (ANNOTATIONS_TOPIC, ANNOTATIONS_TYPE),
            (DEBUG_IMAGE_TOPIC, COMPRESSED_IMAGE_TYPE),
            (DIAGNOSTICS_TOPIC, DIAGNOSTICS_TYPE),
        ):
            self.bag.add_topic(topic, msgtype)
        self.make = BagMessages(self.bag)

    def write(
        self, log_t: int, frame_id: str, r: FrameResult, statuses, image: np.ndarray | None
    ) -> None:
        """
        Write the frame's Detection2DArray (one detection while ``r`` is tracking, else empty).

        Also its annotations, its drawing (when the frame decoded) and its statuses.
        """
        hdr = header(self.make, r.stamp_ns, frame_id)
        self.bag.write(
            DETECTIONS_TOPIC, log_t, detection_array(self.make, hdr, [r], CLASS_ID, DETECTION_ID)
        )
        self.bag.write(
            ANNOTATIONS_TOPIC,
            log_t,
            image_annotations(self.make, r.stamp_ns, [r], DETECTION_ID, box_colour),
        )
        if image is not None:
            fields = array_to_compressed_fields(draw_result(image, r), 'jpeg')
            fields['data'] = np.frombuffer(fields['data'], np.uint8)
            self.bag.write(
                DEBUG_IMAGE_TOPIC, log_t, self.make(COMPRESSED_IMAGE_TYPE, header=hdr, **fields)
            )
        rows = [(s.name('iemd_tracker'), s.level, s.message, s.values) for s in statuses]
        self.bag.write(
            DIAGNOSTICS_TOPIC, log_t, diagnostic_array(self.make, hdr, rows, HARDWARE_ID)
        )

    def close(self, exc_type=None) -> None:
        self.bag.__exit__(exc_type, None, None)


class _Video:
    """
    Annotated MP4 (mp4v), each frame drawn by :func:`iemd_ros.pipeline.drawing.draw_result`.

    The frame rate is the image rate of the bag: the first frame is held until the second one gives
    the interval.
    """

    def __init__(self, path):
        self.path, self.writer, self._held = Path(path), None, None

    def write(self, frame: np.ndarray, r: FrameResult) -> None:
        img = draw_result(frame, r)
        if self.writer is None:
            if self._held is None:
                self._held = (img, r.stamp_ns)
                return
            dt = (r.stamp_ns - self._held[1]) * 1e-9
            self._open(img.shape, 1.0 / dt if dt > 0 else 30.0)
            self.writer.write(self._held[0])
        self.writer.write(img)

    def _open(self, shape, fps: float) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        h, w = shape[:2]
        self.writer = cv2.VideoWriter(
            str(self.path),
            cv2.VideoWriter_fourcc(*'mp4v'),
            float(min(max(fps, 1.0), 240.0)),
            (w, h),
        )
        if not self.writer.isOpened():
            raise ValueError(f'cannot write video {self.path} (OpenCV mp4v writer failed to open)')

    def close(self) -> None:
        if self.writer is None and self._held is not None:
            self._open(self._held[0].shape, 30.0)
            self.writer.write(self._held[0])
        if self.writer is not None:
            self.writer.release()


# ----------------------------------------------------------------------------------------------
# replay kinds of _messages' items
_IMAGE, _IMU, _CAMERA, _BAD_CAMERA = 'image', 'imu', 'camera', 'bad camera'


@dataclass
class _Frame:
    log_t: int
    stamp: int
    frame_id: str
    image: np.ndarray | None
    error: str = ''


class Replay:
    """
    One offline run of a bag through :class:`~iemd_ros.pipeline.TrackingPipeline`.

    (see the module docstring).

    Parameters
    ----------
    bag : path
        A rosbag2 folder (or its ``metadata.yaml`` / storage file) or ROS 1 ``.bag``.
    init_box : str or sequence of 4 float
        ``"X,Y,W,H"`` or 4 numbers (:func:`parse_box`): the target on the first decodable image.
    image_topic, imu_topic, camera_info_topic : str, optional
        Topics to use (default: the bag's one topic of each type).
    config : PipelineConfig, optional
        Default ``PipelineConfig()``; ``use_gyro=False`` disables the prior (``--no-gyro``).
    use_gyro : bool, optional
        False disables the prior as well.
    camera : CameraModel, optional
        Calibration to use instead of the bag's camera info.
    warn : callable, optional
        Receives the warnings (default: printed to stderr).
    drop_stamps : iterable of int
        Images with these stamps are skipped and counted as dropped
        (``TrackingPipeline.note_dropped``), as the live node does with frames that arrive while it
        is busy: a live run reproduced offline.

    Raises
    ------
    ValueError
        (:class:`~iemd_ros.bags.io.BagError`) on bad input: a missing or truncated bag, no images,
        a topic of the wrong type, an init box outside the image.

    """

    def __init__(
        self,
        bag,
        init_box,
        *,
        image_topic: str | None = None,
        imu_topic: str | None = None,
        camera_info_topic: str | None = None,
        config: PipelineConfig | None = None,
        use_gyro: bool = True,
        camera: CameraModel | None = None,
        warn=None,
        drop_stamps=(),
    ):
        self.bag = bag
        self.init_box = parse_box(init_box)
        self._warn = (
            warn
            if warn is not None
            else (lambda s: print(f'iemd-replay: warning: {s}', file=sys.stderr))
        )
        self.warnings: list[str] = []
        self._camera = camera
        self._drop = {int(t) for t in drop_stamps}
        self._reader = open_bag(bag, warn=self._note)
        try:
            self.topics = select_topics(self._reader, image_topic, imu_topic, camera_info_topic)
            cfg = config if config is not None else PipelineConfig()
            self.use_gyro = self._gyro_usable(bool(use_gyro and cfg.use_gyro))
            self.pipeline = TrackingPipeline(
                replace(cfg, use_gyro=self.use_gyro), camera, live=False
            )
        except BaseException:
            self._reader.close()
            raise
        self._wait = ImuWait(self.pipeline)
        self._n_imu = self._reader.topics[self.topics.imu].msgcount if self.use_gyro else 0

    def _gyro_usable(self, wanted: bool) -> bool:
        if wanted and self.topics.imu is None:
            self._note(
                'the bag has no sensor_msgs/msg/Imu topic: replaying without the gyro prior'
            )
            return False
        if wanted and self.topics.camera_info is None and self._camera is None:
            self._note(
                'the bag has no sensor_msgs/msg/CameraInfo topic (the gyro prior needs K): '
                'replaying without the gyro prior'
            )
            return False
        return wanted

    def _note(self, text: str) -> None:
        self.warnings.append(text)
        self._warn(text)

    def run(
        self, csv_path=None, out_bag=None, video=None, progress: bool | None = None
    ) -> ReplayResult:
        """
        Replay the whole bag, writing the outputs asked for.

        (partial output files are removed on an error).

        Parameters
        ----------
        csv_path : str or path-like, optional
            The CSV of the results.
        out_bag : str or path-like, optional
            A new rosbag2 (mcap) of the detections and diagnostics.
        video : str or path-like, optional
            An annotated MP4.
        progress : bool, optional
            Show a progress bar (default: when stderr is a terminal).

        Returns
        -------
        ReplayResult
            The results and the run's statistics.

        Raises
        ------
        ValueError
            A :class:`~iemd_ros.bags.io.BagError` for a bag found truncated or corrupt while
            reading, or without a decodable image; a ValueError naming ``--init`` for an init box
            the first image refuses.

        """
        self._results: list[FrameResult] = []
        self._dropped: list[int] = []
        self._pending: deque[_Frame] = deque()
        self._imu_seen, self._init_s = 0, 0.0
        self._bar = Progress(
            self._reader.topics[self.topics.image].msgcount, 'iemd-replay', progress
        )
        self._out = _OutBag(out_bag, self.topics.image) if out_bag is not None else None
        self._video = _Video(video) if video is not None else None
        opencv_threads = cv2.getNumThreads()  # the caller's, restored below
        cv2.setNumThreads(OPENCV_THREADS)
        t_start = time.perf_counter()
        try:
            self._feed()
            self._bar.close()
            wall = time.perf_counter() - t_start
            if self.pipeline.state is TrackState.UNINITIALIZED and not self._dropped:
                first = self._results[0].reason if self._results else 'the topic is empty'
                raise BagError(
                    f'no image on {self.topics.image!r} of {self.bag} could be decoded: {first}'
                )
            if (
                self.use_gyro
                and self.pipeline.counters['camera_infos'] == 0
                and self._camera is None
            ):
                self._note('no usable camera info in the bag: tracked without the gyro prior')
            if csv_path is not None:
                write_csv(csv_path, self._results)
            self._close_outputs(None)
        except BaseException as exc:
            self._close_outputs(type(exc))
            if video is not None:
                Path(video).unlink(missing_ok=True)
            raise
        finally:
            self._reader.close()
            cv2.setNumThreads(opencv_threads)
        return ReplayResult(
            str(self.bag),
            self.topics,
            self._results,
            wall,
            sum(r.processing_ms for r in self._results) / 1e3,
            self.warnings,
            self.pipeline.diagnostics(),
            self._dropped,
            self._init_s,
        )

    def _close_outputs(self, exc_type) -> None:
        if self._out is not None:
            self._out.close(exc_type)
            self._out = None
        if self._video is not None:
            self._video.close()
            self._video = None

    def _feed(self) -> None:
        """
        Every message in log-time order.

        Before each, the held frames whose IMU wait ended earlier go.
        """
        messages = self._messages()
        try:
            for kind, log_t, item in messages:
                self._release(log_t)
                if kind is _IMAGE:
                    self._pending.append(item)
                elif kind is _IMU:
                    self._imu_seen += 1
                    self.pipeline.add_imu_message(*item)
                elif kind is _CAMERA:
                    self.pipeline.set_camera(item)
                else:
                    self.pipeline.note_bad_camera_info(item)
                self._release(None)
        finally:
            messages.close()
        while self._pending:
            self._process(self._pending.popleft())

    def _messages(self):
        """
        (kind, log time, item) of every message replayed, in log-time order.

        read, decoded and converted (an image into its :class:`_Frame`, an IMU message into the
        arguments of ``add_imu_message``, a camera info into its CameraModel or, refused, the
        reason); nothing here touches the pipeline.
        """
        t = self.topics
        wanted = (
            {t.image}
            | ({t.imu} if self.use_gyro else set())
            | (
                {t.camera_info}
                if self.use_gyro and self._camera is None and t.camera_info
                else set()
            )
        )
        conns = [c for c in self._reader.connections if c.topic in wanted]
        for conn, log_t, raw in iter_messages(self._reader, conns, self.bag):
            msg = deserialize(self._reader, raw, conn.msgtype, self.bag)
            if conn.topic == t.image:
                yield _IMAGE, log_t, self._frame(log_t, msg)
            elif conn.topic == t.imu:
                yield _IMU, log_t, imu_sample(msg)
            else:
                try:
                    yield _CAMERA, log_t, camera_model_from_msg(msg)
                except ValueError as exc:
                    yield _BAD_CAMERA, log_t, str(exc)

    @staticmethod
    def _frame(log_t: int, msg) -> _Frame:
        stamp = stamp_ns(msg.header)
        try:
            return _Frame(log_t, stamp, msg.header.frame_id, image_from_msg(msg))
        except ValueError as exc:
            return _Frame(log_t, stamp, msg.header.frame_id, None, str(exc))

    def _release(self, now_log: int | None) -> None:
        """
        Process the held frames, in order, that may go.

        ready, or (``now_log``: before the message logged then is applied) waited out by then.
        """
        while self._pending:
            f = self._pending[0]
            if not (
                self._ready(f) or (now_log is not None and self._wait.waited_out(f.log_t, now_log))
            ):
                return
            self._process(self._pending.popleft())

    def _ready(self, f: _Frame) -> bool:
        """
        Nothing is lost by processing ``f`` now.

        It is malformed, no target yet, no IMU will come, or the gyro covers it.
        """
        return (
            bool(f.error)
            or self.pipeline.state is TrackState.UNINITIALIZED
            or self._imu_seen >= self._n_imu
            or self._wait.ready(f.stamp)
        )

    def _process(self, f: _Frame) -> None:
        pipe = self.pipeline
        if pipe.state is not TrackState.UNINITIALIZED and f.stamp in self._drop:
            pipe.note_dropped(f.stamp)
            self._dropped.append(f.stamp)
            return
        if f.error:
            self._emit(f, pipe.note_bad_image(f.error, f.stamp))
        # first decodable image: initialize (as the node)
        elif pipe.state is TrackState.UNINITIALIZED:
            t0 = time.perf_counter()
            try:
                result = pipe.init(f.image, self.init_box, f.stamp)
            except ValueError as exc:
                raise ValueError(
                    f'--init {",".join(f"{v:g}" for v in self.init_box)}: {exc}'
                ) from None
            self._init_s = time.perf_counter() - t0
            self._emit(f, result)
        else:
            self._emit(f, pipe.process(f.image, f.stamp))

    def _emit(self, f: _Frame, r: FrameResult) -> None:
        self._results.append(r)
        if self._out is not None:
            self._out.write(f.log_t, f.frame_id, r, self.pipeline.statuses(), f.image)
        if self._video is not None and f.image is not None:
            self._video.write(f.image, r)
        self._bar.update(1, r.state.value)


def replay(
    bag,
    init_box,
    *,
    csv_path=None,
    out_bag=None,
    video=None,
    progress: bool | None = None,
    **options,
) -> ReplayResult:
    """
    ``Replay(bag, init_box, **options).run(csv_path, out_bag, video, progress)``.

    Parameters
    ----------
    bag : path
        As :class:`Replay` takes it.
    init_box : str or sequence of 4 float
        As :class:`Replay` takes it.
    csv_path, out_bag, video : str or path-like, optional
        The outputs, as :meth:`Replay.run` takes them.
    progress : bool, optional
        As :meth:`Replay.run` takes it.
    **options
        The other arguments of :class:`Replay`.

    Returns
    -------
    ReplayResult
        The results and the run's statistics.

    """
    return Replay(bag, init_box, **options).run(csv_path, out_bag, video, progress)
