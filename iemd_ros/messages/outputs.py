"""The tracker's output messages, built once for every message library: the node's rclpy types and the replay's
rosbags types (ROS 2 field names)."""
from __future__ import annotations

from typing import Protocol

import numpy as np

from iemd_ros.messages.conversions import detection_values, ns_to_stamp

__all__ = ["MessageFactory", "header", "detection_array", "diagnostic_array", "DETECTIONS_TYPE", "DIAGNOSTICS_TYPE"]

DETECTIONS_TYPE = "vision_msgs/msg/Detection2DArray"
DIAGNOSTICS_TYPE = "diagnostic_msgs/msg/DiagnosticArray"


class MessageFactory(Protocol):
    """Builds messages of one library from their full type name and every field by keyword."""

    def __call__(self, msgtype: str, **fields): ...

    def byte(self, value: int):
        """The value of a ``byte`` field.

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
    """``std_msgs/Header`` stamped ``stamp_ns``.

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
    return make("std_msgs/msg/Header", stamp=make("builtin_interfaces/msg/Time", sec=sec, nanosec=nanosec),
                frame_id=frame_id)


def detection_array(make: MessageFactory, hdr, result, class_id: str, detection_id: str):
    """The ``vision_msgs/Detection2DArray`` of one frame.

    Parameters
    ----------
    make : MessageFactory
        Builds the messages.
    hdr : std_msgs/Header
        The header of the array and of its detection.
    result : FrameResult or None
        The frame's result (:class:`~iemd_ros.pipeline.FrameResult`).
    class_id : str
        The hypothesis' class.
    detection_id : str
        The detection's id.

    Returns
    -------
    vision_msgs/Detection2DArray
        One detection while ``result`` is tracking, else none.
    """
    detections = []
    values = detection_values(result)
    if values is not None:
        cx, cy, sx, sy = values.bbox
        hypothesis = make("vision_msgs/msg/ObjectHypothesisWithPose",
                          hypothesis=make("vision_msgs/msg/ObjectHypothesis", class_id=class_id, score=values.score),
                          pose=make("geometry_msgs/msg/PoseWithCovariance", pose=_identity_pose(make),
                                    covariance=np.zeros(36)))
        bbox = make("vision_msgs/msg/BoundingBox2D",
                    center=make("vision_msgs/msg/Pose2D", position=make("vision_msgs/msg/Point2D", x=cx, y=cy),
                                theta=0.0),
                    size_x=sx, size_y=sy)
        detections.append(make("vision_msgs/msg/Detection2D", header=hdr, results=[hypothesis], bbox=bbox,
                               id=detection_id))
    return make(DETECTIONS_TYPE, header=hdr, detections=detections)


def diagnostic_array(make: MessageFactory, hdr, statuses, hardware_id: str):
    """``diagnostic_msgs/DiagnosticArray`` of ``statuses``.

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
    return make(DIAGNOSTICS_TYPE, header=hdr, status=[
        make("diagnostic_msgs/msg/DiagnosticStatus", level=make.byte(int(level)), name=name, message=message,
             hardware_id=hardware_id,
             values=[make("diagnostic_msgs/msg/KeyValue", key=str(k), value=str(v)) for k, v in values.items()])
        for name, level, message, values in statuses])


def _identity_pose(make: MessageFactory):
    return make("geometry_msgs/msg/Pose", position=make("geometry_msgs/msg/Point", x=0.0, y=0.0, z=0.0),
                orientation=make("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=0.0, w=1.0))
