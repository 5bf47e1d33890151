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
The camera-IMU rotation from TF.

tf2_ros on a ROS install, else ``/tf_static`` read here and composed.

``tf2_ros`` has no PyPI wheel; without it the node subscribes ``/tf_static`` (tf2_msgs/TFMessage,
reliable and transient local, as static broadcasters publish it) and composes the static chain
between two frames itself (:class:`~iemd_ros.gyro.frames.StaticFrames`).  Dynamic ``/tf`` is only
read through tf2_ros.
"""
from __future__ import annotations

import threading

from iemd_ros.gyro.frames import StaticFrames
from iemd_ros.gyro.rotation import quat_to_rot
import numpy as np
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.time import Time

__all__ = ['TfExtrinsics', 'TF_STATIC_QOS']

TF_STATIC_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _tf2_ros():
    try:
        import tf2_ros
    except ImportError:
        return None
    return tf2_ros


class TfExtrinsics:
    """
    Looks up the orientation of one frame in another for a node.

    Parameters
    ----------
    node : rclpy.node.Node
        The node whose subscriptions read TF.
    warn : callable
        Receives a line for every transform that cannot be used (a malformed message never raises
        here).

    Attributes
    ----------
    backend : str
        "tf2_ros" or "/tf_static".

    """

    def __init__(self, node, warn):
        self._node, self._warn = node, warn
        tf2_ros = _tf2_ros()
        self._sub = self._listener = None
        if tf2_ros is not None:
            self._tf2 = tf2_ros
            self._buffer = tf2_ros.Buffer()
            self._listener = tf2_ros.TransformListener(self._buffer, node, spin_thread=False)
            self.backend = 'tf2_ros'
            return
        from tf2_msgs.msg import TFMessage

        self._frames = StaticFrames()
        self._lock = threading.Lock()
        self._sub = node.create_subscription(
            TFMessage, '/tf_static', self._on_tf_static, TF_STATIC_QOS
        )
        self.backend = '/tf_static'

    def _on_tf_static(self, msg) -> None:
        for t in msg.transforms:
            q = t.transform.rotation
            try:
                with self._lock:
                    self._frames.add(t.header.frame_id, t.child_frame_id, (q.x, q.y, q.z, q.w))
            except ValueError as exc:
                self._warn(
                    f'/tf_static transform {t.header.frame_id!r} -> {t.child_frame_id!r} ignored: '
                    f'{exc}'
                )

    def rotation(self, target: str, source: str) -> np.ndarray | None:
        """
        Orientation of ``source`` in ``target`` (``v_target = R v_source``).

        None when no transform is known.

        Parameters
        ----------
        target, source : str
            Frame ids.

        Returns
        -------
        ndarray or None
            3x3 rotation.

        """
        if self._listener is not None:
            try:
                t = self._buffer.lookup_transform(target.lstrip('/'), source.lstrip('/'), Time())
            except self._tf2.TransformException:
                return None
            q = t.transform.rotation
            return quat_to_rot(np.array([q.w, q.x, q.y, q.z]))
        with self._lock:
            try:
                return self._frames.rotation(target, source)
            except ValueError as exc:
                self._warn(f'TF lookup {source!r} -> {target!r}: {exc}')
                return None

    def close(self) -> None:
        """Destroy the subscription (or tf2_ros's listener)."""
        if self._listener is not None:
            self._listener.unregister()
        elif self._sub is not None:
            self._node.destroy_subscription(self._sub)
        self._sub = self._listener = None
