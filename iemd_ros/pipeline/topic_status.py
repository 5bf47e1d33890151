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
A published topic's rate and stamp-age checks.

As diagnostic_updater's ``TopicDiagnostic`` makes them (ROS-free).

:class:`TopicStatus` is diagnostic_updater's ``FrequencyStatus`` (events counted over a window of
the last ``window`` diagnostics updates; ERROR "No events recorded.", WARN "Frequency too low."
below ``min_rate_hz * (1 - tolerance)`` or "Frequency too high." above ``max_rate_hz * (1 +
tolerance)``, else OK "Desired frequency met") merged with its ``TimeStampStatus`` (the age ``now -
stamp`` of each message at publication, the earliest and latest since the last update; WARN "No
data since last update.", ERROR "Zero timestamp seen.", "Timestamps too far in future seen." below
``stamp_age_min_s`` or "Timestamps too far in the past seen." above ``stamp_age_max_s``), with the
highest level and the messages joined by "; " as its composite task merges them. Its values carry
diagnostic_updater's key names.
"""
from __future__ import annotations

from collections import deque
import threading

from iemd_ros.pipeline.diagnostics import Level

__all__ = ['TopicStatus']


class TopicStatus:
    """
    Rate window and stamp-age check of one published topic.

    Parameters
    ----------
    min_rate_hz, max_rate_hz : float
        The expected rate's window (0 for ``max_rate_hz``: no upper bound).
    tolerance : float
        Relative tolerance on both bounds.
    window : int
        Diagnostics updates the rate is measured over.
    stamp_age_min_s, stamp_age_max_s : float
        Acceptable range of ``now - stamp`` at publication, s (negative: a stamp in the future).
    start_s : float
        Monotonic time the window starts at, s.

    """

    def __init__(self, min_rate_hz: float, max_rate_hz: float, tolerance: float, window: int,
                 stamp_age_min_s: float, stamp_age_max_s: float, start_s: float):
        self._lock = threading.Lock()
        self._count = 0
        self._history: deque = deque([(float(start_s), 0)])
        self.configure(
            min_rate_hz, max_rate_hz, tolerance, window, stamp_age_min_s, stamp_age_max_s
        )
        self._reset_ages()
        self._late = self._early = self._zero = 0

    def configure(
        self,
        min_rate_hz: float,
        max_rate_hz: float,
        tolerance: float,
        window: int,
        stamp_age_min_s: float,
        stamp_age_max_s: float,
    ) -> None:
        """
        Change the checks (the measurements so far are kept).

        Parameters
        ----------
        min_rate_hz, max_rate_hz, tolerance, window, stamp_age_min_s, stamp_age_max_s
            As the constructor's.

        """
        with self._lock:
            self._min, self._max, self._tol = (
                float(min_rate_hz),
                float(max_rate_hz),
                float(tolerance),
            )
            self._window = int(window)
            self._age_min, self._age_max = float(stamp_age_min_s), float(stamp_age_max_s)

    def _reset_ages(self) -> None:
        self._ages = 0
        self._earliest = self._latest = None
        self._zero_seen = False

    def tick(self, now_s: float, age_s: float, zero_stamp: bool = False) -> None:
        """
        Count one published message.

        Parameters
        ----------
        now_s : float
            Monotonic time of publication, s.
        age_s : float
            ``now - stamp`` on the node's clock, s.
        zero_stamp : bool, optional
            The message's stamp is zero.

        """
        with self._lock:
            self._count += 1
            self._ages += 1
            self._zero_seen |= bool(zero_stamp)
            if not zero_stamp:
                self._earliest = age_s if self._earliest is None else min(self._earliest, age_s)
                self._latest = age_s if self._latest is None else max(self._latest, age_s)

    def status(self, now_s: float) -> tuple[Level, str, dict]:
        """
        One diagnostics update: the level, message and values; the stamp ages start over.

        Parameters
        ----------
        now_s : float
            Monotonic time, s.

        Returns
        -------
        tuple
            (Level, message, values).

        """
        with self._lock:
            self._history.append((now_s, self._count))
            while len(self._history) > self._window + 1:
                self._history.popleft()
            t0, n0 = self._history[0]
            events, span = self._count - n0, now_s - t0
            rate = events / span if span > 0 else 0.0
            parts = []
            if events == 0:
                parts.append((Level.ERROR, 'No events recorded.'))
            elif rate < self._min * (1 - self._tol):
                parts.append((Level.WARN, 'Frequency too low.'))
            elif self._max > 0 and rate > self._max * (1 + self._tol):
                parts.append((Level.WARN, 'Frequency too high.'))
            values = {
                'Events in window': events,
                'Events since startup': self._count,
                'Duration of window (s)': f'{span:.6f}',
                'Actual frequency (Hz)': f'{rate:.6f}',
                'Minimum acceptable frequency (Hz)': f'{self._min * (1 - self._tol):.6f}',
                'Maximum acceptable frequency (Hz)': (
                    f'{self._max * (1 + self._tol):.6f}' if self._max > 0 else 'inf'
                ),
            }
            if self._ages == 0:
                parts.append((Level.WARN, 'No data since last update.'))
            else:
                if self._zero_seen:
                    self._zero += 1
                    parts.append((Level.ERROR, 'Zero timestamp seen.'))
                if self._earliest is not None and self._earliest < self._age_min:
                    self._early += 1
                    parts.append((Level.ERROR, 'Timestamps too far in future seen.'))
                if self._latest is not None and self._latest > self._age_max:
                    self._late += 1
                    parts.append((Level.ERROR, 'Timestamps too far in the past seen.'))
            values.update(
                {
                    'Earliest timestamp delay': _seconds(self._earliest),
                    'Latest timestamp delay': _seconds(self._latest),
                    'Earliest acceptable timestamp delay': f'{self._age_min:.6f}',
                    'Latest acceptable timestamp delay': f'{self._age_max:.6f}',
                    'Late diagnostic update count': self._late,
                    'Early diagnostic update count': self._early,
                    'Zero seen diagnostic update count': self._zero,
                }
            )
            self._reset_ages()
        if not parts:
            return Level.OK, 'Desired frequency met; Timestamps are reasonable.', values
        level = max(lv for lv, _ in parts)
        return level, '; '.join(text for _, text in parts), values


def _seconds(v) -> str:
    return 'nan' if v is None else f'{v:.6f}'
