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
What the pipeline says about one frame.

:class:`FrameResult`, its :class:`TrackState` and :class:`Rejection`.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
import enum

from iemd_ros.tracking import Cause

__all__ = [
    'TrackState',
    'Rejection',
    'FrameResult',
    'INIT_REASON',
    'DEFAULT_TARGET',
    'ExtrinsicSource',
]

# FrameResult.reason of the frame init() started on
INIT_REASON = 'target initialized on this frame'
DEFAULT_TARGET = ''  # the target id of TrackingPipeline.init when none is given


class TrackState(enum.Enum):
    """The pipeline's tracking state (its value is the replay CSV's ``state``)."""

    UNINITIALIZED = 'uninitialized'  # no target: waiting for an initial box
    # the window is on the target (also when held: tracked, models not updated)
    TRACKING = 'tracking'
    LOST = 'lost'  # the tracker's window no longer looks like the target


class Rejection(enum.Enum):
    """Why a frame was not tracked (its value is the replay CSV's ``state`` of such a frame)."""

    STAMP = 'rejected'  # its stamp repeats or goes back from the previous frame's
    MALFORMED = 'malformed'  # the image message did not convert or decode
    ABANDONED = 'abandoned'  # the tracker update overran watchdog_ms: the tracker was rebuilt


class ExtrinsicSource(enum.Enum):
    """Where the camera-IMU rotation of the gyro prior comes from."""

    # no transform between the IMU's and the image's frames is known
    PARAMETER = 'parameter gyro.R_cam_imu'
    TF = 'tf'  # the transform between the frames (TF, /tf_static)


@dataclass(frozen=True, kw_only=True)
class FrameResult:
    """
    Outcome of one frame.

    ``box``/``angle``/``emd``/``iterations``/``held``/``cause`` come from the tracker
    (:class:`~iemd_ros.tracking.TrackResult`; the best window searched, also when lost).
    ``processing_ms`` is wall-clock time; everything else depends only on the messages.

    Parameters
    ----------
    stamp_ns : int
        The frame's stamp, camera clock, ns.
    state : TrackState
        The pipeline's state after the frame.
    box : tuple or None
        ``(x, y, w, h)``, the axis-aligned bounding box of the turned window.
    emd : float
        The window's EMD.
    score : float
        ``exp(-emd / score_emd_scale)`` while tracking, else 0.
    iterations : int
        Descent iterations of the chosen start.
    lost : bool
        Whether the tracker reports the target lost.
    held : bool
        Tracked, but the models did not learn.
    cause : Cause or None
        The kind of ``reason`` (None: tracked and learned).
    reason : str
        Why the frame is lost, held, rejected or untracked.
    rejection : Rejection or None
        Why the frame was not tracked.
    gyro_used : bool
        Whether a gyro prior was used.
    gyro_reason : str
        Why the gyro prior was or was not used.
    gyro_box : tuple or None
        The gyro's predicted window.
    predicted_box : tuple or None
        The tracker's starting window (after the gyro prior).
    scale : float
        Relative scale change chosen on the frame.
    starts : int
        Starting points searched.
    codings : int
        Candidate models built.
    solver_warnings : int
        EMD solves that did not end optimal.
    processing_ms : float
        Wall-clock time of the tracker's update.
    angle : float
        The window's turn (radians), which the gyro priors change (mostly the camera's roll).
    is_init : bool
        The result of the frame :meth:`TrackingPipeline.init` started on.
    target_id : str
        The target the result is about (:data:`DEFAULT_TARGET` unless ``init`` named one).

    """

    stamp_ns: int
    state: TrackState
    box: tuple | None = None
    emd: float = float('nan')
    score: float = 0.0
    iterations: int = 0
    lost: bool = False
    held: bool = False
    cause: Cause | None = None
    reason: str = ''
    rejection: Rejection | None = None
    gyro_used: bool = False
    gyro_reason: str = ''
    gyro_box: tuple | None = None
    predicted_box: tuple | None = None
    scale: float = 1.0
    starts: int = 0
    codings: int = 0
    solver_warnings: int = 0
    processing_ms: float = 0.0
    angle: float = 0.0
    is_init: bool = False  # the result of the frame TrackingPipeline.init started on
    target_id: str = DEFAULT_TARGET

    @property
    def tracking(self) -> bool:
        """Whether the frame was tracked and the target is reported (a detection is published)."""
        return self.state is TrackState.TRACKING and self.rejection is None

    def as_dict(self) -> dict:
        """
        Return the fields as a dict.

        Returns
        -------
        dict
            Field name -> value (``dataclasses.asdict``).

        """
        return asdict(self)
