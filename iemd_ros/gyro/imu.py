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
Time-ordered gyro buffer and frame-interval integration.

(paper: "Synchronization of the camera and the gyroscope in time is required", Section "Gyroscope
Data Fusion for Rotation Compensation").

This is the buffer-and-integrate scheme of VIO systems, never an approximate-time synchronizer:
every gyro sample is kept (bounded memory) in time order and, for frames ``k-1`` and ``k`` with
camera stamps ``t_{k-1}``, ``t_k``, the rate is integrated over
``[t_{k-1} + t_d, t_k + t_d]`` (``t_d``: camera-IMU offset, Kalibr's ``t_imu = t_cam + shift``),
interpolating the rate linearly at both ends.  A frame can be processed once a sample at or past
``t_k + t_d`` has arrived (:meth:`ImuBuffer.covers`); until then :meth:`ImuBuffer.integrate`
answers ``not_covered`` so the caller can wait a bounded time and then go on without gyro.

Stamps are integer nanoseconds (like ROS ``builtin_interfaces/Time``).  Real streams are handled:
samples out of order or with a clock stepping back are put in order; samples with the same stamp
are merged into their mean (exact repeats collapse); NaN/inf and saturated samples are rejected and
counted; gaps longer than ``max_gap_ns`` inside an integration window are reported.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum, IntEnum
import threading

from iemd_ros.gyro.rotation import GyroCalibration, magnus_product, quat_to_rot
import numba
import numpy as np

__all__ = ['Coverage', 'SampleStatus', 'ImuIntegration', 'ImuBuffer']

_MERGE_EVERY = 512


class Coverage(str, Enum):
    """Coverage status of an integration window by the buffered gyro samples."""

    OK = 'ok'
    GAP = 'gap'                              # covered, but with a gap > max_gap_ns inside
    NOT_COVERED = 'not_covered'              # no sample at/after the window end yet: wait or go on
    # no sample at/before the window start (startup/dropped)
    START_NOT_COVERED = 'start_not_covered'
    NO_DATA = 'no_data'                      # the buffer is empty


class SampleStatus(IntEnum):
    """What :meth:`ImuBuffer.add` did with a gyro sample (the one place samples are screened)."""

    ACCEPTED = 0
    NOT_FINITE = 1                           # NaN/inf rate: rejected
    SATURATED = 2                            # |w_i| >= saturation: rejected


# The statuses as plain ints for ImuBuffer.add and GyroPredictor.add_imu: numpy comparing an array
# with an IntEnum member probes the enum class for array attributes on every comparison.
ACCEPTED_STATUS, _NOT_FINITE, _SATURATED = (int(s) for s in SampleStatus)
# "no stamp yet" for the compiled screening: nothing is earlier
_NO_STAMP = np.iinfo(np.int64).min


@dataclass(frozen=True)
class ImuIntegration:
    """
    Result of integrating the gyro over one frame interval.

    Parameters
    ----------
    R : ndarray
        3x3 orientation at ``t1`` expressed in the frame at ``t0`` (identity unless covered).
    n_samples : int
        Buffered samples whose values entered the integral (the bracketing ones included).
    status : Coverage
        How the buffered samples cover the window.
    reason : str
        The status in words.
    t0_ns, t1_ns : int
        The window, IMU clock, ns.
    max_gap_ns : int, optional
        Largest spacing between the samples used.

    """

    R: np.ndarray
    n_samples: int
    status: Coverage
    reason: str
    t0_ns: int
    t1_ns: int
    max_gap_ns: int = 0

    @property
    def covered(self) -> bool:
        """Return True when ``R`` was integrated from data (status ``ok`` or ``gap``)."""
        return self.status in (Coverage.OK, Coverage.GAP)

    @property
    def ok(self) -> bool:
        """Return True when the window is covered without a gap (status ``ok``)."""
        return self.status is Coverage.OK


def _identity(t0, t1, status, reason, n=0, gap=0) -> ImuIntegration:
    return ImuIntegration(np.eye(3), n, status, reason, t0, t1, gap)


def _ms(ns) -> str:
    return f'{ns / 1e6:.1f} ms'


class ImuBuffer:
    """
    Bounded, time-ordered gyro buffer with interval integration.

    Parameters
    ----------
    max_duration_ns : int, optional
        Samples older than ``newest - max_duration_ns`` are dropped.
    max_samples : int, optional
        Hard cap on the number of stored samples (oldest dropped first), at least 2.
    saturation : float or None, optional
        Per-axis limit in rad/s on the raw rate; ``|w_i| >= saturation`` rejects a sample
        (``None``: no limit).
    max_gap_ns : int, optional
        Sample spacing above which an integration window is reported as ``gap``.

    Raises
    ------
    ValueError
        For invalid settings (:meth:`check_settings`).

    """

    def __init__(self, max_duration_ns: int = 10_000_000_000, max_samples: int = 20_000,
                 saturation: float | None = None, max_gap_ns: int = 50_000_000):
        self.check_settings(max_duration_ns, max_samples, saturation, max_gap_ns)
        self.max_duration_ns = int(max_duration_ns)
        self.max_samples = int(max_samples)
        self.saturation = None if saturation is None else float(saturation)
        self.max_gap_ns = int(max_gap_ns)
        self._lock = threading.Lock()
        self._t = np.zeros(0, dtype=np.int64)
        self._w = np.zeros((0, 3))
        self._n = np.zeros(0)                  # number of raw samples merged into each entry
        self._pend_t: list[np.ndarray] = []
        self._pend_w: list[np.ndarray] = []
        self._n_pend = 0
        self._t_max: int | None = None         # largest stamp ever accepted
        self._t_integrated: int | None = None  # largest window end integrated so far
        self.counts = {'added': 0, 'accepted': 0, 'nan': 0, 'saturated': 0, 'duplicates': 0,
                       'out_of_order': 0, 'late': 0, 'dropped': 0}

    @staticmethod
    def check_settings(max_duration_ns, max_samples, saturation, max_gap_ns) -> None:
        """
        Check the buffer's settings (see the class docstring).

        Parameters
        ----------
        max_duration_ns : int
            As the class takes it.
        max_samples : int
            As the class takes it.
        saturation : float or None
            As the class takes it.
        max_gap_ns : int
            As the class takes it.

        Raises
        ------
        ValueError
            Unless ``max_duration_ns > 0``, ``max_samples >= 2``, ``saturation`` is None or > 0,
            and ``max_gap_ns > 0``.

        """
        if int(max_duration_ns) <= 0 or int(max_samples) < 2:
            raise ValueError(
                'need max_duration_ns > 0 and max_samples >= 2, got '
                f'{max_duration_ns}, {max_samples}'
            )
        if saturation is not None and not saturation > 0:
            raise ValueError(f'saturation limit must be > 0 rad/s or None, got {saturation}')
        if int(max_gap_ns) <= 0:
            raise ValueError(f'max_gap_ns must be > 0, got {max_gap_ns}')

    # ------------------------------------------------------------------ input
    def add(self, t_ns, w) -> np.ndarray:
        """
        Add one gyro sample or many.

        NaN/inf and saturated samples are rejected and counted.  One sample and a batch take the
        same path: the screening and the order counts are one compiled pass (:func:`_screen`).

        Parameters
        ----------
        t_ns : int or array_like
            Stamp, or (N,) stamps, integer ns.
        w : array_like
            (3,) or (N, 3) raw rates in rad/s in the IMU frame.

        Returns
        -------
        ndarray
            (N,) :class:`SampleStatus` of the samples.

        Raises
        ------
        ValueError
            For shapes other than (N,) and (N, 3), or stamps that are not integer nanoseconds.

        """
        # copies: the caller may reuse its arrays
        t = np.array(t_ns, ndmin=1)
        w = np.array(w, dtype=float, order='C')
        if w.ndim == 1:
            w = w[None, :]
        if t.ndim != 1 or w.shape != (len(t), 3):
            raise ValueError(
                f'gyro samples need t_ns (N,) and w (N, 3), got shapes {t.shape} and {w.shape}'
            )
        if t.dtype.kind not in 'iu':
            if not np.all(np.isfinite(t.astype(float))) or np.any(t != np.round(t)):
                raise ValueError('gyro stamps must be integer nanoseconds')
        t = t.astype(np.int64, copy=False)
        status = np.empty(len(t), dtype=np.int8)
        saturation = np.inf if self.saturation is None else self.saturation
        with self._lock:
            t_max = _NO_STAMP if self._t_max is None else self._t_max
            t_integrated = _NO_STAMP if self._t_integrated is None else self._t_integrated
            nan, saturated, out_of_order, late, t_max = _screen(
                t, w, saturation, t_max, t_integrated, status
            )
            c = self.counts
            c['added'] += len(t)
            if nan or saturated:
                c['nan'] += nan
                c['saturated'] += saturated
                keep = status == ACCEPTED_STATUS
                t, w = t[keep], w[keep]
            if len(t) == 0:
                return status
            c['out_of_order'] += out_of_order
            c['late'] += late
            self._t_max = t_max
            c['accepted'] += len(t)
            self._pend_t.append(t)
            self._pend_w.append(w)
            self._n_pend += len(t)
            if self._n_pend >= _MERGE_EVERY:
                self._merge()
            return status

    def _merge(self) -> None:
        """
        Fold pending samples into the sorted store; merge equal stamps.

        Enforce the memory bound.
        """
        if not self._n_pend:
            return
        pt = np.concatenate(self._pend_t)
        pw = np.concatenate(self._pend_w)
        self._pend_t, self._pend_w, self._n_pend = [], [], 0
        t, w = np.concatenate([self._t, pt]), np.concatenate([self._w, pw])
        n = np.concatenate([self._n, np.ones(len(pt))])
        # the store (sorted, stamps unique) below the earliest arrival stays as it is: only the
        # tail from there is sorted, stably (the store first, arrivals in order) - usually just the
        # arrivals, appended - and only the tail can repeat a stamp (t[lo] > t[lo - 1])
        lo = int(np.searchsorted(self._t, pt.min(), 'left'))
        order = np.argsort(t[lo:], kind='stable')
        t[lo:], w[lo:], n[lo:] = t[lo:][order], w[lo:][order], n[lo:][order]
        tt = t[lo:]
        start = np.flatnonzero(np.concatenate([[True], tt[1:] != tt[:-1]]))  # first of each stamp
        if len(start) < len(tt):
            self.counts['duplicates'] += len(tt) - len(start)
            nn = np.add.reduceat(n[lo:], start)
            group = np.repeat(np.arange(len(start)), np.diff(np.append(start, len(tt))))
            # the weights of each stamp's mean sum to 1, so no finite rates add up to infinity
            wt = np.add.reduceat(w[lo:] * (n[lo:] / nn[group])[:, None], start, axis=0)
            t, w, n = (
                np.concatenate([t[:lo], tt[start]]),
                np.concatenate([w[:lo], wt]),
                np.concatenate([n[:lo], nn]),
            )
        keep_from = max(
            len(t) - self.max_samples, int(np.searchsorted(t, t[-1] - self.max_duration_ns))
        )
        self.counts['dropped'] += keep_from
        self._t, self._w, self._n = t[keep_from:], w[keep_from:], n[keep_from:]

    # ------------------------------------------------------------------ queries
    def __len__(self) -> int:
        with self._lock:
            self._merge()
            return len(self._t)

    @property
    def t_newest_ns(self) -> int | None:
        """Largest stamp ever accepted (None before the first sample)."""
        return self._t_max

    def covers(self, t_ns: int) -> bool:
        """
        Return True once a sample at or past ``t_ns`` has arrived.

        (a frame at ``t_ns`` can be integrated).

        Parameters
        ----------
        t_ns : int
            IMU clock, ns.

        Returns
        -------
        bool
            Whether the buffer covers ``t_ns``.

        """
        return self._t_max is not None and self._t_max >= int(t_ns)

    def samples(
        self, t0_ns: int | None = None, t1_ns: int | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """
        Copy of the stored (merged, sorted) samples with ``t0_ns <= t <= t1_ns``.

        Parameters
        ----------
        t0_ns, t1_ns : int, optional
            The window, IMU clock, ns (None: unbounded on that side).

        Returns
        -------
        t : ndarray
            (M,) int64 stamps.
        w : ndarray
            (M, 3) rates, rad/s.

        """
        with self._lock:
            self._merge()
            lo = 0 if t0_ns is None else int(np.searchsorted(self._t, int(t0_ns), 'left'))
            hi = (
                len(self._t)
                if t1_ns is None
                else int(np.searchsorted(self._t, int(t1_ns), 'right'))
            )
            return self._t[lo:hi].copy(), self._w[lo:hi].copy()

    def gaps(self, t0_ns: int | None = None, t1_ns: int | None = None) -> list[tuple[int, int]]:
        """
        Consecutive stored samples further apart than ``max_gap_ns``.

        Parameters
        ----------
        t0_ns, t1_ns : int, optional
            The window searched, as :meth:`samples` takes it.

        Returns
        -------
        list of tuple of int
            Pairs ``(t_before, t_after)``.

        """
        t, _ = self.samples(t0_ns, t1_ns)
        i = np.nonzero(np.diff(t) > self.max_gap_ns)[0]
        return [(int(t[j]), int(t[j + 1])) for j in i]

    def integrate(
        self,
        t0_ns: int,
        t1_ns: int,
        calibration: GyroCalibration | None = None,
        coning: bool = True,
    ) -> ImuIntegration:
        """
        Integrate the rate over ``[t0_ns, t1_ns]``.

        (IMU clock) into the rotation of ``t1`` in ``t0``.

        Rates are interpolated linearly at both ends, then integrated exactly by
        ``_window_rotation`` (one compiled pass through
        :func:`iemd_ros.gyro.rotation.magnus_product`, the core of
        :func:`iemd_ros.gyro.rotation.integrate_rates`: the same maths).

        Parameters
        ----------
        t0_ns, t1_ns : int
            The window, IMU clock, ns.
        calibration : GyroCalibration, optional
            With it the bias is removed and the rotation is expressed in the camera frame:
            ``R_cam = R_cam_imu R R_cam_imu^T``.
        coning : bool, optional
            Apply the coning correction.

        Returns
        -------
        ImuIntegration
            The rotation (identity unless covered), the window's coverage status and the reason.

        Raises
        ------
        ValueError
            When the window ends before it starts.

        """
        t0, t1 = int(t0_ns), int(t1_ns)
        if t1 < t0:
            raise ValueError(f'integration window ends before it starts: t0={t0} ns, t1={t1} ns')
        cal = calibration if calibration is not None else GyroCalibration()
        with self._lock:
            self._merge()
            t, w = self._t, self._w
            if len(t) == 0:
                return _identity(t0, t1, Coverage.NO_DATA, 'no gyro sample received yet')
            if t[-1] < t1:
                return _identity(
                    t0,
                    t1,
                    Coverage.NOT_COVERED,
                    f'gyro not covering the frame yet: newest sample is {_ms(t1 - t[-1])} '
                    f'before the window end',
                )
            if t[0] > t0:
                why = (
                    'the oldest buffered sample (older ones were dropped from the bounded buffer)'
                    if self.counts['dropped']
                    else 'the first gyro sample'
                )
                return _identity(
                    t0,
                    t1,
                    Coverage.START_NOT_COVERED,
                    f'window start is {_ms(t[0] - t0)} before {why}',
                )
            self._t_integrated = t1 if self._t_integrated is None else max(self._t_integrated, t1)
            i0 = int(np.searchsorted(t, t0, 'right')) - 1  # last sample <= t0
            i1 = int(np.searchsorted(t, t1, 'left'))  # first sample >= t1
            ts, ws = t[i0: i1 + 1], w[i0: i1 + 1] - cal.bias
        n_used = len(ts)
        max_gap = int(np.diff(ts).max()) if n_used > 1 else 0
        if t1 == t0:
            return _identity(t0, t1, Coverage.OK, 'empty window', n_used, max_gap)
        q_imu = _window_rotation((ts - t0).astype(float) * 1e-9, ws, (t1 - t0) * 1e-9, coning)
        R = cal.R_cam_imu @ quat_to_rot(q_imu) @ cal.R_cam_imu.T
        if max_gap > self.max_gap_ns:
            return ImuIntegration(
                R,
                n_used,
                Coverage.GAP,
                f'gyro gap of {_ms(max_gap)} (> {_ms(self.max_gap_ns)}) inside the window; '
                'rate interpolated across it',
                t0,
                t1,
                max_gap,
            )
        return ImuIntegration(R, n_used, Coverage.OK, f'{n_used} gyro samples', t0, t1, max_gap)

    def stats(self) -> dict:
        """
        Return the buffer's counters and size.

        Returns
        -------
        dict
            The counts added, accepted, nan, saturated, duplicates, out_of_order, late, dropped,
            and the size stored.

        """
        with self._lock:
            self._merge()
            return dict(self.counts, stored=len(self._t))


@numba.njit(cache=True)
def _window_rotation(rel, ws, t_end, coning):
    """
    Return the quaternion of :func:`iemd_ros.gyro.rotation.integrate_rates` over [0, t_end].

    The samples are at ``rel``.

    ``rel`` (s, strictly increasing) brackets the window: rel[0] <= 0 < t_end <= rel[-1], so it
    holds at least 2 samples (``integrate`` answers an empty window before calling).  The knots are
    0, the samples strictly inside and t_end, with the rate interpolated linearly at both ends (as
    ``np.interp``).  One compiled pass: for a handful of samples numpy's array overhead dominates.
    """
    knots = np.empty(rel.size + 2)
    rates = np.empty((rel.size + 2, 3))
    knots[0], rates[0] = 0.0, _interp_rate(rel, ws, 0.0)
    m = 1
    for i in range(rel.size):
        if 0.0 < rel[i] < t_end:
            knots[m], rates[m] = rel[i], ws[i]
            m += 1
    knots[m], rates[m] = t_end, _interp_rate(rel, ws, t_end)
    return magnus_product(knots[: m + 1], rates[: m + 1], coning)


@numba.njit(cache=True)
def _interp_rate(rel, ws, x):
    """
    Rate at ``x`` interpolated linearly in ``ws`` at ``rel`` (at least 2 samples).

    Clamped at the ends.
    """
    j = 0
    while j < rel.size - 2 and rel[j + 1] < x:
        j += 1
    f = min(max((x - rel[j]) / (rel[j + 1] - rel[j]), 0.0), 1.0)
    return ws[j] + f * (ws[j + 1] - ws[j])


@numba.njit(cache=True)
def _screen(t, w, saturation, t_max, t_integrated, status):
    """
    Screen gyro samples in arrival order: the one place each rule is applied.

    Writes each sample's :class:`SampleStatus` into ``status``: NaN/inf rates are rejected, then
    finite ones with ``|w_i| >= saturation`` (``inf``: no limit).  Counts, among the accepted ones,
    those earlier than a sample accepted before them (out of order, a clock stepping back included;
    ``t_max`` is the largest stamp accepted before this call) and those earlier than
    ``t_integrated`` (late: a window up to there was already integrated).  ``_NO_STAMP`` stands for
    "none yet".  Returns (nan, saturated, out_of_order, late, largest accepted stamp).
    """
    nan = saturated = out_of_order = late = 0
    for i in range(t.size):
        if not (np.isfinite(w[i, 0]) and np.isfinite(w[i, 1]) and np.isfinite(w[i, 2])):
            status[i] = _NOT_FINITE
            nan += 1
        elif (
            abs(w[i, 0]) >= saturation or abs(w[i, 1]) >= saturation or abs(w[i, 2]) >= saturation
        ):
            status[i] = _SATURATED
            saturated += 1
        else:
            status[i] = ACCEPTED_STATUS
            if t[i] < t_max:
                out_of_order += 1
            else:
                t_max = t[i]
            if t[i] < t_integrated:
                late += 1
    return nan, saturated, out_of_order, late, t_max
