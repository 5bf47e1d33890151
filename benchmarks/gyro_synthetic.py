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
Accuracy of the gyro prediction alone (no tracker) on synthetic shaking sequences.

For every frame pair with the target visible, the exact target centre of frame k-1 is mapped by the
gyro prediction (lens-aware, ``K R^T K^-1``) and compared with the exact target centre of frame k.
The target is static in the scene, so a perfect prediction has zero error.  Desk-like camera:
640x480, f = 570 px; 300 frames at 30 fps; shaking with a peak rate of 200 deg/s.  Realistic gyro:
white noise 0.01 rad/s per sample, stamp jitter 0.5 ms, bias (0.02, -0.015, 0.01) rad/s, 5 ms
camera-IMU offset, IMU mounted rotated (signed axis permutation).

    PYTHONPATH=. .venv/bin/python benchmarks/gyro_synthetic.py [--rate 200] [--frames 300]
"""
from __future__ import annotations

import argparse
import sys

from iemd_ros.datasets.synthetic import generate, SyntheticConfig
from iemd_ros.gyro import GyroConfig, GyroPredictor
from iemd_ros.gyro.predictor import warp_points
import numpy as np

# IMU axes: a proper signed permutation
R_CI = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])
BIAS = (0.02, -0.015, 0.01)
DESK_D = (-0.346217, 0.128289, 0.0, 0.0, 0.0)


def errors(seq, cfg: GyroConfig | None, lens_aware: bool = True) -> np.ndarray:
    """
    Return the prediction's centre errors, px.

    ``cfg=None`` means no prediction (previous position).
    """
    pred = None if cfg is None else GyroPredictor(seq.camera, cfg)
    fed = 0
    out = []
    for k in range(1, len(seq.frame_stamps_ns)):
        if pred is not None:     # stream the gyro: everything stamped up to 20 ms past this frame
            upto = int(
                np.searchsorted(
                    seq.gyro_t_ns, pred.imu_time(seq.frame_stamps_ns[k]) + 20_000_000, 'right'
                )
            )
            if upto > fed:
                pred.add_imu(seq.gyro_t_ns[fed:upto], seq.gyro[fed:upto])
                fed = upto
        if not (seq.visible[k - 1] and seq.visible[k]):
            continue
        c = seq.gt_centres[k - 1]
        if pred is None:
            p = c
        else:
            r = pred.predict(seq.frame_stamps_ns[k - 1], seq.frame_stamps_ns[k])
            if not r.ok:
                raise RuntimeError(r.reason)
            p = warp_points(c, r.H, seq.camera if lens_aware else None)
        out.append(np.hypot(*(p - seq.gt_centres[k])))
    return np.array(out)


def row(label: str, e: np.ndarray) -> None:
    print(
        f'  {label:75s} {e.mean():8.3f} {np.percentile(e, 95):8.3f} {e.max():8.3f}   ({len(e)} '
        'pairs)'
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--rate', type=float, default=200.0, help='peak angular rate, deg/s')
    ap.add_argument('--frames', type=int, default=300)
    ap.add_argument('--seed', type=int, default=11)
    args = ap.parse_args(argv)
    if not args.rate > 0 or args.frames < 2:
        print('error: need --rate > 0 and --frames >= 2', file=sys.stderr)
        return 2
    base = SyntheticConfig(
        width=640,
        height=480,
        hfov_deg=58.6,
        n_frames=args.frames,
        max_rate_deg_s=args.rate,
        render=False,
        seed=args.seed,
        still_start_s=1.0,
    )
    clean = generate(base)
    real = generate(
        base,
        gyro_noise_std=0.01,
        gyro_jitter_s=0.0005,
        gyro_bias=BIAS,
        time_offset_s=0.005,
        R_cam_imu=R_CI,
    )
    real100 = generate(
        base,
        gyro_noise_std=0.01,
        gyro_jitter_s=0.0005,
        gyro_bias=BIAS,
        time_offset_s=0.005,
        R_cam_imu=R_CI,
        gyro_rate_hz=100.0,
    )
    lens = generate(
        base,
        dist=DESK_D,
        gyro_noise_std=0.01,
        gyro_jitter_s=0.0005,
        gyro_bias=BIAS,
        time_offset_s=0.005,
        R_cam_imu=R_CI,
    )
    off = real.time_offset_ns
    print(
        f'synthetic shaking, peak {args.rate:.0f} deg/s, 640x480 f=570, {args.frames} frames at '
        '30 fps, static target'
    )
    print(f'  {"centre error of the prediction (px)":75s} {"mean":>8s} {"p95":>8s} {"max":>8s}')
    row('no prediction (target displacement between frames)', errors(clean, None))
    row('noise-free gyro 200 Hz', errors(clean, GyroConfig()))
    row(
        'noise-free gyro 200 Hz, trapezoid exp without the coning term',
        errors(clean, GyroConfig(coning=False)),
    )
    row(
        'realistic 200 Hz, all compensated (bias from 1 s still start)',
        errors(real, GyroConfig(time_offset_ns=off, R_cam_imu=R_CI, still_bias_samples=150)),
    )
    row(
        'realistic 200 Hz, bias NOT compensated',
        errors(real, GyroConfig(time_offset_ns=off, R_cam_imu=R_CI)),
    )
    row(
        'realistic 200 Hz, 5 ms time offset NOT compensated',
        errors(real, GyroConfig(time_offset_ns=0, R_cam_imu=R_CI, still_bias_samples=150)),
    )
    row(
        'realistic 100 Hz, all compensated',
        errors(real100, GyroConfig(time_offset_ns=off, R_cam_imu=R_CI, still_bias_samples=75)),
    )
    row(
        'realistic 200 Hz + lens k1=-0.35 (desk), lens-aware prediction',
        errors(lens, GyroConfig(time_offset_ns=off, R_cam_imu=R_CI, still_bias_samples=150)),
    )
    row(
        'realistic 200 Hz + lens k1=-0.35, H applied to raw pixels (lens ignored)',
        errors(
            lens,
            GyroConfig(time_offset_ns=off, R_cam_imu=R_CI, still_bias_samples=150),
            lens_aware=False,
        ),
    )
    return 0


if __name__ == '__main__':
    sys.exit(main())
