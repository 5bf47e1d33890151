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
``iemd-make-bag``: image folder + gyro log + calibration -> rosbag2.

(mcap/sqlite3) or ROS 1 ``.bag``.

Sources (detected from the folder; loaded by :mod:`iemd_ros.datasets.recordings` /
:mod:`iemd_ros.datasets.otb`):

* CMU desk / aerial (``*_img.log``) and the phone sequence (``derived_gyro_camframe.csv``): frames,
  gyro, calibration and time offset of the recording;
* an OTB sequence (``img/`` + ``groundtruth_rect.txt``): frames only, stamped at ``--fps``; no IMU
  and no camera info (OTB has no calibration) unless ``--camera-yaml`` is given;
* any folder of images (sorted by name) with ``--fps`` or ``--stamps FILE`` (one time in seconds
  per line), optionally ``--imu-csv FILE`` (``t_s, wx, wy, wz[, ax, ay, az]``, rad/s, m/s^2) and
  ``--camera-yaml FILE`` (ROS camera_info YAML).

Images are ``sensor_msgs/Image`` (``--encoding`` bgr8 or mono8) on ``--image-topic``, or with
``--compress jpeg|png`` ``sensor_msgs/CompressedImage`` as image_transport's compressed plugin
writes them: on ``--image-topic`` + ``/compressed``, format ``"bgr8; jpeg compressed bgr8"``
(mono8: ``"mono8; png compressed "``), JPEG quality ``--jpeg-quality`` (default 95); PNG is
lossless.

Stamps and clocks (the choice made here)
----------------------------------------
All header stamps are on the **camera clock**: ``Image.header.stamp = CameraInfo.header.stamp`` =
the frame's capture time, and the IMU samples are shifted onto the camera clock with the
recording's offset (Kalibr's ``t_imu = t_cam + t_d``): ``Imu.header.stamp = t_imu - t_d`` (CMU: t_d
= -20 ms, so +20 ms; phone: t_d = +13 ms).  A bag made here therefore needs ``t_d = 0`` at replay
time, which is the replay's and the node's default; the applied shift is recorded in the rosbag2
``custom_data`` (``iemd_ros.imu_time_shift_ns``) for provenance only.  Shifting rather than keeping
the IMU clock makes the bag self-consistent for any consumer (Foxglove, ``ros2 bag play`` into
other nodes) and survives ``rosbags-convert`` from ROS 1, which has no metadata to carry an offset.

IMU samples within ``--imu-margin`` of the first/last frame are kept, in the recorded row order
(the desk clock steps back at 3 rows: those samples keep their stamps, the consumer's buffer sorts
them).

Frames: ``Imu.angular_velocity`` is the gyro rate as the loader gives it.  The CMU and phone
loaders give the *derived camera-frame* rate (SOURCES.md), so their IMU ``frame_id`` is the
camera's optical frame (identity extrinsic by construction); a user's ``--imu-csv`` is written with
``--imu-frame-id`` (default ``imu_link``) and its extrinsic must be configured in the consumer.
``orientation_covariance[0] = -1`` (no orientation); ``linear_acceleration_covariance[0] = -1``
when there is no accelerometer.

Log (receive) times: images and camera info are logged at their stamp, IMU samples at the running
maximum of their stamps (a sample is never received before an earlier-logged one); all log times
are then made strictly increasing (+1 ns steps where equal, order IMU, camera info, image), so
every reader sees the same, unambiguous message order.

"""
from __future__ import annotations

from collections.abc import Callable
import csv
from dataclasses import dataclass
from pathlib import Path

import cv2
from iemd_ros.bags.io import (
    BagWriter,
    camera_info_fields,
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    header,
    IMAGE_TYPE,
    IMU_TYPE,
    META_PREFIX,
)
from iemd_ros.common.cli import finite_float, non_negative_float, positive_float
from iemd_ros.datasets.otb import (
    IMAGE_SUFFIXES,
    is_sequence_folder,
    list_sequences,
    load_sequence,
    read_frame,
)
from iemd_ros.datasets.recordings import load_recording, seconds_to_ns
from iemd_ros.gyro import CameraModel
from iemd_ros.messages.conversions import (
    array_to_compressed_fields,
    check_compression,
    compressed_topic,
    is_compressed_topic,
    JPEG_QUALITY,
)
import numpy as np

__all__ = [
    'BagSource',
    'source_from_folder',
    'source_from_synthetic',
    'write_bag',
    'write_gt',
    'DEFAULT_TOPICS',
    'ENCODINGS',
    'CAMERA_FRAME',
    'IMU_FRAME',
]

DEFAULT_TOPICS = {
    'image': '/camera/image_raw',
    'camera_info': '/camera/camera_info',
    'imu': '/imu/data',
}
CAMERA_FRAME = 'camera_optical_frame'
IMU_FRAME = 'imu_link'
ENCODINGS = ('bgr8', 'mono8')
_BASE_NS = 1_000_000_000  # stamps of frame-rate-only sources start at 1 s (0 often means "unset")


@dataclass
class BagSource:
    """
    What goes into a bag.

    Stamps are integer ns; ``imu_t_ns`` is on the IMU clock.

    Parameters
    ----------
    name : str
        The source's name.
    frame_stamps_ns : ndarray
        (N,) frame stamps, camera clock.
    read_frame : callable
        ``read_frame(i, grey)`` returns frame ``i`` as BGR (or grey) uint8.
    camera : CameraModel, optional
        The calibration (None: no camera info).
    imu_t_ns : ndarray, optional
        (M,) IMU stamps, IMU clock.
    gyro : ndarray, optional
        (M, 3) rates, rad/s.
    accel : ndarray, optional
        (M, 3) accelerations, m/s^2.
    time_offset_ns : int, optional
        The offset t_d (``t_imu = t_cam + t_d``).
    imu_frame_id : str, optional
        ``frame_id`` of the IMU samples; None: the gyro is in the camera frame.
    gt_boxes : ndarray, optional
        (N, 4) 0-based ground truth.
    gt_flags : ndarray, optional
        (N,) flags of the ground truth.

    """

    name: str
    frame_stamps_ns: np.ndarray
    read_frame: Callable[[int, bool], np.ndarray]
    camera: CameraModel | None = None
    imu_t_ns: np.ndarray | None = None
    gyro: np.ndarray | None = None
    accel: np.ndarray | None = None
    time_offset_ns: int = 0
    imu_frame_id: str | None = None
    gt_boxes: np.ndarray | None = None  # (N, 4) 0-based
    gt_flags: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.frame_stamps_ns)

    @property
    def has_imu(self) -> bool:
        """Whether the source has IMU samples."""
        return self.imu_t_ns is not None and len(self.imu_t_ns) > 0


def _frame_rate_stamps(n: int, fps: float) -> np.ndarray:
    positive_float.check('--fps', fps)
    return _BASE_NS + np.round(np.arange(n) * 1e9 / fps).astype(np.int64)


def _read_table(path: Path, min_cols: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """
    Rows of a CSV/whitespace file (``#`` comments and a non-numeric header skipped).

    The first column as exact integer ns (decimal seconds,
    :func:`iemd_ros.datasets.recordings.seconds_to_ns`) and the other columns (up to 6) as floats.
    """
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f'cannot read {what} {path}: {exc}') from None
    times, values = [], []
    for n, line in enumerate(text.splitlines(), 1):
        parts = line.split('#', 1)[0].replace(',', ' ').split()
        if not parts:
            continue
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not times:
                continue  # header line
            raise ValueError(f'{path}:{n}: not a number in {what} line {line!r}') from None
        if len(vals) < min_cols or not all(np.isfinite(vals[:1])):
            raise ValueError(f'{path}:{n}: {what} needs at least {min_cols} columns, got {line!r}')
        times.append(seconds_to_ns(parts[0]))
        values.append(vals[1:7])
    if not times:
        raise ValueError(f'{path}: no {what} rows')
    width = min(len(v) for v in values)
    return np.array(times, dtype=np.int64), np.array(
        [v[:width] for v in values], dtype=float
    ).reshape(len(times), width)


def source_from_folder(
    folder,
    fps: float | None = None,
    stamps=None,
    imu_csv=None,
    camera_yaml=None,
    time_offset_ms: float | None = None,
    imu_frame_id: str = IMU_FRAME,
) -> BagSource:
    """
    Detect and load a source folder (see module docstring).

    Parameters
    ----------
    folder : str or path-like
        A CMU or phone recording, an OTB sequence or a folder of images.
    fps : float, optional
        Frame rate of a source without stamps (default 30).
    stamps : str or path-like, optional
        File of one time in seconds per line, one line per image.
    imu_csv : str or path-like, optional
        ``t_s, wx, wy, wz[, ax, ay, az]`` rows (rad/s, m/s^2).
    camera_yaml : str or path-like, optional
        ROS camera_info YAML (for a recording: used instead of its own calibration).
    time_offset_ms : float, optional
        The offset t_d of ``imu_csv``, ms (``t_imu = t_cam + t_d``; finite).
    imu_frame_id : str, optional
        ``frame_id`` of the ``imu_csv`` samples.

    Returns
    -------
    BagSource
        The source.

    Raises
    ------
    ValueError
        For a folder that is none of these, options that do not apply to a known recording, stamps
        that do not match the images or do not increase strictly, or files that cannot be read.

    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f'source {folder} is not a folder')
    if time_offset_ms is not None:
        finite_float.check('--time-offset-ms', time_offset_ms)
    camera = CameraModel.from_yaml(camera_yaml) if camera_yaml else None
    if list(folder.glob('*_img.log')) or (folder / 'derived_gyro_camframe.csv').exists():
        if fps or stamps or imu_csv or time_offset_ms is not None:
            raise ValueError(
                f'{folder} is a known recording: --fps/--stamps/--imu-csv/--time-offset-ms '
                'do not apply (its own stamps, gyro and offset are used)'
            )
        rec = load_recording(folder)
        return BagSource(
            rec.name,
            rec.frame_stamps_ns,
            rec.load_frame,
            camera or rec.camera,
            rec.imu_t_ns,
            rec.gyro,
            rec.accel,
            rec.time_offset_ns,
            None,
            rec.gt_boxes,
            rec.gt_flags,
        )
    if is_sequence_folder(folder):
        names = list_sequences(folder.parent)
        name = next(n for n in names if n == folder.name or n.startswith(folder.name + '-'))
        seq = load_sequence(name, folder.parent)
        paths = list(seq.frame_paths)
        gt = seq.gt_boxes
    else:
        paths = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not paths:
            raise ValueError(
                f'{folder} holds no image (.jpg/.jpeg/.png) and is no known recording layout'
            )
        name, gt = folder.name, None
    if stamps:
        t = _read_table(Path(stamps), 1, 'frame stamp')[0]
        if len(t) != len(paths):
            raise ValueError(f'{stamps} has {len(t)} stamps for {len(paths)} images in {folder}')
    else:
        t = _frame_rate_stamps(len(paths), fps if fps is not None else 30.0)
    if np.any(np.diff(t) <= 0):
        raise ValueError('frame stamps must increase strictly')
    imu_t = gyro = accel = None
    if imu_csv:
        imu_t, rows = _read_table(Path(imu_csv), 4, 'IMU')
        gyro = rows[:, 0:3]
        accel = rows[:, 3:6] if rows.shape[1] >= 6 else None

    def load(i: int, grey: bool = False) -> np.ndarray:
        img = read_frame(paths[i])
        return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY) if grey else img

    offset = int(round((time_offset_ms or 0.0) * 1e6))
    return BagSource(
        name, t, load, camera, imu_t, gyro, accel, offset, imu_frame_id if imu_csv else None, gt
    )


def source_from_synthetic(seq, imu_frame_id: str = IMU_FRAME) -> BagSource:
    """
    Return a rendered :class:`~iemd_ros.datasets.synthetic.SyntheticSequence` as a bag source.

    The gyro is in the IMU frame, ``R_cam_imu`` of the sequence (identity by default).

    Parameters
    ----------
    seq : SyntheticSequence
        The sequence.
    imu_frame_id : str, optional
        ``frame_id`` of the IMU samples when ``R_cam_imu`` is not the identity (else they are in
        the camera frame).

    Returns
    -------
    BagSource
        The source, with the sequence's ground truth.

    Raises
    ------
    ValueError
        For a sequence generated with ``render=False``.

    """
    if seq.frames is None:
        raise ValueError(
            'the synthetic sequence was generated with render=False: no frames to write'
        )

    def load(i: int, grey: bool = False) -> np.ndarray:
        f = seq.frames[i]
        return cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) if grey else f

    imu_frame = None if np.allclose(seq.R_cam_imu, np.eye(3)) else imu_frame_id
    return BagSource(
        'synthetic',
        seq.frame_stamps_ns,
        load,
        seq.camera,
        seq.gyro_t_ns,
        seq.gyro,
        None,
        seq.time_offset_ns,
        imu_frame,
        seq.gt_boxes,
    )


# ----------------------------------------------------------------------------------------------
# writing
def _image_msg(bag: BagWriter, topic: str, t: int, frame_id: str, img: np.ndarray, encoding: str):
    img = np.ascontiguousarray(img)
    h, w = img.shape[:2]
    ch = 1 if img.ndim == 2 else img.shape[2]
    return bag.msg(IMAGE_TYPE)(
        header=header(bag, topic, t, frame_id),
        height=h,
        width=w,
        encoding=encoding,
        is_bigendian=0,
        step=w * ch,
        data=img.reshape(-1),
    )


def _compressed_msg(
    bag: BagWriter,
    topic: str,
    t: int,
    frame_id: str,
    img: np.ndarray,
    codec: str,
    jpeg_quality: int = JPEG_QUALITY,
):
    """
    ``img`` (bgr8 or mono8) as image_transport's compressed plugin publishes it.

    (:func:`iemd_ros.messages.conversions.array_to_compressed_fields`).
    """
    fields = array_to_compressed_fields(img, codec, jpeg_quality)
    return bag.msg(COMPRESSED_IMAGE_TYPE)(
        header=header(bag, topic, t, frame_id),
        format=fields['format'],
        data=np.frombuffer(fields['data'], dtype=np.uint8),
    )


def _camera_info_msg(
    bag: BagWriter, topic: str, t: int, frame_id: str, camera: CameraModel, w: int, h: int
):
    info = camera.to_camera_info()
    roi = bag.msg('sensor_msgs/msg/RegionOfInterest')(
        x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
    )
    return bag.msg(CAMERA_INFO_TYPE)(
        header=header(bag, topic, t, frame_id),
        height=h,
        width=w,
        distortion_model='plumb_bob',
        **camera_info_fields(
            bag.ros1,
            info['distortion_coefficients']['data'],
            info['camera_matrix']['data'],
            info['rectification_matrix']['data'],
            info['projection_matrix']['data'],
        ),
        binning_x=0,
        binning_y=0,
        roi=roi,
    )


def _imu_msg(
    bag: BagWriter, topic: str, t: int, frame_id: str, w: np.ndarray, a: np.ndarray | None
):
    V = bag.msg('geometry_msgs/msg/Vector3')
    no_cov = np.zeros(9)
    unknown = np.zeros(9)
    unknown[0] = -1.0
    return bag.msg(IMU_TYPE)(
        header=header(bag, topic, t, frame_id),
        orientation=bag.msg('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=unknown.copy(),
        angular_velocity=V(x=float(w[0]), y=float(w[1]), z=float(w[2])),
        angular_velocity_covariance=no_cov.copy(),
        linear_acceleration=V(x=0.0, y=0.0, z=0.0)
        if a is None
        else V(x=float(a[0]), y=float(a[1]), z=float(a[2])),
        linear_acceleration_covariance=unknown.copy() if a is None else no_cov.copy(),
    )


def _schedule(
    frame_t: np.ndarray, imu_t: np.ndarray | None, with_info: bool
) -> list[tuple[int, int, int]]:
    """
    ``(log_time_ns, kind, index)`` in writing order.

    Kind 0 = IMU, 1 = camera info, 2 = image.
    """
    events = []
    if imu_t is not None and len(imu_t):
        recv = np.maximum.accumulate(imu_t)
        events += [(int(t), 0, i) for i, t in enumerate(recv)]
    for i, t in enumerate(frame_t):
        if with_info:
            events.append((int(t), 1, i))
        events.append((int(t), 2, i))
    events.sort()
    out, last = [], None
    for t, kind, i in events:
        t = t if last is None or t > last else last + 1
        out.append((t, kind, i))
        last = t
    return out


def write_bag(
    source: BagSource,
    out,
    fmt: str = 'mcap',
    encoding: str = 'bgr8',
    first: int = 0,
    count: int | None = None,
    imu_margin_s: float = 0.5,
    topics: dict | None = None,
    frame_id: str = CAMERA_FRAME,
    gt_out=None,
    progress: Callable[[int], None] | None = None,
    compress: str | None = None,
    jpeg_quality: int | None = None,
) -> dict:
    """
    Write frames ``first .. first+count-1`` of ``source`` into a new bag ``out``.

    With camera info and the IMU samples within ``imu_margin_s`` of the frames, stamped and logged
    as the module docstring says.

    Parameters
    ----------
    source : BagSource
        What goes into the bag.
    out : str or path-like
        The new bag.
    fmt : {"mcap", "sqlite3", "ros1"}, optional
        The bag's format.
    encoding : {"bgr8", "mono8"}, optional
        Encoding of the images.
    first : int, optional
        The first frame.
    count : int, optional
        Number of frames (default: to the last).
    imu_margin_s : float, optional
        IMU samples this close to the first/last frame are kept, s (finite, >= 0).
    topics : dict, optional
        ``image``, ``camera_info``, ``imu`` topic names replacing :data:`DEFAULT_TOPICS`.
    frame_id : str, optional
        ``frame_id`` of the images and camera info (and of a gyro in the camera frame).
    gt_out : str or path-like, optional
        Also write the frames' ground truth there (OTB text, 1-based; the desk flags kept as a 5th
        column).
    progress : callable, optional
        Called with 1 for every image written.
    compress : {"jpeg", "png"}, optional
        CompressedImage on the image topic + ``/compressed`` (module docstring).
    jpeg_quality : int, optional
        JPEG quality, 1-100, with ``compress="jpeg"`` only.

    Returns
    -------
    dict
        A summary: message counts, the image topic, the IMU shift applied, the frame range.

    Raises
    ------
    ValueError
        For bad options, a frame range outside the source, no IMU sample near the frames, no ground
        truth for ``gt_out``, or images whose size is not the calibration's or the first one's (the
        partial bag is removed).

    """
    if encoding not in ENCODINGS:
        raise ValueError(f'encoding must be one of {", ".join(ENCODINGS)}, got {encoding!r}')
    if jpeg_quality is not None and compress != 'jpeg':
        raise ValueError(
            f'--jpeg-quality applies to --compress jpeg only (got --compress {compress or "off"})'
        )
    quality = JPEG_QUALITY if jpeg_quality is None else jpeg_quality
    if compress is not None:
        check_compression(compress, quality)  # before the bag is opened
    last = _last_frame(source, first, count)
    non_negative_float.check('--imu-margin', imu_margin_s)
    if gt_out is not None and source.gt_boxes is None:
        raise ValueError(f'{source.name} has no ground truth to write to {gt_out}')
    tp = _topics(topics, compress)
    frame_t = np.asarray(source.frame_stamps_ns[first:last], dtype=np.int64)
    shift = -int(source.time_offset_ns)  # IMU clock -> camera clock
    imu_idx, imu_t = _imu_window(source, frame_t, shift, imu_margin_s)
    first_img = source.read_frame(first, encoding == 'mono8')
    h, w = first_img.shape[:2]
    if (
        source.camera is not None
        and source.camera.width is not None
        and (source.camera.width, source.camera.height) != (w, h)
    ):
        raise ValueError(
            f'calibration is for {source.camera.width}x{source.camera.height} but the images '
            f'are {w}x{h}'
        )
    meta = {
        f'{META_PREFIX}source': source.name,
        f'{META_PREFIX}frames': f'{first}:{last}',
        f'{META_PREFIX}imu_time_shift_ns': str(shift if source.has_imu else 0),
        f'{META_PREFIX}stamps': 'header stamps on the camera clock; IMU already shifted (replay '
        't_d = 0)',
    }
    with BagWriter(out, fmt, meta) as bag:
        bag.add_topic(tp['image'], IMAGE_TYPE if compress is None else COMPRESSED_IMAGE_TYPE)
        if source.camera is not None:
            bag.add_topic(tp['camera_info'], CAMERA_INFO_TYPE)
        if imu_t is not None:
            bag.add_topic(tp['imu'], IMU_TYPE)

        def image(i: int):
            img = first_img if i == 0 else source.read_frame(first + i, encoding == 'mono8')
            if img.shape[:2] != (h, w):
                raise ValueError(
                    f'frame {first + i} is {img.shape[1]}x{img.shape[0]}, the first one {w}x{h}'
                )
            args = (bag, tp['image'], int(frame_t[i]), frame_id, img)
            return (
                _image_msg(*args, encoding)
                if compress is None
                else _compressed_msg(*args, compress, quality)
            )

        imu_frame = source.imu_frame_id or frame_id
        for log_t, kind, i in _schedule(frame_t, imu_t, source.camera is not None):
            if kind == 0:
                j = imu_idx[i]
                acc = None if source.accel is None else source.accel[j]
                bag.write(
                    tp['imu'],
                    log_t,
                    _imu_msg(bag, tp['imu'], int(imu_t[i]), imu_frame, source.gyro[j], acc),
                )
            elif kind == 1:
                bag.write(
                    tp['camera_info'],
                    log_t,
                    _camera_info_msg(
                        bag, tp['camera_info'], int(frame_t[i]), frame_id, source.camera, w, h
                    ),
                )
            else:
                bag.write(tp['image'], log_t, image(i))
                if progress is not None:
                    progress(1)
    if gt_out is not None:
        write_gt(
            gt_out,
            source.gt_boxes[first:last],
            None if source.gt_flags is None else source.gt_flags[first:last],
        )
    return {
        'path': str(out),
        'format': fmt,
        'frames': last - first,
        'first': first,
        'size': (w, h),
        'image_topic': tp['image'],
        'imu': 0 if imu_t is None else len(imu_t),
        'camera_info': source.camera is not None,
        'imu_time_shift_ns': shift if imu_t is not None else 0,
        'counts': dict(bag.counts),
    }


def _last_frame(source: BagSource, first: int, count: int | None) -> int:
    """
    One past the last frame of the range.

    ValueError naming ``--first``/``--count`` outside the source.
    """
    n = len(source)
    if not 0 <= first < n:
        raise ValueError(f'--first {first} is outside the {n} frames of {source.name}')
    last = n if count is None else first + int(count)
    if count is not None and (count < 1 or last > n):
        raise ValueError(
            f'--count {count} from frame {first} exceeds the {n} frames of {source.name}'
        )
    return last


def _topics(topics: dict | None, compress: str | None) -> dict:
    """
    Return the bag's topics.

    The defaults, overridden, the image topic + ``/compressed`` when compressing.
    """
    tp = dict(DEFAULT_TOPICS, **(topics or {}))
    if compress is not None:
        if is_compressed_topic(tp['image']):
            raise ValueError(
                f'--image-topic {tp["image"]} ends in /compressed: give the raw topic, --compress '
                'appends /compressed as image_transport does'
            )
        tp['image'] = compressed_topic(tp['image'])
    return tp


def _imu_window(source: BagSource, frame_t: np.ndarray, shift: int, margin_s: float):
    """
    (indicate, camera-clock stamps) of the IMU samples within ``margin_s`` of the frames.

    (None, None) without IMU.
    """
    if not source.has_imu:
        return None, None
    t_cam = np.asarray(source.imu_t_ns, dtype=np.int64) + shift
    margin = int(round(margin_s * 1e9))
    idx = np.nonzero((t_cam >= frame_t[0] - margin) & (t_cam <= frame_t[-1] + margin))[0]
    if len(idx) == 0:
        raise ValueError(f'{source.name}: no IMU sample within {margin_s} s of the frames')
    return idx, t_cam[idx]


def write_gt(path, boxes: np.ndarray, flags=None) -> None:
    """
    Ground truth as 1-based ``x,y,w,h`` lines.

    Readable by :func:`iemd_ros.datasets.otb.parse_groundtruth` (``with_flags=True`` for the 5th
    column).

    Parameters
    ----------
    path : str or path-like
        The file written.
    boxes : ndarray
        (N, 4) 0-based boxes; ``NaN`` is written where absent (a box with a non-finite value).
    flags : sequence of str, optional
        The flags, as a 5th column if given.

    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open('w', newline='') as f:
        wr = csv.writer(f, lineterminator='\n')
        for k, b in enumerate(np.asarray(boxes, dtype=float)):
            row = (
                [repr(float(v)) for v in (b[0] + 1, b[1] + 1, b[2], b[3])]
                if np.all(np.isfinite(b))
                else ['NaN'] * 4
            )
            wr.writerow(row + ([str(flags[k])] if flags is not None else []))
