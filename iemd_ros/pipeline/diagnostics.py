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
The pipeline's diagnostics.

OK/WARN/ERROR statuses computed from one snapshot of its counters (no state here).
"""
from __future__ import annotations

from dataclasses import dataclass
import enum
import math

__all__ = ['Level', 'Part', 'Status', 'statuses', 'LOST_ERROR_FRAMES', 'IMU_ERROR_RUN', 'rate_hz']

LOST_ERROR_FRAMES = 30  # lost this many frames in a row: ERROR
IMU_ERROR_RUN = 10      # this many rejected IMU messages in a row: ERROR


class Level(enum.IntEnum):
    """Levels of diagnostic_msgs/DiagnosticStatus."""

    OK = 0
    WARN = 1
    ERROR = 2


class Part(enum.Enum):
    """What a status is about (its value ends the status name: ``<node>: <part>``)."""

    TRACKING = 'tracking'
    IMAGE = 'image input'
    IMU = 'imu'
    CAMERA = 'camera_info'
    # the published detections' rate and stamp age (the node's, pipeline.topic_status)
    OUTPUT = 'detections'


@dataclass(frozen=True)
class Status:
    """
    One diagnostic status about ``part``, with the values behind it.

    Parameters
    ----------
    part : Part
        What the status is about.
    level : Level
        OK, WARN or ERROR.
    message : str
        The status in one line.
    values : dict
        The values behind it, as strings.

    """

    part: Part
    level: Level
    message: str
    values: dict

    def name(self, prefix: str) -> str:
        """
        Return the status's name, ``<prefix>: <part>``.

        Parameters
        ----------
        prefix : str
            The node's name.

        Returns
        -------
        str
            The name.

        """
        return f'{prefix}: {self.part.value}'


def statuses(d: dict) -> list[Status]:
    """
    Return the tracking, image input, IMU and camera_info statuses of a diagnostics snapshot.

    Parameters
    ----------
    d : dict
        A :meth:`TrackingPipeline.diagnostics` snapshot.

    Returns
    -------
    list of Status
        The four statuses, in that order.

    """
    fmt = {k: (f'{v:.3f}' if isinstance(v, float) else str(v)) for k, v in d.items()}

    def vals(*keys):
        return {k: fmt[k] for k in keys}

    return [
        Status(
            Part.TRACKING,
            *_tracking(d),
            vals(
                'state',
                'targets',
                'held',
                'emd',
                'iterations',
                'lost_run',
                'lost_s',
                'frames_lost',
                'frames_held',
                'processing_ms_mean',
                'processing_ms_max',
                'processing_rate_hz',
                'inits',
                'resets',
                'updates_abandoned',
                'frame_reason',
            ),
        ),
        Status(
            Part.IMAGE,
            *_image(d),
            vals(
                'frames_received',
                'frames_processed',
                'frames_dropped',
                'frames_rejected',
                'images_malformed',
                'input_rate_hz',
                'processing_rate_hz',
                'recent_dropped',
                'image_error',
                'drop_reason',
                'clock_resets',
            ),
        ),
        Status(
            Part.IMU,
            *_imu(d),
            vals(
                'imu_received',
                'imu_rejected',
                'imu_out_of_order',
                'imu_saturated',
                'imu_stored',
                'imu_pending',
                'gyro_used',
                'gyro_unused',
                'recent_gyro_used',
                'gyro_reason',
                'imu_reason',
                'bias_status',
                'extrinsic_source',
                'imu_frame',
                'camera_frame',
                'R_cam_imu',
            ),
        ),
        Status(
            Part.CAMERA,
            *_camera(d),
            vals(
                'camera', 'camera_infos', 'camera_infos_rejected', 'camera_error', 'camera_misfit'
            ),
        ),
    ]


def _tracking(d: dict) -> tuple[Level, str]:
    if d['watchdog_reason']:
        return (
            Level.ERROR,
            f'latest frame: {d["watchdog_reason"]} ({d["updates_abandoned"]} abandoned so far)',
        )
    if d['state'] == 'uninitialized':
        return Level.WARN, 'no target: set the initial_box parameter or publish on ~/init'
    if d['state'] == 'lost':
        level = Level.ERROR if d['lost_run'] >= LOST_ERROR_FRAMES else Level.WARN
        return (
            level,
            f'target lost for {d["lost_run"]} frame(s), {d["lost_s"]:.2f} s: {d["frame_reason"]}',
        )
    return Level.OK, f'tracking (EMD {d["emd"]:.4f}, {d["iterations"]} iterations)'


def _image(d: dict) -> tuple[Level, str]:
    if d['image_bad']:
        return Level.ERROR, f'latest image rejected: {d["image_error"]}'
    if d['frames_received'] == 0:
        return Level.WARN, 'no image received yet'
    if d['recent_frames'] and d['recent_dropped'] > d['recent_frames'] // 2:
        return Level.WARN, (
            f'processing falls behind: {d["recent_dropped"]} of the last {d["recent_frames"]} '
            'frames dropped (the newest is kept)'
        )
    if d['stamp_rejected']:
        return Level.WARN, f'latest rejected frame: {d["frame_reason"]}'
    return Level.OK, f'{d["input_rate_hz"]:.1f} Hz in, {d["processing_rate_hz"]:.1f} Hz processed'


def _imu(d: dict) -> tuple[Level, str]:
    if not d['use_gyro']:
        return Level.OK, 'gyro prior disabled (use_gyro is false)'
    if d['imu_bad_run'] >= IMU_ERROR_RUN:
        return (
            Level.ERROR,
            f'the last {d["imu_bad_run"]} IMU samples were rejected: {d["imu_reason"]}',
        )
    if d['imu_received'] == 0:
        return Level.WARN, 'no IMU message received: tracking without the gyro prior'
    if d['imu_bad_run']:
        return Level.WARN, d['imu_reason']
    if d['frames_unrelated'] and d['parameter_is_identity']:
        return Level.WARN, (
            f"the IMU frame '{d['imu_frame']}' is not the image's '{d['camera_frame']}' and no "
            'transform between them is known (TF): using gyro.R_cam_imu, the identity'
        )
    if d['recent_processed'] and d['last_gyro_used'] is False:
        return Level.WARN, f'latest frame tracked without the gyro prior: {d["gyro_reason"]}'
    return (
        Level.OK,
        f'gyro prior used on {d["recent_gyro_used"]} of the last {d["recent_processed"]} frames',
    )


def _camera(d: dict) -> tuple[Level, str]:
    if not d['has_camera']:
        if d['camera_error']:
            return Level.ERROR, f'camera_info rejected: {d["camera_error"]}'
        if d['use_gyro']:
            return Level.WARN, 'no camera_info received: the gyro prior needs K'
        return Level.OK, 'no camera_info (not needed: gyro disabled)'
    if d['camera_error']:
        return (
            Level.WARN,
            f'latest camera_info rejected ({d["camera_error"]}); keeping the previous one',
        )
    if d['camera_misfit']:
        return (
            Level.WARN,
            f'camera model does not fit the images, no gyro prior: {d["camera_misfit"]}',
        )
    return Level.OK, 'camera model received'


def rate_hz(stamps) -> float:
    """
    Frames per second of message stamps over their span.

    Parameters
    ----------
    stamps : sequence of int
        Stamps, ns.

    Returns
    -------
    float
        The rate; nan with fewer than two stamps (or no span).

    """
    if len(stamps) < 2:
        return math.nan
    span = (max(stamps) - min(stamps)) * 1e-9
    return (len(stamps) - 1) / span if span > 0 else math.nan
