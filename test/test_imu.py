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
ImuBuffer: ordering, duplicates, clock steps, gaps, rejection, coverage.

Interval integration.
"""
from iemd_ros.gyro.imu import Coverage, ImuBuffer, SampleStatus
from iemd_ros.gyro.rotation import (
    GyroCalibration,
    integrate_rates,
    quat_to_rot,
    rotation_angle,
    so3_exp,
)
import numpy as np
import pytest

MS = 1_000_000
T0 = 5_000_000_000          # an arbitrary clock origin (ns)


def angle_between(Ra, Rb):
    return float(rotation_angle(Ra.T @ Rb))


def rate_fn(t_s):
    """Return a smooth, axis-turning test rate (rad/s)."""
    t = np.asarray(t_s, float)
    return np.stack([2.0 * np.sin(7 * t), 3.0 * np.cos(5 * t), 1.0 + 0.5 * t], -1)


def reference(t0_s, t1_s):
    tk = np.linspace(t0_s, t1_s, 4001)
    return quat_to_rot(integrate_rates(tk, rate_fn(tk)))


def filled(rate_hz=200.0, dur_s=2.0):
    t = np.arange(0, dur_s, 1 / rate_hz)
    buf = ImuBuffer()
    buf.add(T0 + np.round(t * 1e9).astype(np.int64), rate_fn(t))
    return buf


def test_constant_rate_window_with_partial_samples_at_both_ends():
    """Window boundaries fall between samples: the ends are interpolated, giving exactly w * T."""
    w = np.array([0.5, -4.0, 1.2])
    buf = ImuBuffer()
    t = T0 + np.arange(0, 100) * 10 * MS                       # 100 Hz
    buf.add(t, np.tile(w, (len(t), 1)))
    res = buf.integrate(T0 + 13 * MS, T0 + 46 * MS + 300_000)  # 33.3 ms, not on the sample grid
    assert res.status is Coverage.OK and res.ok
    assert res.n_samples == 5                                  # 10, 20, 30, 40 and 50 ms
    np.testing.assert_allclose(res.R, so3_exp(w * 0.0333), atol=1e-12)


def test_imu_slower_than_the_camera():
    """
    11 Hz gyro, 30 fps frames.

    A window with no sample inside uses the two bracketing samples.
    """
    w = np.array([0.0, np.radians(257.0), 0.0])
    t = T0 + np.round(np.arange(0, 12) / 11 * 1e9).astype(np.int64)
    buf = ImuBuffer(max_gap_ns=100 * MS)
    buf.add(t, np.tile(w, (len(t), 1)))
    # between the samples at 90.9 and 181.8 ms
    res = buf.integrate(T0 + 100 * MS, T0 + 133 * MS)
    assert res.ok and res.n_samples == 2
    np.testing.assert_allclose(res.R, so3_exp(w * 0.033), atol=1e-12)


def test_interval_integration_matches_fine_reference():
    buf = filled(200.0)
    for a, b in [(0.1031, 0.1364), (0.5, 0.5333), (1.2017, 1.3)]:
        res = buf.integrate(T0 + int(a * 1e9), T0 + int(b * 1e9))
        # the only error is the piecewise-linear model of a smooth rate sampled at 200 Hz
        assert angle_between(res.R, reference(a, b)) < 2e-5


def test_out_of_order_and_duplicate_samples_give_the_sorted_result():
    t = np.arange(0, 1.0, 0.005)
    t_ns = T0 + np.round(t * 1e9).astype(np.int64)
    w = rate_fn(t)
    clean = ImuBuffer()
    clean.add(t_ns, w)
    rng = np.random.default_rng(0)
    order = rng.permutation(len(t))
    messy = ImuBuffer()
    for i in order:                                   # one by one, shuffled
        messy.add(int(t_ns[i]), w[i])
    dup = rng.choice(len(t), 15, replace=False)
    messy.add(t_ns[dup], w[dup])                      # exact repeats
    st = messy.stats()
    assert st['duplicates'] == 15 and st['stored'] == len(t)
    assert st['out_of_order'] > 50
    a = clean.integrate(T0 + 200 * MS, T0 + 233 * MS)
    b = messy.integrate(T0 + 200 * MS, T0 + 233 * MS)
    np.testing.assert_allclose(a.R, b.R, atol=1e-14)


def test_equal_stamps_with_different_values_are_averaged():
    buf = ImuBuffer()
    buf.add(
        [T0, T0 + 10 * MS, T0 + 10 * MS, T0 + 20 * MS],
        [[0, 0, 0], [1, 0, 0], [3, 0, 0], [2, 0, 0]],
    )
    t, w = buf.samples()
    assert list(t - T0) == [0, 10 * MS, 20 * MS]
    np.testing.assert_allclose(w[1], [2, 0, 0])
    assert buf.stats()['duplicates'] == 1


def test_later_batches_reaching_back_into_the_store_or_appended():
    """
    Samples merged after the store.

    Sorted in (equal stamps weighted by what each entry holds).
    """
    buf = ImuBuffer()
    buf.add(
        T0 + np.array([0, 10, 10, 20, 30]) * MS,
        [[0, 0, 0], [1, 0, 0], [3, 0, 0], [2, 0, 0], [4, 0, 0]],
    )
    # stored: 10 ms holds the mean 2 of 2 samples
    assert len(buf) == 4
    buf.add(
        T0 + np.array([25, 10, 40, 5, 25]) * MS,
        [[6, 0, 0], [5, 0, 0], [8, 0, 0], [1, 0, 0], [2, 0, 0]],
    )
    assert len(buf) == 7  # reaching back: 5, 10 and 25 ms
    # appended
    buf.add(T0 + np.array([60, 50, 55, 50]) * MS, [[9, 0, 0], [7, 0, 0], [1, 0, 0], [3, 0, 0]])
    t, w = buf.samples()
    assert list((t - T0) // MS) == [0, 5, 10, 20, 25, 30, 40, 50, 55, 60]
    # 10 ms: (2 * 2 + 5) / 3
    np.testing.assert_array_equal(w[:, 0], [0, 1, 3, 2, 4, 4, 8, 5, 1, 9])
    st = buf.stats()
    assert (st['duplicates'], st['out_of_order'], st['stored']) == (4, 7, 10)


def test_arrivals_on_the_first_or_last_stored_stamp_are_merged_into_it():
    buf = ImuBuffer()
    buf.add(T0 + np.array([0, 10, 20]) * MS, [[1, 0, 0], [2, 0, 0], [3, 0, 0]])
    assert len(buf) == 3
    # on the newest stored stamp
    buf.add(T0 + np.array([20, 30]) * MS, [[5, 0, 0], [7, 0, 0]])
    assert len(buf) == 4
    # on the oldest, twice
    buf.add(T0 + np.array([15, 0, 0]) * MS, [[4, 0, 0], [2, 0, 0], [6, 0, 0]])
    t, w = buf.samples()
    assert list((t - T0) // MS) == [0, 10, 15, 20, 30]
    np.testing.assert_array_equal(w[:, 0], [3, 2, 4, 4, 7])
    st = buf.stats()
    assert (st['duplicates'], st['out_of_order'], st['stored']) == (3, 3, 5)


def test_clock_stepping_back_like_the_cmu_desk_log():
    """
    Rows 77139, 77169, 77159, 77169.

    77179 ms (the desk pattern) are put in order and counted.
    """
    t_ms = np.array([77119, 77129, 77139, 77169, 77159, 77169, 77179, 77189])
    w = rate_fn((t_ms - 77119) / 1000.0)
    buf = ImuBuffer()
    for ti, wi in zip(t_ms, w):
        buf.add(int(ti) * MS, wi)
    st = buf.stats()
    assert st['out_of_order'] == 1 and st['duplicates'] == 1 and st['stored'] == 7
    ts, _ = buf.samples()
    assert np.all(np.diff(ts) > 0)
    res = buf.integrate(77125 * MS, 77185 * MS)
    assert res.ok and res.n_samples == 7


def test_frame_before_imu_coverage_then_covered():
    buf = ImuBuffer()
    assert buf.integrate(T0, T0 + 33 * MS).status is Coverage.NO_DATA
    t = T0 + np.arange(0, 30) * 5 * MS  # up to T0 + 145 ms
    buf.add(t, rate_fn((t - T0) * 1e-9))
    assert not buf.covers(T0 + 150 * MS)
    res = buf.integrate(T0 + 117 * MS, T0 + 150 * MS)
    assert res.status is Coverage.NOT_COVERED and not res.covered
    assert '5.0 ms before' in res.reason
    np.testing.assert_array_equal(res.R, np.eye(3))
    buf.add(T0 + 150 * MS, rate_fn(0.150))
    assert buf.covers(T0 + 150 * MS)
    assert buf.integrate(T0 + 117 * MS, T0 + 150 * MS).ok
    early = buf.integrate(T0 - 10 * MS, T0 + 20 * MS)
    assert (
        early.status is Coverage.START_NOT_COVERED
        and '10.0 ms before the first gyro sample' in early.reason
    )


def test_gap_is_reported():
    buf = ImuBuffer(max_gap_ns=30 * MS)
    # 80 ms hole (90 -> 170 ms)
    t = np.r_[np.arange(0, 100, 10), np.arange(170, 300, 10)] * MS + T0
    buf.add(t, np.tile([0.0, 1.0, 0.0], (len(t), 1)))
    res = buf.integrate(T0 + 80 * MS, T0 + 200 * MS)
    assert res.status is Coverage.GAP and res.covered and not res.ok
    assert res.max_gap_ns == 80 * MS and 'gap of 80.0 ms' in res.reason
    # rate interpolated across
    np.testing.assert_allclose(res.R, so3_exp([0, 0.12, 0]), atol=1e-12)
    assert buf.gaps() == [(T0 + 90 * MS, T0 + 170 * MS)]
    assert buf.integrate(T0 + 200 * MS, T0 + 250 * MS).ok


def test_nan_and_saturated_samples_are_rejected_and_counted():
    buf = ImuBuffer(saturation=np.radians(200))
    t = T0 + np.arange(10) * 10 * MS
    w = np.tile([0.0, 1.0, 0.0], (10, 1))
    w[3] = [np.nan, 1.0, 0.0]
    w[5] = [0.0, np.inf, 0.0]
    w[7] = [0.0, np.radians(205), 0.0]
    A, N, S = SampleStatus.ACCEPTED, SampleStatus.NOT_FINITE, SampleStatus.SATURATED
    assert buf.add(t, w).tolist() == [A, A, A, N, A, N, A, S, A, A]
    st = buf.stats()
    assert (st['nan'], st['saturated'], st['accepted'], st['stored']) == (2, 1, 7, 7)
    res = buf.integrate(T0, T0 + 90 * MS)
    np.testing.assert_allclose(res.R, so3_exp([0, 0.09, 0]), atol=1e-12)


def test_bounded_memory_and_too_old_windows():
    buf = ImuBuffer(max_duration_ns=1_000 * MS, max_samples=150)
    for i in range(2000):  # 10 s at 200 Hz, one at a time
        buf.add(T0 + i * 5 * MS, [0.0, 0.0, 1.0])
    assert len(buf) <= 150
    assert buf.stats()['dropped'] >= 1850
    res = buf.integrate(T0, T0 + 33 * MS)
    assert res.status is Coverage.START_NOT_COVERED and 'dropped' in res.reason


def test_late_samples_are_counted():
    buf = filled(100.0, 1.0)
    buf.integrate(T0 + 100 * MS, T0 + 200 * MS)
    buf.add(T0 + 150 * MS + 1, [0.0, 0.0, 0.0])
    assert buf.stats()['late'] == 1


def test_extrinsic_and_bias_are_applied():
    """w_cam = R_cam_imu (w_imu - b): integrating raw IMU samples gives the camera rotation."""
    R_ci = so3_exp([0.3, -1.1, 2.0])
    b = np.array([0.02, -0.03, 0.01])
    t = np.arange(0, 1.0, 0.005)
    w_cam = rate_fn(t)
    buf = ImuBuffer()
    buf.add(T0 + np.round(t * 1e9).astype(np.int64), w_cam @ R_ci + b)
    res = buf.integrate(T0 + 300 * MS, T0 + 333 * MS, GyroCalibration(R_ci, b))
    assert angle_between(res.R, reference(0.3, 0.333)) < 1e-5
    wrong = buf.integrate(T0 + 300 * MS, T0 + 333 * MS)  # no extrinsic, no bias
    assert angle_between(wrong.R, reference(0.3, 0.333)) > 0.05


def test_bad_input_raises():
    buf = ImuBuffer()
    with pytest.raises(ValueError, match='shapes'):
        buf.add([1, 2], [[0, 0, 0]])
    with pytest.raises(ValueError, match='integer'):
        buf.add(1.5, [0, 0, 0])
    with pytest.raises(ValueError, match='ends before'):
        buf.integrate(10, 5)
    with pytest.raises(ValueError):
        ImuBuffer(saturation=-1.0)


def test_real_desk_log_step_backs(imu_root):
    from iemd_ros.datasets.recordings import load_recording

    rec = load_recording(imu_root / 'cmu_hwangbo_desk')
    buf = ImuBuffer(max_duration_ns=10**12)
    buf.add(rec.imu_t_ns, rec.gyro)
    st = buf.stats()
    assert st['out_of_order'] == 3 and st['duplicates'] == 3
    order = np.argsort(rec.imu_t_ns, kind='stable')
    ref = ImuBuffer(max_duration_ns=10**12)
    ref.add(rec.imu_t_ns[order], rec.gyro[order])
    ti = rec.frame_imu_ns
    for k in range(0, len(ti) - 1, 37):
        np.testing.assert_allclose(
            buf.integrate(ti[k], ti[k + 1]).R, ref.integrate(ti[k], ti[k + 1]).R, atol=1e-14
        )


def _messy_stream(n=3000, seed=7):
    """
    Stamps and rates with every case the screening handles.

    NaN/inf, saturated, exact repeats, equal stamps with other values, small and large steps back.
    """
    rng = np.random.default_rng(seed)
    t = T0 + np.cumsum(rng.integers(1, 10, n)) * MS
    back = rng.random(n) < 0.05
    t[back] -= rng.integers(1, 50, back.sum()) * MS
    w = rng.normal(0.0, 2.0, (n, 3))
    rep = np.flatnonzero(rng.random(n) < 0.03)
    rep = rep[rep > 0]
    t[rep] = t[rep - 1]
    # half exact repeats, half other values
    w[rep[::2]] = w[rep[::2] - 1]
    w[rng.random(n) < 0.02, rng.integers(0, 3)] = np.nan
    w[rng.random(n) < 0.01, rng.integers(0, 3)] = -np.inf
    w[rng.random(n) < 0.02, 1] = 7.5  # at or over the limit of 6 rad/s
    w[rng.random(n) < 0.01, 2] = -6.0
    return t, w


def test_one_sample_at_a_time_matches_one_batch():
    """Statuses, counters, stored samples and newest stamp do not depend on the stream's cuts."""
    t, w = _messy_stream()
    half = len(t) // 2
    # arrives after the window below: late
    t[half + 2] = t[half - 5]

    def feed(cuts):
        buf = ImuBuffer(max_duration_ns=2_000 * MS, saturation=6.0)
        status = []
        for a, b in zip(cuts[:-1], cuts[1:]):
            # a frame integrated mid-stream: later samples before its end are late
            if a == half:
                buf.integrate(buf.t_newest_ns - 40 * MS, buf.t_newest_ns)
            if b - a == 1:  # what the node passes: an int stamp and a rate triple
                status.append(buf.add(int(t[a]), tuple(float(x) for x in w[a])))
            else:
                status.append(buf.add(t[a:b], w[a:b]))
        return buf, np.concatenate(status)

    rng = np.random.default_rng(1)
    chunks = np.unique(np.r_[0, half, rng.integers(0, len(t), 40), len(t)])
    runs = [feed([0, half, len(t)]), feed(list(range(len(t) + 1))), feed(list(chunks))]
    (ref, ref_status), others = runs[0], runs[1:]
    st = ref.stats()
    assert (
        min(st[k] for k in ('nan', 'saturated', 'duplicates', 'out_of_order', 'late', 'dropped'))
        > 0
    )
    assert np.array_equal(
        ref_status == SampleStatus.ACCEPTED, np.isfinite(w).all(1) & (np.abs(w) < 6.0).all(1)
    )
    t_ref, w_ref = ref.samples()
    for buf, status in others:
        np.testing.assert_array_equal(status, ref_status)
        assert status.dtype == ref_status.dtype
        assert buf.stats() == st and buf.t_newest_ns == ref.t_newest_ns
        t_got, w_got = buf.samples()
        np.testing.assert_array_equal(t_got, t_ref)
        np.testing.assert_array_equal(w_got, w_ref)


def test_empty_and_all_rejected_batches_leave_the_stream_untouched():
    buf = ImuBuffer(saturation=1.0)
    assert buf.add(np.zeros(0, np.int64), np.zeros((0, 3))).tolist() == []
    assert buf.add([T0, T0 + MS], [[np.nan, 0, 0], [0, 2.0, 0]]).tolist() == [
        SampleStatus.NOT_FINITE,
        SampleStatus.SATURATED,
    ]
    assert buf.t_newest_ns is None and not buf.covers(0)
    assert buf.stats() == {
        'added': 2,
        'accepted': 0,
        'nan': 1,
        'saturated': 1,
        'duplicates': 0,
        'out_of_order': 0,
        'late': 0,
        'dropped': 0,
        'stored': 0,
    }


def test_samples_sharing_a_stamp_merge_without_overflowing():
    """
    Two finite rates near the float maximum at one stamp merge without overflowing.

    Found by test_fuzz: they were averaged through their sum, which overflowed to inf inside the
    buffer.
    """
    buf = ImuBuffer()
    buf.add(
        np.array([0, 0, 10]), np.array([[0.0, 0.0, 8e307], [0.0, 0.0, 1e308], [0.0, 0.0, 0.0]])
    )
    t, w = buf.samples()
    assert list(t) == [0, 10] and np.all(np.isfinite(w)) and w[0, 2] == pytest.approx(9e307)
