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
How long a frame waits for the gyro to cover it.

One policy for the node (wall clock) and the replay (bag time).
"""
from __future__ import annotations

__all__ = ['ImuWait']


class ImuWait:
    """
    A frame goes to the tracker once the gyro covers it, or once it has waited ``imu_wait_ms``.

    The clock is the caller's: the node passes monotonic wall-clock times, the replay the log times
    of the bag's messages, so that a replay at any speed takes the decisions the node takes when
    the bag plays at 1x.

    Parameters
    ----------
    pipeline : TrackingPipeline
        Says whether the gyro covers a frame (:meth:`TrackingPipeline.gyro_ready`).

    """

    def __init__(self, pipeline):
        self._pipeline = pipeline

    @property
    def wait_ns(self) -> int:
        """Return the longest wait, ns (the pipeline's ``imu_wait_ms``)."""
        return int(round(self._pipeline.config.imu_wait_ms * 1e6))

    def ready(self, stamp_ns: int) -> bool:
        """
        Whether the frame stamped ``stamp_ns`` loses nothing by going now.

        Parameters
        ----------
        stamp_ns : int
            The frame's stamp, camera clock, ns.

        Returns
        -------
        bool
            True when the gyro covers it, or no prior can be used.

        """
        return self._pipeline.gyro_ready(stamp_ns)

    def waited_out(self, arrival_ns: int, now_ns: int) -> bool:
        """
        Whether a frame that arrived at ``arrival_ns`` has waited its longest at ``now_ns``.

        Parameters
        ----------
        arrival_ns, now_ns : int
            Times on the caller's clock, ns.

        Returns
        -------
        bool
            True once more than ``imu_wait_ms`` has passed.

        """
        return now_ns - arrival_ns > self.wait_ns

    def remaining_s(self, arrival_ns: int, now_ns: int) -> float:
        """
        Seconds the frame that arrived at ``arrival_ns`` may still wait at ``now_ns``.

        Parameters
        ----------
        arrival_ns, now_ns : int
            Times on the caller's clock, ns.

        Returns
        -------
        float
            Seconds left (<= 0: none).

        """
        return (arrival_ns + self.wait_ns - now_ns) * 1e-9
