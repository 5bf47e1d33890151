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
Per-message cost of the IMU path, this checkout against a baseline revision, in the same run.

The baseline's ``iemd_ros`` is taken from git (``git archive REV iemd_ros``) into a temporary
folder and imported under another name (its numba kernels, the tracker's included, compile there on
every run: about 10 s before any timing), so both versions run in one process on the same inputs.
The calls are timed alternately (old, new, old, ...; the best of ``--repeats`` rounds each), so
load changes on a shared machine hit both alike.  Timed:

* ``ImuBuffer.add`` of one sample (int stamp, rate triple: one sensor_msgs/Imu), 200 Hz stamps;
* ``TrackingPipeline.add_imu`` of one sample (what the node and the replay call per Imu message);
* ``ImuBuffer.add`` of 20000 samples in one batch (recordings), per sample;
* ``quat_to_rot`` of one quaternion and ``ImuBuffer.integrate`` of one 33 ms frame window with a
  calibration (the per-frame gyro rotation, as ``GyroPredictor.rotation`` calls it).

Before timing, both versions are fed the same stream (NaN, saturated, repeated and out-of-order
samples) one message at a time and must agree on every status, counter and stored sample.

    PYTHONPATH=. .venv/bin/python benchmarks/imu_ingest.py [--baseline REV] [--repeats 7]
"""
from __future__ import annotations

import importlib
from io import BytesIO
import itertools
from pathlib import Path
import subprocess
import sys
import tarfile
import tempfile
import time

from iemd_ros.common.cli import cli_main, CliParser
import iemd_ros.gyro.imu
import iemd_ros.gyro.rotation
import iemd_ros.pipeline.pipeline
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
# the last commit before the one-pass IMU screening and quat_to_rot's single build
BASELINE = '8e58e6b'
MS = 1_000_000


def load_baseline(rev: str, folder: Path):
    """
    Return the ``imu``, ``pipeline`` and ``rotation`` modules of ``iemd_ros`` at ``rev``.

    As package ``iemd_baseline``.
    """
    tar = subprocess.run(
        ['git', '-C', str(ROOT), 'archive', rev, 'iemd_ros'], check=True, capture_output=True
    ).stdout
    with tarfile.open(fileobj=BytesIO(tar)) as archive:
        archive.extractall(folder, filter='data')
    (folder / 'iemd_ros').rename(folder / 'iemd_baseline')
    sys.path.insert(0, str(folder))
    return tuple(
        importlib.import_module(f'iemd_baseline.{m}') for m in ('imu', 'pipeline', 'rotation')
    )


def messy_stream(n: int = 4000, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """
    200 Hz-like stamps and rates with NaN/inf, saturated (|w_i| >= 6).

    Repeated and out-of-order samples.
    """
    rng = np.random.default_rng(seed)
    t = 10**12 + np.cumsum(rng.integers(1, 10, n)) * MS
    back = rng.random(n) < 0.05
    t[back] -= rng.integers(1, 50, back.sum()) * MS
    w = rng.normal(0.0, 2.0, (n, 3))
    w[rng.random(n) < 0.02, 0] = np.nan
    w[rng.random(n) < 0.02, 1] = 7.0
    rep = np.flatnonzero(rng.random(n) < 0.03)[1:]
    t[rep] = t[rep - 1]
    return t, w


def check_same(old_imu, new_imu) -> None:
    """
    Raise ValueError unless both versions give the same statuses, counters and samples.

    One message at a time.
    """
    t, w = messy_stream()
    runs = []
    for imu in (old_imu, new_imu):
        buf = imu.ImuBuffer(max_duration_ns=2_000 * MS, saturation=6.0)
        status = [int(buf.add(int(ti), tuple(wi))[0]) for ti, wi in zip(t, w)]
        ts, ws = buf.samples()
        runs.append((status, buf.stats(), ts.tolist(), ws.tobytes()))
    if runs[0] != runs[1]:
        raise ValueError('the baseline and this checkout disagree on the test stream')


def per_call_us(make_call, n: int) -> float:
    """
    Microseconds per call of ``make_call()`` (a fresh zero-argument callable).

    Over ``n`` calls.
    """
    call = make_call()
    start = time.perf_counter()
    for _ in range(n):
        call()
    return (time.perf_counter() - start) / n * 1e6


def one_sample_adds(add, period_ns: int = 5 * MS):
    """Return a callable adding the next 200 Hz sample with ``add(t_ns, (wx, wy, wz))``."""
    stamps = iter(range(10**12, 10**18, period_ns))
    rate = (0.01, -0.2, 0.3)
    return lambda: add(next(stamps), rate)


def cases(imu, pipeline, rotation) -> dict:
    """Return name -> (factory of a timed call, calls per round, samples per call), one version."""
    q = rotation.quat_normalize([0.9, 0.1, -0.2, 0.3])
    cal = rotation.GyroCalibration(
        np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]), [0.02, -0.015, 0.01]
    )
    filled = imu.ImuBuffer()
    t200 = 10**12 + np.arange(1000) * 5 * MS
    filled.add(t200, np.random.default_rng(1).normal(size=(1000, 3)))
    # 30 fps inside the 5 s held
    frame_ends = itertools.cycle(10**12 + np.arange(100, 4900, 33) * MS)
    t_batch = 10**12 + np.arange(20_000) * 5 * MS
    w_batch = np.random.default_rng(2).normal(size=(20_000, 3))

    def integrate():
        t1 = int(next(frame_ends))
        return filled.integrate(t1 - 33 * MS, t1, cal)

    return {
        'ImuBuffer.add, one sample': (lambda: one_sample_adds(imu.ImuBuffer().add), 20_000, 1),
        'TrackingPipeline.add_imu, one sample': (
            lambda: one_sample_adds(pipeline.TrackingPipeline().add_imu),
            20_000,
            1,
        ),
        'ImuBuffer.add, 20000 in one batch': (
            lambda: lambda: imu.ImuBuffer().add(t_batch, w_batch),
            20,
            20_000,
        ),
        'quat_to_rot, one quaternion': (lambda: lambda: rotation.quat_to_rot(q), 20_000, 1),
        'ImuBuffer.integrate, one frame': (lambda: integrate, 5_000, 1),
    }


def main(argv=None) -> int:
    return cli_main('imu_ingest', lambda: _main(argv))


def _main(argv) -> int:
    p = CliParser(prog='imu_ingest', description=__doc__.split('\n\n')[0])
    p.add_argument(
        '--baseline', default=BASELINE, help=f'git revision to compare with (default {BASELINE})'
    )
    p.add_argument(
        '--repeats', type=int, default=7, help='timed rounds per version and call (best kept)'
    )
    args = p.parse_args(argv)
    if args.repeats < 1:
        raise ValueError(f'--repeats must be >= 1, got {args.repeats}')
    with tempfile.TemporaryDirectory() as tmp:
        old = load_baseline(args.baseline, Path(tmp))
        new = (iemd_ros.gyro.imu, iemd_ros.pipeline.pipeline, iemd_ros.gyro.rotation)
        check_same(old[0], new[0])
        old_cases, new_cases = cases(*old), cases(*new)
        for (make, n, _), (make_new, _, _) in zip(old_cases.values(), new_cases.values()):
            per_call_us(make, 10), per_call_us(make_new, 10)  # warm-up (JIT, caches)
        print(
            f'per call, best of {args.repeats} alternating rounds; baseline {args.baseline}, new '
            '= this checkout'
        )
        print(f'{"call":<40} {"baseline us":>12} {"new us":>9} {"speed-up":>9}')
        for name, (make_old, n, per) in old_cases.items():
            make_new = new_cases[name][0]
            t_old, t_new = [], []
            for _ in range(args.repeats):
                t_old.append(per_call_us(make_old, n) / per)
                t_new.append(per_call_us(make_new, n) / per)
            unit = 'per sample' if per > 1 else ''
            print(
                f'{name:<40} {min(t_old):12.3f} {min(t_new):9.3f} {min(t_old) / min(t_new):8.1f}x '
                f'{unit}'
            )
    return 0


if __name__ == '__main__':
    sys.exit(main())
