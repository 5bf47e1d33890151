"""``iemd-replay`` / ``ros2 run iemd_ros replay``: run the tracker over a bag offline, as fast as the CPU allows.

    iemd-replay BAG --init X,Y,W,H [--image-topic T] [--imu-topic T] [--camera-info-topic T] [--no-gyro]
                --csv OUT.csv [--out-bag DIR] [--video OUT.mp4] [--gt FILE] [--config YAML]
                [--camera-yaml FILE] [--time-offset-ms MS] [--progress | --no-progress]

``BAG``: a rosbag2 folder (sqlite3 or mcap) or a ROS 1 ``.bag`` file (rosbags' AnyReader).  The image,
IMU and camera-info topics are auto-detected when the bag has one of each type, else named.  Images are
``sensor_msgs/Image`` or ``sensor_msgs/CompressedImage`` (jpeg/png, e.g. ``image_raw/compressed``); a
compressed topic is left out when its own raw twin (``image_raw`` for ``image_raw/compressed``) holds
messages (:func:`iemd_ros.bags.io.select_topics`).  The messages go, in
the bag's (log-time) order, through :class:`iemd_ros.pipeline.pipeline.TrackingPipeline` -- the same
synchronization, gyro prediction and tracker as the node -- deterministically: nothing depends on the
wall clock, so the same bag gives the same CSV byte for byte.

IMU synchronization: a frame is held until the gyro covers it (:meth:`TrackingPipeline.gyro_ready`)
or until ``imu_wait_ms`` (pipeline config, default 15 ms) of *bag* time has passed after it (a message
logged later than that is applied after the frame), then processed (without the prior if the gyro
still does not cover it).  As in the node, an Imu with ``angular_velocity_covariance[0] = -1`` carries no
rate and is rejected.  This is what the node does with the bag played at 1x when its processing keeps
up (the node waits ``imu_wait_ms`` of wall time); the live node may in addition drop frames that
arrive while it is busy, the offline replay never drops.
The gyro time offset ``t_d`` is ``gyro.time_offset_ns`` of the config (default 0: bags made by
``iemd-make-bag`` already carry IMU stamps on the camera clock).

The tracker is initialised with ``--init`` (0-based pixels, top-left + size) on the first image that
can be decoded, as the node does with its ``initial_box``.

Outputs: the CSV (``stamp_ns,x,y,w,h,emd,state``, one row per image, floats in shortest round-trip
form; the init frame's row holds the init box with state ``init`` and an empty emd; a frame the
pipeline could not use has an empty box and state ``rejected``/``malformed`` (an image that does not
convert or decode: counted, tracking goes on)); optionally a rosbag2 (mcap) with
``vision_msgs/Detection2DArray`` and ``diagnostic_msgs/DiagnosticArray`` stamped and logged like the
images (open it in Foxglove next to the input), an annotated MP4 (``mp4v``), and with ``--gt`` (OTB
``x,y,w,h`` or the desk ``x,y,w,h,flag`` format, one line per image, 1-based) the metrics of
:mod:`iemd_ros.evaluation.ope`.

Bad input (missing/truncated bag, no images, a topic of the wrong type, an init box outside the image,
...) prints one line on stderr and exits with status 2.
"""
from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from collections import deque
from dataclasses import dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np

from iemd_ros.bags.io import (DETECTIONS_TYPE, DIAGNOSTICS_TYPE, BagError, BagWriter, Progress, Topics, deserialize, header,
                     iter_messages, open_bag, select_topics)
from iemd_ros.common.boxes import check_box
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.common.cli import CliParser, cli_main, split_ros_args
from iemd_ros.messages.conversions import (CLASS_ID, DETECTION_ID, camera_model_from_msg, detection_values, image_from_msg,
                          imu_sample, stamp_ns)
from iemd_ros.pipeline.drawing import draw_result
from iemd_ros.pipeline.pipeline import FrameResult, PipelineConfig, TrackingPipeline

__all__ = ["ReplayResult", "replay", "parse_box", "load_gt", "write_csv", "CSV_HEADER", "main"]

CSV_HEADER = ("stamp_ns", "x", "y", "w", "h", "emd", "state")
# as the node publishes them (iemd_ros.ros.node defaults: ``detections`` in the root namespace, class_id
# "target", id "iemd"; one detection while tracking, none when lost; the init frame has score 1)
DETECTIONS_TOPIC = "/detections"
DIAGNOSTICS_TOPIC = "/diagnostics"


@dataclass
class ReplayResult:
    """Per-image results (the init frame's has ``is_init``; frames skipped with
    ``drop_stamps`` have none) and run statistics."""

    bag: str
    topics: Topics
    results: list[FrameResult]
    wall_s: float                     # whole replay (reading, decoding, tracking, writing)
    track_s: float                    # sum of the tracker's processing_ms (updates)
    warnings: list[str] = field(default_factory=list)
    diagnostics: dict = field(default_factory=dict)
    dropped: list[int] = field(default_factory=list)   # stamps skipped on request (``drop_stamps``)
    init_s: float = 0.0               # the tracker's init on the first frame (one-off)

    @property
    def boxes(self) -> np.ndarray:
        """(N, 4) boxes, NaN where a frame gave none."""
        return np.array([r.box if r.box is not None else (np.nan,) * 4 for r in self.results], dtype=float)

    @property
    def stamps_ns(self) -> np.ndarray:
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
        return sum(r.gyro_used for r in self.results)


def parse_box(box) -> tuple[float, float, float, float]:
    """The init box: ``"X,Y,W,H"`` or a sequence of 4 numbers -> 4 floats (finite, w, h > 0); ValueError
    (naming ``--init``) otherwise."""
    return check_box(box.split(",") if isinstance(box, str) else box, "--init", shown=box)


def load_gt(path) -> np.ndarray:
    """Ground truth (N, 4), 0-based: OTB ``x,y,w,h`` lines or the desk ``x,y,w,h,flag`` lines."""
    from iemd_ros.datasets.otb import parse_groundtruth

    return parse_groundtruth(path, with_flags=True)[0]


def _fmt(v) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else repr(float(v))


def csv_rows(results: list[FrameResult]):
    for r in results:
        box = r.box if r.box is not None else (None,) * 4
        if r.is_init:
            state = "init"
        elif r.rejected:
            state = "malformed" if r.rejected.startswith("malformed") else "rejected"
        else:
            state = r.state
        emd = None if r.is_init or r.rejected else r.emd
        yield [str(int(r.stamp_ns)), *(_fmt(v) for v in box), _fmt(emd), state]


def write_csv(path, results: list[FrameResult]) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(CSV_HEADER)
        w.writerows(csv_rows(results))


# ---------------------------------------------------------------------------------------------- outputs
class _OutBag:
    """Detections + diagnostics rosbag2 (mcap), stamped and logged like the images."""

    def __init__(self, path, frame_topic: str):
        self.bag = BagWriter(path, "mcap", {"iemd_ros.replay_of": frame_topic})
        self.bag.__enter__()
        self.bag.add_topic(DETECTIONS_TOPIC, DETECTIONS_TYPE)
        self.bag.add_topic(DIAGNOSTICS_TOPIC, DIAGNOSTICS_TYPE)

    def write(self, log_t: int, frame_id: str, r: FrameResult, statuses) -> None:
        """The frame's Detection2DArray (one detection while ``r`` is tracking, else empty) and statuses."""
        b = self.bag
        M = b.msg
        hdr = header(b, DETECTIONS_TOPIC, r.stamp_ns, frame_id)
        dets = []
        values = detection_values(r)
        if values is not None:
            cx, cy, sx, sy = values.bbox
            hyp = M("vision_msgs/msg/ObjectHypothesisWithPose")(
                hypothesis=M("vision_msgs/msg/ObjectHypothesis")(class_id=CLASS_ID, score=values.score),
                pose=M("geometry_msgs/msg/PoseWithCovariance")(
                    pose=M("geometry_msgs/msg/Pose")(
                        position=M("geometry_msgs/msg/Point")(x=0.0, y=0.0, z=0.0),
                        orientation=M("geometry_msgs/msg/Quaternion")(x=0.0, y=0.0, z=0.0, w=1.0)),
                    covariance=np.zeros(36)))
            bbox = M("vision_msgs/msg/BoundingBox2D")(
                center=M("vision_msgs/msg/Pose2D")(position=M("vision_msgs/msg/Point2D")(x=cx, y=cy), theta=0.0),
                size_x=sx, size_y=sy)
            dets.append(M("vision_msgs/msg/Detection2D")(header=hdr, results=[hyp], bbox=bbox, id=DETECTION_ID))
        b.write(DETECTIONS_TOPIC, log_t, M(DETECTIONS_TYPE)(header=hdr, detections=dets))
        status = [M("diagnostic_msgs/msg/DiagnosticStatus")(
            level=s.level, name=s.name, message=s.message, hardware_id="iemd_replay",
            values=[M("diagnostic_msgs/msg/KeyValue")(key=str(k), value=str(v)) for k, v in s.values.items()])
            for s in statuses]
        b.write(DIAGNOSTICS_TOPIC, log_t,
                M(DIAGNOSTICS_TYPE)(header=header(b, DIAGNOSTICS_TOPIC, r.stamp_ns, frame_id), status=status))

    def close(self, exc_type=None) -> None:
        self.bag.__exit__(exc_type, None, None)


class _Video:
    """Annotated MP4 (mp4v), each frame drawn by :func:`iemd_ros.pipeline.drawing.draw_result`.

    The frame rate is the image rate of the bag: the first frame is held until the second one gives
    the interval."""

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
        self.writer = cv2.VideoWriter(str(self.path), cv2.VideoWriter_fourcc(*"mp4v"),
                                      float(min(max(fps, 1.0), 240.0)), (w, h))
        if not self.writer.isOpened():
            raise ValueError(f"cannot write video {self.path} (OpenCV mp4v writer failed to open)")

    def close(self) -> None:
        if self.writer is None and self._held is not None:
            self._open(self._held[0].shape, 30.0)
            self.writer.write(self._held[0])
        if self.writer is not None:
            self.writer.release()


# ---------------------------------------------------------------------------------------------- replay
@dataclass
class _Frame:
    log_t: int
    stamp: int
    frame_id: str
    image: np.ndarray | None
    error: str = ""


def replay(bag, init_box, *, image_topic: str | None = None, imu_topic: str | None = None,
           camera_info_topic: str | None = None, config: PipelineConfig | None = None, use_gyro: bool = True,
           camera: CameraModel | None = None, csv_path=None, out_bag=None, video=None, progress: bool | None = None,
           warn=None, drop_stamps=()) -> ReplayResult:
    """Replay ``bag`` through :class:`TrackingPipeline`, initialised with ``init_box`` on the first image
    (``"X,Y,W,H"`` or 4 numbers, checked by :func:`parse_box`).

    ``config``: pipeline configuration (default ``PipelineConfig()``); ``use_gyro=False`` disables the
    prior (``--no-gyro``).  ``camera``: calibration to use instead of the bag's camera info.
    ``warn(text)`` receives the warnings (default: printed to stderr).  ``drop_stamps``: images with
    these stamps are skipped and counted as dropped (``TrackingPipeline.note_dropped``), as the live node
    does with frames that arrive while it is busy -- to reproduce a live run offline.  Raises ValueError (BagError)
    on bad input; partial output files are removed then.
    """
    warn = warn if warn is not None else (lambda s: print(f"iemd-replay: warning: {s}", file=sys.stderr))
    init_box = parse_box(init_box)
    cfg = config if config is not None else PipelineConfig()
    warnings: list[str] = []

    def note(text: str) -> None:
        warnings.append(text)
        warn(text)

    reader = open_bag(bag)
    outputs: list = []
    try:
        topics = select_topics(reader, image_topic, imu_topic, camera_info_topic)
        use = bool(use_gyro and cfg.use_gyro)
        if use and topics.imu is None:
            note("the bag has no sensor_msgs/msg/Imu topic: replaying without the gyro prior")
            use = False
        elif use and topics.camera_info is None and camera is None:
            note("the bag has no sensor_msgs/msg/CameraInfo topic (the gyro prior needs K): "
                 "replaying without the gyro prior")
            use = False
        cfg = replace(cfg, use_gyro=use)
        pipe = TrackingPipeline(cfg, camera)
        wanted = {topics.image} | ({topics.imu} if use else set()) | \
                 ({topics.camera_info} if use and camera is None and topics.camera_info else set())
        conns = [c for c in reader.connections if c.topic in wanted]
        n_images = reader.topics[topics.image].msgcount
        n_imu = reader.topics[topics.imu].msgcount if use else 0
        wait_ns = int(round(cfg.imu_wait_ms * 1e6))
        bar = Progress(n_images, "iemd-replay", progress)
        results: list[FrameResult] = []
        pending: deque[_Frame] = deque()
        out = _OutBag(out_bag, topics.image) if out_bag is not None else None
        if out is not None:
            outputs.append(out)
        vid = None
        imu_seen = 0
        drop = {int(t) for t in drop_stamps}
        dropped: list[int] = []
        init_s = [0.0]
        t_start = time.perf_counter()

        def emit(f: _Frame, r: FrameResult) -> None:
            nonlocal vid
            results.append(r)
            if out is not None:
                out.write(f.log_t, f.frame_id, r, pipe.statuses())
            if video is not None and f.image is not None:
                if vid is None:
                    vid = _Video(video)
                    outputs.append(vid)
                vid.write(f.image, r)
            bar.update(1, f"{r.state}")

        def process(f: _Frame) -> None:
            if pipe.state != "uninitialized" and f.stamp in drop:
                pipe.note_dropped(f.stamp)
                dropped.append(f.stamp)
                return
            if f.error:
                pipe.note_bad_image(f.error, f.stamp)
                emit(f, FrameResult(f.stamp, pipe.state, rejected=f"malformed: {f.error}"))
            elif pipe.state == "uninitialized":    # first decodable image: initialise (as the node)
                t0 = time.perf_counter()
                try:
                    r = pipe.init(f.image, init_box, f.stamp)
                except ValueError as exc:
                    raise ValueError(f"--init {','.join(f'{v:g}' for v in init_box)}: {exc}") from None
                init_s[0] = time.perf_counter() - t0
                emit(f, r)
            else:
                emit(f, pipe.process(f.image, f.stamp))

        def ready(f: _Frame) -> bool:
            return (bool(f.error) or pipe.state == "uninitialized" or imu_seen >= n_imu
                    or pipe.gyro_ready(f.stamp))

        def flush(now_log: int | None, arrived: bool) -> None:
            """Process the held frames that can go: ready, or -- before the message logged at
            ``now_log`` is applied (``arrived`` False) -- whose IMU wait ended earlier; all at the end."""
            while pending:
                f = pending[0]
                if not (now_log is None or ready(f) or (not arrived and now_log > f.log_t + wait_ns)):
                    return
                pending.popleft()
                process(f)

        for conn, log_t, raw in iter_messages(reader, conns, bag):
            flush(log_t, arrived=False)          # frames the node would have given up waiting for
            msg = deserialize(reader, raw, conn.msgtype, bag)
            if conn.topic == topics.image:
                stamp = stamp_ns(msg.header)
                try:
                    img = image_from_msg(msg)
                    pending.append(_Frame(log_t, stamp, msg.header.frame_id, img))
                except ValueError as exc:
                    pending.append(_Frame(log_t, stamp, msg.header.frame_id, None, str(exc)))
            elif conn.topic == topics.imu:
                imu_seen += 1
                pipe.add_imu_message(*imu_sample(msg))
            else:
                try:
                    pipe.set_camera(camera_model_from_msg(msg))
                except ValueError as exc:
                    pipe.note_bad_camera_info(str(exc))
            flush(log_t, arrived=True)
        flush(None, arrived=True)
        bar.close()
        wall = time.perf_counter() - t_start
        if pipe.state == "uninitialized" and not dropped:
            raise BagError(f"no image on {topics.image!r} of {bag} could be decoded: "
                           f"{results[0].rejected if results else 'the topic is empty'}")
        if use and pipe.counters["camera_infos"] == 0 and camera is None:
            note("no usable camera info in the bag: tracked without the gyro prior")
        if csv_path is not None:
            write_csv(csv_path, results)
        for o in outputs:
            o.close()
        outputs.clear()
        return ReplayResult(str(bag), topics, results, wall,
                            sum(r.processing_ms for r in results) / 1e3, warnings, pipe.diagnostics(), dropped,
                            init_s[0])
    except BaseException as exc:
        for o in outputs:
            if isinstance(o, _OutBag):
                o.close(type(exc))
            else:
                o.close()
                Path(video).unlink(missing_ok=True)
        raise
    finally:
        reader.close()


# ---------------------------------------------------------------------------------------------- CLI
def score_replay(result: ReplayResult, gt: np.ndarray, name: str):
    """The tracker evaluation's scores (:class:`iemd_ros.evaluation.metrics.SequenceScores`) of a replay against ``gt``;
    fps counts the tracker's processing time only."""
    from iemd_ros.evaluation.metrics import score_sequence

    boxes = result.boxes
    if len(gt) != len(boxes):
        raise ValueError(f"the ground truth has {len(gt)} boxes for {len(boxes)} images in the bag")
    fps = len(boxes) / result.track_s if result.track_s > 0 else math.inf
    return score_sequence(boxes, gt, name, fps=fps)


def evaluation_table(result: ReplayResult, gt: np.ndarray, name: str, label: str = "iemd") -> tuple[str, object]:
    """Scores of the replay against ``gt`` and the table of :func:`iemd_ros.evaluation.ope.format_table`."""
    from iemd_ros.evaluation.ope import MEAN, format_table, mean_scores

    scores = score_replay(result, gt, name)
    table = format_table({label: {name: scores.to_dict(), MEAN: mean_scores([scores])}}, [label], [name])
    return table, scores


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(prog="iemd-replay", description=__doc__.split("\n\n")[0],
                  epilog="Details: python -m pydoc iemd_ros.bags.replay")
    p.add_argument("bag", help="rosbag2 folder (sqlite3/mcap) or ROS 1 .bag file")
    p.add_argument("--init", required=True, type=str, metavar="X,Y,W,H",
                   help="initial box on the first image (0-based pixels, top-left + size)")
    p.add_argument("--image-topic", default=None, help="sensor_msgs/Image or CompressedImage topic (default: the "
                                                        "bag's one image topic; X/compressed yields to its raw X)")
    p.add_argument("--imu-topic", default=None)
    p.add_argument("--camera-info-topic", default=None)
    p.add_argument("--no-gyro", action="store_true", help="track without the gyro prior")
    p.add_argument("--csv", required=True, type=Path, help="per-image results (stamp_ns,x,y,w,h,emd,state)")
    p.add_argument("--out-bag", type=Path, default=None,
                   help="write detections + diagnostics into this new rosbag2 (mcap) folder")
    p.add_argument("--video", type=Path, default=None, help="write an annotated MP4 (mp4v)")
    p.add_argument("--gt", type=Path, default=None, help="ground truth (OTB or desk format): print the metrics")
    p.add_argument("--config", type=Path, default=None,
                   help="pipeline configuration: the node's parameter file (config/tracker.yaml) or "
                        "{tracker: {...}, gyro: {...}, imu_wait_ms: ...}")
    p.add_argument("--camera-yaml", type=Path, default=None,
                   help="ROS camera_info YAML to use instead of the bag's camera info")
    p.add_argument("--time-offset-ms", type=float, default=None,
                   help="gyro time offset t_d (t_imu = t_cam + t_d); default from --config, else 0")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: when stderr is a terminal)")
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        args, _ = split_ros_args(argv)      # from `ros2 run` / launch: the replay has no ROS arguments
        a = build_parser().parse_args(args)
        box = parse_box(a.init)
        cfg = PipelineConfig.from_yaml(a.config) if a.config else PipelineConfig()
        if a.time_offset_ms is not None:
            cfg = replace(cfg, gyro=replace(cfg.gyro, time_offset_ns=int(round(a.time_offset_ms * 1e6))))
        camera = CameraModel.from_yaml(a.camera_yaml) if a.camera_yaml else None
        gt = load_gt(a.gt) if a.gt else None
        if a.out_bag is not None and a.out_bag.exists():
            raise ValueError(f"--out-bag {a.out_bag} exists already; choose a new folder")
        res = replay(a.bag, box, image_topic=a.image_topic, imu_topic=a.imu_topic,
                     camera_info_topic=a.camera_info_topic, config=cfg, use_gyro=not a.no_gyro, camera=camera,
                     csv_path=a.csv, out_bag=a.out_bag, video=a.video, progress=a.progress)
        d = res.diagnostics
        n = len(res.results)
        print(f"iemd-replay: {n} images from {res.topics.image}"
              f"{f', IMU {res.topics.imu}' if res.topics.imu else ''}: gyro prior on {res.gyro_used} frames, "
              f"lost on {d.get('frames_lost', 0)}, rejected {d.get('frames_rejected', 0) + d.get('images_malformed', 0)}; "
              f"{res.wall_s:.1f} s wall for {res.duration_s:.1f} s of bag = {res.realtime_factor:.2f}x real time")
        print(f"iemd-replay: results -> {a.csv}" + (f", {a.out_bag}" if a.out_bag else "")
              + (f", {a.video}" if a.video else ""))
        if gt is not None:
            table, _ = evaluation_table(res, gt, Path(a.bag).name.removesuffix(".bag")[:14],
                                        "iemd" if a.no_gyro else "iemd+g")
            print()
            print(table)
        return 0

    return cli_main("iemd-replay", body)


if __name__ == "__main__":
    sys.exit(main())
