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

"""The tracker run causally over a real camera + gyro recording, through the node's pipeline."""
from __future__ import annotations

from iemd_ros.datasets.recordings import Recording
from iemd_ros.pipeline import FrameResult, PipelineConfig, TrackingPipeline
from iemd_ros.tracking import TrackerConfig

__all__ = ['track_recording']


def track_recording(rec: Recording, start: int, stop: int, use_gyro: bool = True,
                    config: TrackerConfig | None = None) -> tuple[list[FrameResult], list[str]]:
    """
    Track frames ``start+1 .. stop-1`` of ``rec`` from its GT box at ``start``, causally.

    The frames and the whole gyro record go through a
    :class:`~iemd_ros.pipeline.pipeline.TrackingPipeline`, so the priors are the node's: with
    ``use_gyro`` the prior for frame k is the lens-aware local homography at the tracker's window,
    integrated from the previous frame (lost or not: a lost window keeps moving with the camera),
    and a prior the tracker refuses is dropped for that frame.

    Parameters
    ----------
    rec : Recording
        The recording, with ground truth at ``start``.
    start : int
        The frame the tracker starts on.
    stop : int
        One past the last frame tracked.
    use_gyro : bool, optional
        Use the gyro prior.
    config : TrackerConfig, optional
        The tracker's configuration (default ``TrackerConfig()``).

    Returns
    -------
    results : list of FrameResult
        One per frame tracked.
    notes : list of str
        One note per frame tracked without a gyro prior.

    """
    cfg = PipelineConfig(
        tracker=config if config is not None else TrackerConfig(),
        gyro=rec.gyro_config(),
        use_gyro=use_gyro,
    )
    pipe = TrackingPipeline(cfg, camera=rec.camera, live=False)
    if use_gyro:  # as the node gets them: one message at a time
        for t, w in zip(rec.imu_t_ns, rec.gyro):
            pipe.add_imu(int(t), w)
    pipe.init(rec.load_frame(start), rec.gt_boxes[start], int(rec.frame_stamps_ns[start]))
    results, no_prior = [], []
    for k in range(start + 1, stop):
        res = pipe.process(rec.load_frame(k), int(rec.frame_stamps_ns[k]))
        results.append(res)
        if use_gyro and not res.gyro_used:
            no_prior.append(f'frame {k}: {res.gyro_reason}')
    return results, no_prior
