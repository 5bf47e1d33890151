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
ROS messages <-> numpy and the pipeline's inputs and outputs, without rclpy or cv_bridge.

The functions read message fields by name and never import a message type, so ``rclpy`` messages
(``data`` is an ``array.array`` or ``bytes``), ``rosbags`` messages (``data`` is a numpy array) and
hand-made values all work:

    frame = image_from_msg(msg)                  # an Image (image_to_array) or a CompressedImage
                                                 # (compressed_to_array)
    t_ns, gyro, cov0 = imu_sample(msg)           # the arguments of add_imu_message
    camera = camera_model_from_msg(msg)          # CameraInfo, cached per content (ROS 1 or 2
                                                 # field names)
    fill_image_msg(Image(), frame)               # a frame into an Image's pixel fields
    values = detection_values(result)            # a FrameResult's Detection2D values (or None)

Pixel data is reinterpreted with ``np.frombuffer`` (no per-element Python loop); the returned frame
is what :class:`iemd_ros.IemdTracker` takes: ``HxW`` uint8 (grey) or ``HxWx3`` uint8 BGR.
"""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import cv2
from iemd_ros.common.boxes import box_centre, centre_box, check_box
from iemd_ros.common.limits import IMAGE_SIDE
from iemd_ros.gyro.camera import CameraModel
import numpy as np

__all__ = [
    'ENCODINGS',
    'COMPRESSED_CODECS',
    'JPEG_QUALITY',
    'image_to_array',
    'compressed_to_array',
    'array_to_image_fields',
    'array_to_compressed_fields',
    'check_compression',
    'compressed_topic',
    'is_compressed_topic',
    'raw_twin',
    'fill_image_msg',
    'camera_model_from_info',
    'camera_model_from_msg',
    'image_from_msg',
    'imu_sample',
    'stamp_to_ns',
    'stamp_ns',
    'ns_to_stamp',
    'box_to_bbox',
    'bbox_to_box',
    'bbox_values',
    'fill_bbox',
    'CLASS_ID',
    'DETECTION_ID',
    'DetectionValues',
    'detection_values',
]

# encoding -> (channels, bytes per channel)
ENCODINGS = {
    'mono8': (1, 1),
    'mono16': (1, 2),
    'bgr8': (3, 1),
    'rgb8': (3, 1),
    'bgra8': (4, 1),
    'rgba8': (4, 1),
}
COMPRESSED_CODECS = ('jpeg', 'png')  # image_transport's compressed plugin
JPEG_QUALITY = 95  # its default quality


def _as_bytes(data) -> memoryview:
    """
    Return a flat byte view of ``data``.

    (bytes, bytearray, array.array, numpy array, list of ints).
    """
    if isinstance(data, np.ndarray):
        return memoryview(np.ascontiguousarray(data).view(np.uint8).reshape(-1))
    if isinstance(data, (list, tuple)):  # rare: a hand-made message
        return memoryview(np.asarray(data, dtype=np.uint8))
    try:
        return memoryview(data).cast('B')
    except TypeError as exc:
        raise ValueError(f'image data must be bytes-like, got {type(data).__name__}') from exc


def image_to_array(
    encoding: str, height: int, width: int, step: int, data, is_bigendian: bool = False
) -> np.ndarray:
    """
    ``sensor_msgs/Image`` fields -> tracker frame.

    mono8/bgr8 are returned as views of ``data`` when the rows are unpadded; rgb8/bgra8/rgba8 are
    converted to BGR (alpha dropped).  mono16 (either byte order) is reduced to 8 bits by the right
    shift that puts the frame's highest set bit at bit 7 (a 12-bit sensor in mono16 keeps its 8
    most significant *used* bits instead of turning almost black under a fixed ``>> 8``; the shift
    only changes when the frame maximum crosses a power of two, and the tracker normalizes the grey
    levels of its window anyway).

    Parameters
    ----------
    encoding : str
        One of :data:`ENCODINGS`.
    height, width : int
        Image size, px.
    step : int
        Bytes per row.
    data : bytes-like
        The pixels (bytes, bytearray, array.array, numpy array or list of ints), ``step * height``
        bytes.
    is_bigendian : bool, optional
        Byte order of mono16 pixels.

    Returns
    -------
    ndarray
        ``HxW`` uint8 or ``HxWx3`` uint8 BGR.

    Raises
    ------
    ValueError
        For an unknown encoding, a width or height out of
        :data:`~iemd_ros.common.limits.IMAGE_SIDE`, a ``step`` shorter than a row or a ``data``
        size other than ``step * height``.

    """
    if encoding not in ENCODINGS:
        raise ValueError(
            f'unsupported image encoding {encoding!r}: expected one of {", ".join(ENCODINGS)}'
        )
    height, width, step = int(height), int(width), int(step)
    _check_size(width, height)
    channels, depth = ENCODINGS[encoding]
    row = width * channels * depth
    if step < row:
        raise ValueError(
            f'step {step} is shorter than one {encoding} row of {width} px ({row} bytes)'
        )
    buf = _as_bytes(data)
    if len(buf) != step * height:
        raise ValueError(
            f'image data has {len(buf)} bytes, expected step*height = {step}*{height} = '
            f'{step * height}'
        )
    raw = np.frombuffer(buf, dtype=np.uint8).reshape(height, step)[:, :row]
    if depth == 2:
        return _to_8bit(raw.view('>u2' if is_bigendian else '<u2').reshape(height, width))
    pix = raw.reshape(height, width, channels) if channels > 1 else raw
    if encoding in ('mono8', 'bgr8'):
        return pix
    if encoding == 'rgb8':
        return np.ascontiguousarray(pix[..., ::-1])
    if encoding == 'bgra8':
        return np.ascontiguousarray(pix[..., :3])
    return np.ascontiguousarray(pix[..., 2::-1])  # rgba8


def _check_size(width: int, height: int) -> None:
    """
    Raise ValueError unless the image's width and height are within the limits.

    The limits are :data:`~iemd_ros.common.limits.IMAGE_SIDE`.
    """
    IMAGE_SIDE.check('image width', width)
    IMAGE_SIDE.check('image height', height)


def _to_8bit(pixels: np.ndarray) -> np.ndarray:
    """
    16-bit pixels -> uint8 by the right shift that puts the highest set bit at bit 7.

    (see image_to_array).
    """
    shift = max(0, int(pixels.max()).bit_length() - 8)
    return (pixels >> shift).astype(np.uint8)


def compressed_to_array(fmt: str, data) -> np.ndarray:
    """
    ``sensor_msgs/CompressedImage`` fields -> tracker frame.

    The data are decoded by what they are (``cv2.imdecode``), which gives BGR whatever the source
    encoding (the plugin stores colour as bgr8, and the codec's own channel order is undone by
    OpenCV).  An alpha channel is dropped; 16-bit PNG (mono16/bgr16) is reduced to 8 bits as mono16
    in :func:`image_to_array`.

    Parameters
    ----------
    fmt : str
        ``format`` as image_transport's compressed plugin writes it (``"jpeg"``, ``"png"`` or e.g.
        ``"rgb8; jpeg compressed bgr8"``).
    data : bytes-like
        The compressed image.

    Returns
    -------
    ndarray
        ``HxW`` or ``HxWx3`` uint8 BGR.

    Raises
    ------
    ValueError
        For data that do not decode, an image size out of
        :data:`~iemd_ros.common.limits.IMAGE_SIDE`, and for ``compressedDepth`` (depth maps, not
        camera images).

    """
    if 'compresseddepth' in str(fmt).lower():
        raise ValueError(
            f'compressed image format {fmt!r} is a depth map (compressedDepth), not a camera image'
        )
    buf = np.frombuffer(_as_bytes(data), dtype=np.uint8)
    if buf.size == 0:
        raise ValueError(f'compressed image ({fmt!r}) has no data')
    try:
        img = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
    except cv2.error as exc:  # e.g. a header declaring more pixels than OpenCV accepts
        raise ValueError(
            f'cannot decode the compressed image (format {fmt!r}, {buf.size} bytes): '
            f'{str(exc).strip().splitlines()[-1]}'
        ) from None
    if img is None:
        raise ValueError(f'cannot decode the compressed image (format {fmt!r}, {buf.size} bytes)')
    if img.dtype == np.uint16:
        img = _to_8bit(img)
    elif img.dtype != np.uint8:
        raise ValueError(
            f'compressed image ({fmt!r}) decodes to {img.dtype} pixels; expected 8 or 16 bits'
        )
    _check_size(img.shape[1], img.shape[0])
    if img.ndim == 3 and img.shape[2] == 4:
        img = img[..., :3]
    return np.ascontiguousarray(img)


def array_to_image_fields(frame: np.ndarray, encoding: str | None = None) -> dict:
    """
    Tracker frame -> ``sensor_msgs/Image`` fields (``data`` as ``bytes``, the fast path for rclpy).

    :func:`fill_image_msg` sets them on a message.

    Parameters
    ----------
    frame : ndarray
        Tracker frame, ``HxW`` or ``HxWx3`` uint8.
    encoding : str, optional
        Default mono8 for ``HxW`` and bgr8 for ``HxWx3`` frames; rgb8 flips the channels.

    Returns
    -------
    dict
        The fields encoding, height, width, step, is_bigendian and data.

    Raises
    ------
    ValueError
        For a frame that is not a tracker frame, or an encoding it cannot be written as.

    """
    frame = _check_frame(frame)
    default = 'mono8' if frame.ndim == 2 else 'bgr8'
    encoding = default if encoding is None else encoding
    if encoding not in (default, 'rgb8' if frame.ndim == 3 else default):
        raise ValueError(f'cannot write a {frame.shape} frame as {encoding!r}')
    if encoding == 'rgb8':
        frame = frame[..., ::-1]
    h, w = frame.shape[:2]
    channels = 1 if frame.ndim == 2 else 3
    return {
        'encoding': encoding,
        'height': h,
        'width': w,
        'step': w * channels,
        'is_bigendian': 0,
        'data': np.ascontiguousarray(frame).tobytes(),
    }


def _check_frame(frame) -> np.ndarray:
    """``frame`` as an array, checked to be a tracker frame (``HxW`` or ``HxWx3`` uint8)."""
    frame = np.asarray(frame)
    if (
        frame.dtype != np.uint8
        or frame.ndim not in (2, 3)
        or (frame.ndim == 3 and frame.shape[2] != 3)
    ):
        raise ValueError(f'frame must be HxW or HxWx3 uint8, got {frame.dtype} {frame.shape}')
    return frame


def check_compression(codec: str, quality: int = JPEG_QUALITY) -> None:
    """
    Check a compressed image's codec and quality.

    Parameters
    ----------
    codec : str
        One of :data:`COMPRESSED_CODECS`.
    quality : int, optional
        JPEG quality, 1-100.

    Raises
    ------
    ValueError
        Unless ``codec`` is one of :data:`COMPRESSED_CODECS` and ``quality`` a JPEG quality 1-100.

    """
    if codec not in COMPRESSED_CODECS:
        raise ValueError(
            f'codec must be {" or ".join(map(repr, COMPRESSED_CODECS))}, got {codec!r}'
        )
    if not 1 <= int(quality) <= 100:
        raise ValueError(f'JPEG quality must be in [1, 100], got {quality}')


def compressed_topic(image_topic: str) -> str:
    """
    image_transport's name of an image topic's compressed stream: ``<image_topic>/compressed``.

    Parameters
    ----------
    image_topic : str
        The raw image topic.

    Returns
    -------
    str
        The compressed topic.

    """
    return image_topic.rstrip('/') + '/compressed'


def is_compressed_topic(topic: str) -> bool:
    """
    Return True for a name whose last part is ``compressed`` (image_transport's compressed stream).

    Parameters
    ----------
    topic : str
        A topic name.

    Returns
    -------
    bool
        Whether it names a compressed stream.

    """
    return topic.rstrip('/').rpartition('/')[2] == 'compressed'


def raw_twin(topic: str) -> str | None:
    """
    Return the image topic whose compressed stream ``topic`` is named as.

    (inverse of :func:`compressed_topic`).

    Parameters
    ----------
    topic : str
        A topic name.

    Returns
    -------
    str or None
        The raw image topic; None for a name that is not ``<image>/compressed``.

    """
    head = topic.rstrip('/').rpartition('/')[0]
    return head if is_compressed_topic(topic) and head else None


def array_to_compressed_fields(
    frame: np.ndarray, codec: str = 'jpeg', quality: int = JPEG_QUALITY
) -> dict:
    """
    Tracker frame -> ``sensor_msgs/CompressedImage`` fields.

    The fields are as image_transport's compressed plugin writes them.  ``format`` is ``"bgr8; jpeg
    compressed bgr8"``, for ``HxW`` ``"mono8; jpeg compressed "`` (the plugin names a target
    encoding for colour only; ``png`` is lossless).

    Parameters
    ----------
    frame : ndarray
        Tracker frame, ``HxW`` or ``HxWx3`` uint8.
    codec : {"jpeg", "png"}, optional
        The codec.
    quality : int, optional
        JPEG quality, 1-100.

    Returns
    -------
    dict
        ``format`` and the encoded ``data`` as ``bytes``.

    Raises
    ------
    ValueError
        For a bad frame, codec or quality, or a frame OpenCV cannot encode.

    """
    frame = _check_frame(frame)
    check_compression(codec, quality)
    params = [cv2.IMWRITE_JPEG_QUALITY, int(quality)] if codec == 'jpeg' else []
    ok, buf = cv2.imencode('.jpg' if codec == 'jpeg' else '.png', frame, params)
    if not ok:
        raise ValueError(f'OpenCV could not encode a {frame.shape} frame as {codec}')
    fmt = f'mono8; {codec} compressed ' if frame.ndim == 2 else f'bgr8; {codec} compressed bgr8'
    return {'format': fmt, 'data': buf.tobytes()}


def fill_image_msg(msg, frame: np.ndarray, encoding: str | None = None):
    """
    Set a ``sensor_msgs/Image``'s pixel fields from a tracker frame.

    (:func:`array_to_image_fields`).

    The header is the caller's.  ``data`` goes in as ``bytes``, which an rclpy message copies at
    once, where a numpy array is converted element by element.

    Parameters
    ----------
    msg : sensor_msgs/Image
        The message to fill.
    frame : ndarray
        Tracker frame, ``HxW`` or ``HxWx3`` uint8.
    encoding : str, optional
        As :func:`array_to_image_fields` takes it.

    Returns
    -------
    sensor_msgs/Image
        ``msg``.

    Raises
    ------
    ValueError
        As :func:`array_to_image_fields` raises it.

    """
    for name, value in array_to_image_fields(frame, encoding).items():
        setattr(msg, name, value)
    return msg


def camera_model_from_msg(msg) -> CameraModel:
    """
    Return the camera model of a ``sensor_msgs/CameraInfo``.

    (ROS 2 ``k``/``d`` or ROS 1 ``K``/``D`` fields).

    A driver repeats the same CameraInfo with every image; each content is turned into a model
    once.

    Parameters
    ----------
    msg : sensor_msgs/CameraInfo
        An rclpy or rosbags message.

    Returns
    -------
    CameraModel
        The model (:func:`camera_model_from_info`).

    Raises
    ------
    ValueError
        For bad content (not cached).

    """
    k = getattr(msg, 'k', None)
    d = getattr(msg, 'd', None)
    if k is None:  # ROS 1 field names
        k, d = msg.K, msg.D
    return _camera_model(
        tuple(map(float, k)), tuple(map(float, d)), msg.distortion_model, msg.width, msg.height
    )


@lru_cache(maxsize=4)
def _camera_model(
    k: tuple, d: tuple, distortion_model: str, width: int, height: int
) -> CameraModel:
    return camera_model_from_info(k, d, distortion_model, width, height)


def camera_model_from_info(k, d, distortion_model: str, width: int, height: int) -> CameraModel:
    """
    ``sensor_msgs/CameraInfo`` fields -> :class:`~iemd_ros.gyro.camera.CameraModel`.

    (K and plumb_bob D).

    Parameters
    ----------
    k : sequence of float
        The 9 values of K.
    d : sequence of float
        The distortion coefficients.
    distortion_model : str
        The distortion model ("" means plumb_bob).
    width, height : int
        Image size (0: unknown).

    Returns
    -------
    CameraModel
        The model.

    Raises
    ------
    ValueError
        For a ``k`` not of 9 values, an all-zero ``k`` (an uncalibrated driver), non-plumb_bob
        models with non-zero coefficients, and a focal length or principal point out of its limit
        for the image size (:class:`CameraModel`), saying so.

    """
    K = np.asarray(k, dtype=float).ravel()
    if K.shape != (9,):
        raise ValueError(f'camera_info k must have 9 values, got {K.size}')
    if not np.any(K):
        raise ValueError('camera_info k is all zero: the camera is not calibrated')
    D = np.asarray(d, dtype=float).ravel()
    w, h = int(width), int(height)
    return CameraModel.from_camera_info(
        {
            'k': K,
            'd': D,
            'distortion_model': distortion_model or 'plumb_bob',
            'width': w if w > 0 else None,
            'height': h if h > 0 else None,
        }
    )


def stamp_to_ns(sec: int, nanosec: int) -> int:
    """
    ``builtin_interfaces/Time`` -> integer nanoseconds.

    Parameters
    ----------
    sec, nanosec : int
        The stamp's fields.

    Returns
    -------
    int
        Nanoseconds.

    """
    return int(sec) * 1_000_000_000 + int(nanosec)


def image_from_msg(msg) -> np.ndarray:
    """
    Return a ``sensor_msgs/Image`` or ``sensor_msgs/CompressedImage`` -> tracker frame.

    Parameters
    ----------
    msg : sensor_msgs/Image or sensor_msgs/CompressedImage
        An rclpy or rosbags message (:func:`image_to_array`, :func:`compressed_to_array`).

    Returns
    -------
    ndarray
        ``HxW`` uint8 or ``HxWx3`` uint8 BGR.

    Raises
    ------
    ValueError
        For an image that cannot be converted.

    """
    if hasattr(msg, 'format'):  # CompressedImage: header, format, data
        return compressed_to_array(msg.format, msg.data)
    return image_to_array(
        msg.encoding, msg.height, msg.width, msg.step, msg.data, bool(msg.is_bigendian)
    )


def imu_sample(msg) -> tuple[int, tuple[float, float, float], float]:
    """
    Return a ``sensor_msgs/Imu`` -> the arguments of ``TrackingPipeline.add_imu_message``.

    Parameters
    ----------
    msg : sensor_msgs/Imu
        An rclpy or rosbags message.

    Returns
    -------
    stamp_ns : int
        The header's stamp, ns.
    rates : tuple of float
        Gyro rates (x, y, z), rad/s.
    covariance0 : float
        ``angular_velocity_covariance[0]``.

    """
    w = msg.angular_velocity
    return stamp_ns(msg.header), (w.x, w.y, w.z), msg.angular_velocity_covariance[0]


def stamp_ns(header) -> int:
    """
    Nanoseconds of a ``std_msgs/Header``.

    Parameters
    ----------
    header : std_msgs/Header
        An rclpy or rosbags message, ROS 1 or 2.

    Returns
    -------
    int
        The stamp, ns.

    """
    return stamp_to_ns(header.stamp.sec, header.stamp.nanosec)


def ns_to_stamp(t_ns: int) -> tuple[int, int]:
    """
    Integer nanoseconds -> ``(sec, nanosec)``.

    Parameters
    ----------
    t_ns : int
        Nanoseconds.

    Returns
    -------
    sec : int
        Seconds.
    nanosec : int
        Nanoseconds, ``0 <= nanosec < 1e9``.

    """
    sec, nsec = divmod(int(t_ns), 1_000_000_000)
    return sec, nsec


def box_to_bbox(box) -> tuple[float, float, float, float]:
    """
    Tracker box ``(x, y, w, h)`` -> ``vision_msgs/BoundingBox2D``.

    The BoundingBox2D is ``(center_x, center_y, size_x, size_y)``.  The centre is in pixel-index
    coordinates (pixel centres at integers, as ``K``): ``x + (w - 1) / 2``
    (:func:`iemd_ros.common.boxes.box_centre`); the size is ``w, h`` pixels.

    Parameters
    ----------
    box : sequence of 4 float
        (x, y, w, h).

    Returns
    -------
    tuple of float
        ``(center_x, center_y, size_x, size_y)``.

    Raises
    ------
    ValueError
        For a box that is not finite with a positive size.

    """
    b = check_box(box)
    cx, cy = box_centre(b)
    return float(cx), float(cy), b[2], b[3]


def bbox_to_box(
    center_x: float, center_y: float, size_x: float, size_y: float
) -> tuple[float, float, float, float]:
    """
    Inverse of :func:`box_to_bbox`.

    The values are checked as given (``check_box``'s last two are the sizes), so the message shows
    what the sender wrote, not the corner box derived from it.

    Parameters
    ----------
    center_x, center_y : float
        The centre, pixel-index coordinates.
    size_x, size_y : float
        The size, px.

    Returns
    -------
    tuple of float
        The tracker box ``(x, y, w, h)``.

    Raises
    ------
    ValueError
        For non-finite values or a non-positive size.

    """
    cx, cy, sx, sy = check_box(
        (center_x, center_y, size_x, size_y), 'bounding box (center_x, center_y, size_x, size_y)'
    )
    return tuple(float(v) for v in centre_box((cx, cy), (sx, sy)))


def bbox_values(bbox) -> tuple[float, float, float, float]:
    """
    Return a ``vision_msgs/BoundingBox2D`` -> ``(center_x, center_y, size_x, size_y)``.

    Parameters
    ----------
    bbox : vision_msgs/BoundingBox2D
        An rclpy or rosbags message.

    Returns
    -------
    tuple of float
        ``(center_x, center_y, size_x, size_y)``.

    """
    c = bbox.center.position
    return c.x, c.y, bbox.size_x, bbox.size_y


def fill_bbox(bbox, values) -> None:
    """
    Set a ``vision_msgs/BoundingBox2D``'s centre and size; ``theta`` is left as it is.

    Parameters
    ----------
    bbox : vision_msgs/BoundingBox2D
        The message to fill.
    values : sequence of 4 float
        ``(center_x, center_y, size_x, size_y)`` (:func:`box_to_bbox`'s values).

    """
    c = bbox.center.position
    c.x, c.y, bbox.size_x, bbox.size_y = (float(v) for v in values)


CLASS_ID = 'target'  # default class_id of the published hypothesis (node parameter ``class_id``)
DETECTION_ID = 'iemd'  # default id of the published Detection2D (node parameter ``detection_id``)


class DetectionValues(NamedTuple):
    """
    Values of the tracker's ``vision_msgs/Detection2D``.

    Parameters
    ----------
    bbox : tuple of float
        ``(center_x, center_y, size_x, size_y)`` (``theta`` 0).
    score : float
        Its one hypothesis' score.

    """

    bbox: tuple[float, float, float, float]
    score: float


def detection_values(result) -> DetectionValues | None:
    """
    Return a :class:`~iemd_ros.pipeline.pipeline.FrameResult` -> its detection's values.

    Parameters
    ----------
    result : FrameResult or None
        The frame's result.

    Returns
    -------
    DetectionValues or None
        :func:`box_to_bbox` of its box and its score; None when ``result`` is None or not tracking:
        no detection is published then.

    """
    if result is None or not result.tracking:
        return None
    return DetectionValues(box_to_bbox(result.box), float(result.score))
