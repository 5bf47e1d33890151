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
Static coordinate frames as ``/tf_static`` carries them.

Composed along their tree (ROS-free, tf2's conventions).

A transform ``parent -> child`` (``TransformStamped.header.frame_id`` -> ``child_frame_id``) gives
the child frame's orientation in the parent: a vector ``v_c`` in the child frame is ``R v_c`` in
the parent.  :meth:`StaticFrames.rotation` composes the chain between two frames of the same tree,
as tf2's ``lookup_transform(target, source)`` does; the gyro prior wants ``R_cam_imu =
rotation(camera frame, IMU frame)`` (``w_cam = R_cam_imu w_imu``)::

    frames = StaticFrames()
    frames.add("base_link", "imu_link", (0, 0, 0, 1))  # x, y, z, w as in ROS
    frames.add("base_link", "camera_optical_frame", (-0.5, 0.5, -0.5, 0.5))
    R_cam_imu = frames.rotation("camera_optical_frame", "imu_link")
"""
from __future__ import annotations

from iemd_ros.gyro.rotation import quat_to_rot
import numpy as np

__all__ = ['StaticFrames', 'frame_name']

_MAX_DEPTH = 1000  # a tree deeper than this is taken for a cycle


def frame_name(frame_id: str) -> str:
    """
    Return a frame id as tf2 compares it (without a leading ``/``).

    Parameters
    ----------
    frame_id : str
        A header's ``frame_id``.

    Returns
    -------
    str
        The name.

    """
    return str(frame_id).lstrip('/')


class StaticFrames:
    """
    Static transforms by child frame.

    A child given again takes its newest parent and rotation (as tf2).
    """

    def __init__(self):
        self._parent: dict[str, tuple[str, np.ndarray]] = {}

    def __len__(self) -> int:
        return len(self._parent)

    def add(self, parent: str, child: str, quat_xyzw) -> bool:
        """
        Record the rotation of ``child`` in ``parent``.

        Parameters
        ----------
        parent, child : str
            The frames (``header.frame_id``, ``child_frame_id``).
        quat_xyzw : sequence of 4 float
            ``transform.rotation`` as ROS orders it (x, y, z, w); normalized here.

        Returns
        -------
        bool
            True when it changed what was known.

        Raises
        ------
        ValueError
            For an empty or equal frame name, or a zero or non-finite quaternion.

        """
        parent, child = frame_name(parent), frame_name(child)
        if not parent or not child or parent == child:
            raise ValueError(
                f'a transform needs two different, non-empty frames, got {parent!r} -> {child!r}'
            )
        x, y, z, w = (float(v) for v in quat_xyzw)
        R = quat_to_rot(np.array([w, x, y, z]))
        old = self._parent.get(child)
        if old is not None and old[0] == parent and np.array_equal(old[1], R):
            return False
        self._parent[child] = (parent, R)
        return True

    def _to_root(self, frame: str) -> tuple[str, np.ndarray]:
        """(root of ``frame``'s tree, orientation of ``frame`` in it)."""
        R = np.eye(3)
        for _ in range(_MAX_DEPTH):
            link = self._parent.get(frame)
            if link is None:
                return frame, R
            frame, R_parent = link
            R = R_parent @ R
        raise ValueError(f'the static transforms form a cycle through {frame!r}')

    def rotation(self, target: str, source: str) -> np.ndarray | None:
        """
        Orientation of ``source`` in ``target``: ``v_target = R v_source``.

        Parameters
        ----------
        target, source : str
            Frame ids.

        Returns
        -------
        ndarray or None
            3x3 rotation; the identity for one frame; None when the two are not in one tree.

        Raises
        ------
        ValueError
            When the transforms form a cycle.

        """
        target, source = frame_name(target), frame_name(source)
        if target == source:
            return np.eye(3)
        root_t, R_t = self._to_root(target)
        root_s, R_s = self._to_root(source)
        if root_t != root_s:
            return None
        return R_t.T @ R_s
