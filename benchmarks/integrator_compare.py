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
Exact gyro integration vs the paper's first-order quaternion step (eq.

21), in degrees.

1. Constant rate (closed form ``exp(w T)``): the error of one frame (33.3 ms) at 100 Hz and at 11
   Hz (the paper's gyro rate; one step per frame, and one step over a whole 11 Hz sample period).
2. Synthetic shaking (peak 257 deg/s, analytic truth): per-frame rotation error of both integrators
   from the gyro sampled at 200 / 100 / 11 Hz.  The paper's step holds each sample's rate until
   the next sample (zero-order hold, as a sampled gyro gives it); ours interpolates it linearly.
3. CMU desk (real gyro, 100 Hz): per-frame difference between the two integrators.

Pixel equivalents use f = 570 px (the desk camera).

    PYTHONPATH=. .venv/bin/python benchmarks/integrator_compare.py [--imu-root ../shared/data/imu]
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys

from iemd_ros.datasets.synthetic import angular_velocity, SyntheticConfig
from iemd_ros.gyro.rotation import (
    integrate_first_order,
    integrate_rates,
    quat_to_rot,
    rotation_angle,
    so3_exp,
)
import numpy as np

F_PX = 570.0
DEFAULT_ROOT = Path(__file__).resolve().parents[1].parent / 'shared' / 'data' / 'imu'


def knots(t_samples: np.ndarray, t0: float, t1: float) -> np.ndarray:
    inner = t_samples[(t_samples > t0) & (t_samples < t1)]
    return np.concatenate([[t0], inner, [t1]])


def both(t_s: np.ndarray, w_s: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray]:
    """(exact, first-order) rotation over [t0, t1] from samples (t_s, w_s): linear vs held rate."""
    tk = knots(t_s, t0, t1)
    lin = np.stack([np.interp(tk, t_s, w_s[:, j]) for j in range(3)], 1)
    held = w_s[np.clip(np.searchsorted(t_s, tk, 'right') - 1, 0, len(t_s) - 1)]
    return quat_to_rot(integrate_rates(tk, lin)), quat_to_rot(integrate_first_order(tk, held))


def err_deg(Ra, Rb) -> np.ndarray:
    return np.degrees(rotation_angle(np.swapaxes(Ra, -1, -2) @ Rb))


def constant_rate(rate_dps: float) -> None:
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    w = np.radians(rate_dps) * axis
    print(f'1. constant rate {rate_dps:.0f} deg/s (closed form exp(w T)):')
    for label, T, hz in [('one frame 33.3 ms, gyro 100 Hz', 1 / 30, 100.0),
                         ('one frame 33.3 ms, gyro 11 Hz (one step)', 1 / 30, 11.0),
                         ('one 11 Hz sample period, 90.9 ms', 1 / 11, 11.0)]:
        t_s = np.arange(-1.0, 1.0, 1 / hz)
        w_s = np.tile(w, (len(t_s), 1))
        R_true = so3_exp(w * T)
        Re, Rp = both(t_s, w_s, 0.0, T)
        print(
            f'   {label:42s} rotation {np.degrees(rotation_angle(R_true)):6.3f} deg | exact error '
            f'{err_deg(R_true, Re):.1e} deg | paper first-order error {err_deg(R_true, Rp):.4f} '
            'deg '
            f'({np.radians(err_deg(R_true, Rp)) * F_PX:.2f} px)'
        )


def shaking(peak_dps: float, n_frames: int = 300) -> None:
    cfg = SyntheticConfig(motion='shake', max_rate_deg_s=peak_dps, n_frames=n_frames, seed=3)
    tf = np.arange(n_frames) / cfg.fps
    # analytic truth per frame interval (fine 4th-order Magnus)
    R_true = np.array(
        [
            quat_to_rot(
                integrate_rates(
                    np.linspace(a, b, 200), angular_velocity(cfg, np.linspace(a, b, 200))
                )
            )
            for a, b in zip(tf[:-1], tf[1:])
        ]
    )
    ang = np.degrees(rotation_angle(R_true))
    print(
        f'2. synthetic shaking, peak {peak_dps:.0f} deg/s, {n_frames - 1} frame pairs at 30 fps '
        f'(rotation per frame mean {ang.mean():.2f}, max {ang.max():.2f} deg); error vs truth, '
        'deg:'
    )
    print(
        f'   {"gyro rate":>9s} | {"exact (linear rate)":>26s} | '
        f'{"paper first-order (held rate)":>30s}'
    )
    for hz in (200.0, 100.0, 11.0):
        t_s = np.arange(-0.5, tf[-1] + 0.5, 1 / hz)
        w_s = angular_velocity(cfg, t_s)
        pairs = [both(t_s, w_s, a, b) for a, b in zip(tf[:-1], tf[1:])]
        ee = err_deg(R_true, np.array([p[0] for p in pairs]))
        ep = err_deg(R_true, np.array([p[1] for p in pairs]))
        print(
            f'   {hz:7.0f} Hz | mean {ee.mean():.4f}  max {ee.max():.4f} | mean {ep.mean():.4f}  '
            f'max {ep.max():.4f}'
            f'   (max {np.radians(ep.max()) * F_PX:.1f} px vs {np.radians(ee.max()) * F_PX:.2f} '
            'px)'
        )


def desk(root: Path) -> None:
    from iemd_ros.datasets.recordings import load_recording

    rec = load_recording(root / 'cmu_hwangbo_desk')
    t, w = rec.gyro_predictor().buffer.samples()  # the whole record, sorted, repeats merged
    t_s = (t - t[0]) * 1e-9
    tf = (rec.frame_imu_ns - t[0]) * 1e-9
    pairs = [both(t_s, w, a, b) for a, b in zip(tf[:-1], tf[1:])]
    d = err_deg(np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs]))
    ang = np.degrees(rotation_angle(np.array([p[0] for p in pairs])))
    fast = ang >= np.percentile(ang, 90)
    print(
        f'3. CMU desk, real 100 Hz gyro, {len(d)} frame pairs: |exact - first-order| mean '
        f'{d.mean():.3f}, '
        f'p90 {np.percentile(d, 90):.3f}, max {d.max():.3f} deg (max '
        f'{np.radians(d.max()) * F_PX:.1f} px); '
        f'fastest 10 % pairs mean {d[fast].mean():.3f} deg'
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--imu-root', type=Path, default=DEFAULT_ROOT)
    ap.add_argument('--rate', type=float, default=257.0, help='rate / peak rate in deg/s')
    args = ap.parse_args(argv)
    if not args.rate > 0:
        print(f'error: --rate must be > 0, got {args.rate}', file=sys.stderr)
        return 2
    constant_rate(args.rate)
    shaking(args.rate)
    if (args.imu_root / 'cmu_hwangbo_desk').is_dir():
        desk(args.imu_root)
    else:
        print(f'3. CMU desk skipped: {args.imu_root / "cmu_hwangbo_desk"} not found')
    return 0


if __name__ == '__main__':
    sys.exit(main())
