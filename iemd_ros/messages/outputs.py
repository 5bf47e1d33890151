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
The tracker's output messages, built once for every message library.

The node's rclpy types and the replay's rosbags types (ROS 2 field names).
"""
from __future__ import annotations

import math
from typing import Protocol

from iemd_ros.gyro.bearing import bearing, ray_quaternion
from iemd_ros.messages.conversions import detection_values, ns_to_stamp
import numpy as np

__all__ = [
    'MessageFactory',
    'header',
    'detection_array',
    'bearing_array',
    'image_annotations',
    'diagnostic_array',
    'DETECTIONS_TYPE',
    'BEARINGS_TYPE',
    'ANNOTATIONS_TYPE',
    'DIAGNOSTICS_TYPE',
    'COMPRESSED_IMAGE_TYPE',
]

DETECTIONS_TYPE = 'vision_msgs/msg/Detection2DArray'
BEARINGS_TYPE = 'vision_msgs/msg/Detection3DArray'
ANNOTATIONS_TYPE = 'foxglove_msgs/msg/ImageAnnotations'
DIAGNOSTICS_TYPE = 'diagnostic_msgs/msg/DiagnosticArray'
COMPRESSED_IMAGE_TYPE = 'sensor_msgs/msg/CompressedImage'
LINE_LOOP = 2  # foxglove_msgs/PointsAnnotation.LINE_LOOP


class MessageFactory(Protocol):
    """Builds messages of one library from their full type name and every field by keyword."""

    def __call__(self, msgtype: str, **fields): ...

    def byte(self, value: int):
        """
        Return the value of a ``byte`` field.

        Parameters
        ----------
        value : int
            The byte's value.

        Returns
        -------
        bytes or int
            For rclpy ``bytes`` of length 1, for rosbags an int.

        """


def header(make: MessageFactory, stamp_ns: int, frame_id: str):
    """
    ``std_msgs/Header`` stamped ``stamp_ns``.

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    stamp_ns : int
        The stamp, ns.
    frame_id : str
        The header's frame.

    Returns
    -------
    std_msgs/Header
        A message of ``make``'s library.

    """
    sec, nanosec = ns_to_stamp(stamp_ns)
    return make(
        'std_msgs/msg/Header',
        stamp=make('builtin_interfaces/msg/Time', sec=sec, nanosec=nanosec),
        frame_id=frame_id,
    )


def _hypothesis(make: MessageFactory, class_id: str, score: float, pose):
    return make(
        'vision_msgs/msg/ObjectHypothesisWithPose',
        hypothesis=make('vision_msgs/msg/ObjectHypothesis', class_id=class_id, score=score),
        pose=make('geometry_msgs/msg/PoseWithCovariance', pose=pose, covariance=np.zeros(36)),
    )


def _target_id(result, default_id: str) -> str:
    return result.target_id or default_id


def detection_array(make: MessageFactory, hdr, results, class_id: str, default_id: str):
    """
    Return the ``vision_msgs/Detection2DArray`` of one frame.

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    hdr : std_msgs/Header
        The header of the array and of its detections.
    results : iterable of FrameResult
        The frame's results, one per target (:class:`~iemd_ros.pipeline.FrameResult`).
    class_id : str
        The hypotheses' class.
    default_id : str
        The id of a detection whose result names no target.

    Returns
    -------
    vision_msgs/Detection2DArray
        One detection per target that is tracking, with the target's id.

    """
    detections = []
    for result in results:
        values = detection_values(result)
        if values is None:
            continue
        cx, cy, sx, sy = values.bbox
        bbox = make(
            'vision_msgs/msg/BoundingBox2D',
            center=make(
                'vision_msgs/msg/Pose2D',
                position=make('vision_msgs/msg/Point2D', x=cx, y=cy),
                theta=0.0,
            ),
            size_x=sx,
            size_y=sy,
        )
        detections.append(
            make(
                'vision_msgs/msg/Detection2D',
                header=hdr,
                results=[_hypothesis(make, class_id, values.score, _pose(make))],
                bbox=bbox,
                id=_target_id(result, default_id),
            )
        )
    return make(DETECTIONS_TYPE, header=hdr, detections=detections)


def bearing_array(make: MessageFactory, hdr, results, camera, class_id: str, default_id: str):
    """
    Return the bearings of one frame's targets as a ``vision_msgs/Detection3DArray``.

    The array is in the camera's optical frame.  Each detection is the target seen as if at 1 m
    along its ray (:mod:`iemd_ros.gyro.bearing`): ``bbox.center`` has the unit ray as its position
    and, as its orientation, the shortest rotation of the optical axis onto the ray; ``bbox.size``
    is ``(2 tan(angular_width / 2), 2 tan(angular_height / 2), 0)``, the size at that range; the
    hypothesis carries the class, the score and the same pose.

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    hdr : std_msgs/Header
        The image's header (its frame is the optical frame).
    results : iterable of FrameResult
        The frame's results.
    camera : CameraModel or None
        The lens; None gives an empty array (no bearing without K).
    class_id : str
        The hypotheses' class.
    default_id : str
        The id of a detection whose result names no target.

    Returns
    -------
    vision_msgs/Detection3DArray
        One detection per tracking target whose box lies in the lens model's valid region.

    """
    detections = []
    for result in results if camera is not None else ():
        values = detection_values(result)
        if values is None:
            continue
        try:
            b = bearing(camera, result.box)
        except ValueError:
            continue
        pose = _pose(make, b.ray, ray_quaternion(b.ray))
        size = make(
            'geometry_msgs/msg/Vector3',
            x=2 * math.tan(b.angular_width / 2),
            y=2 * math.tan(b.angular_height / 2),
            z=0.0,
        )
        detections.append(
            make(
                'vision_msgs/msg/Detection3D',
                header=hdr,
                results=[_hypothesis(make, class_id, values.score, pose)],
                bbox=make('vision_msgs/msg/BoundingBox3D', center=pose, size=size),
                id=_target_id(result, default_id),
            )
        )
    return make(BEARINGS_TYPE, header=hdr, detections=detections)


def image_annotations(make: MessageFactory, stamp_ns: int, results, default_id: str, colour_of):
    """
    ``foxglove_msgs/ImageAnnotations`` of one frame.

    Each target's box as a closed line and its id and score as a label, stamped like the image
    (Foxglove's Image panel draws them over the image of that stamp).

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    stamp_ns : int
        The image's stamp, ns.
    results : iterable of FrameResult
        The frame's results (those with a box are drawn).
    default_id : str
        The label of a result that names no target.
    colour_of : callable
        FrameResult -> (B, G, R) 0-255 (:func:`iemd_ros.pipeline.drawing.box_colour`).

    Returns
    -------
    foxglove_msgs/ImageAnnotations
        One points annotation (LINE_LOOP of the box's corners) and one text per result with a box.

    """
    sec, nanosec = ns_to_stamp(stamp_ns)
    points, texts = [], []
    for r in results:
        if r.box is None:
            continue
        b, g, rd = (c / 255.0 for c in colour_of(r))
        colour = make('foxglove_msgs/msg/Color', r=rd, g=g, b=b, a=1.0)
        clear = make('foxglove_msgs/msg/Color', r=0.0, g=0.0, b=0.0, a=0.0)
        x, y, w, h = r.box
        left, top, right, bottom = x - 0.5, y - 0.5, x + w - 0.5, y + h - 0.5
        corners = [
            make('foxglove_msgs/msg/Point2', x=float(px), y=float(py))
            for px, py in ((left, top), (right, top), (right, bottom), (left, bottom))
        ]
        stamp = make('builtin_interfaces/msg/Time', sec=sec, nanosec=nanosec)
        points.append(
            make(
                'foxglove_msgs/msg/PointsAnnotation',
                timestamp=stamp,
                type=LINE_LOOP,
                points=corners,
                outline_color=colour,
                outline_colors=[],
                fill_color=clear,
                thickness=2.0,
            )
        )
        label = (
            f'{_target_id(r, default_id)} {r.score:.2f}'
            if r.tracking
            else f'{_target_id(r, default_id)} '
            f'{r.rejection.value if r.rejection else r.state.value}'
        )
        texts.append(
            make(
                'foxglove_msgs/msg/TextAnnotation',
                timestamp=stamp,
                position=make('foxglove_msgs/msg/Point2', x=float(left), y=float(top - 4.0)),
                text=label,
                font_size=14.0,
                text_color=colour,
                background_color=make('foxglove_msgs/msg/Color', r=0.0, g=0.0, b=0.0, a=0.5),
            )
        )
    return make(ANNOTATIONS_TYPE, circles=[], points=points, texts=texts)


def diagnostic_array(make: MessageFactory, hdr, statuses, hardware_id: str):
    """
    ``diagnostic_msgs/DiagnosticArray`` of ``statuses``.

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    hdr : std_msgs/Header
        The array's header.
    statuses : iterable of tuple
        (name, level, message, values) tuples.
    hardware_id : str
        The statuses' hardware_id.

    Returns
    -------
    diagnostic_msgs/DiagnosticArray
        One status per tuple.

    """
    return make(
        DIAGNOSTICS_TYPE,
        header=hdr,
        status=[
            make(
                'diagnostic_msgs/msg/DiagnosticStatus',
                level=make.byte(int(level)),
                name=name,
                message=message,
                hardware_id=hardware_id,
                values=[
                    make('diagnostic_msgs/msg/KeyValue', key=str(k), value=str(v))
                    for k, v in values.items()
                ],
            )
            for name, level, message, values in statuses
        ],
    )


def _pose(make: MessageFactory, position=(0.0, 0.0, 0.0), quat_xyzw=(0.0, 0.0, 0.0, 1.0)):
    (x, y, z), (qx, qy, qz, qw) = (float(v) for v in position), (float(v) for v in quat_xyzw)
    return make(
        'geometry_msgs/msg/Pose',
        position=make('geometry_msgs/msg/Point', x=x, y=y, z=z),
        orientation=make('geometry_msgs/msg/Quaternion', x=qx, y=qy, z=qz, w=qw),
    )
