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
Gyro pre-warp quality on the real recordings (direction of the homography, time offset).

For the fastest fraction of frame pairs (by integrated gyro rotation angle), frame k is warped by
the gyro prediction and compared with frame k+1: mean absolute grey-level difference over the
pixels valid in both (CMU images undistorted first, same K).  Compared in the same run:
no warp, ``K R^T K^-1`` (this package's direction) and ``K R K^-1`` (the opposite).  A scan of the
camera-IMU time offset around the recording's value is printed too.

    PYTHONPATH=. .venv/bin/python benchmarks/gyro_prewarp.py [--imu-root ../shared/data/imu]
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys

import cv2
from iemd_ros.datasets.recordings import load_recording
from iemd_ros.gyro.predictor import rotation_homography, warp_difference
from iemd_ros.gyro.rotation import rotation_angle
import numpy as np

DEFAULT_ROOT = Path(__file__).resolve().parents[1].parent / 'shared' / 'data' / 'imu'
SEQUENCES = {'desk': 'cmu_hwangbo_desk', 'aerial': 'cmu_hwangbo_aerial',
             'phone': 'phone_gyrostab_20200109_145447'}


def pair_rotations(rec, offset_ns: int) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (camera k+1 in camera k) of every consecutive frame pair, and a validity mask."""
    pred = rec.gyro_predictor(offset_ns)
    st = rec.frame_stamps_ns
    res = [pred.rotation(a, b) for a, b in zip(st[:-1], st[1:])]
    return np.array([r.R for r in res]), np.array([r.ok for r in res])


class PairScorer:
    """
    Mean absolute grey difference of warped frame k vs frame k+1.

    (undistorted, valid pixels only).
    """

    def __init__(self, rec):
        self.rec = rec
        cam = rec.camera
        self.maps = cam.undistort_maps() if cam.has_distortion else None
        ones = np.full((cam.height, cam.width), 255, np.uint8)
        self.valid = self._undistort(ones) == 255
        self._cache: dict[int, np.ndarray] = {}

    def _undistort(self, img):
        if self.maps is None:
            return img
        return cv2.remap(
            img, *self.maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0
        )

    def frame(self, i: int) -> np.ndarray:
        if i not in self._cache:
            self._cache[i] = self._undistort(self.rec.load_frame(i, grey=True))
        return self._cache[i]

    def score(self, k: int, H: np.ndarray) -> float:
        return warp_difference(self.frame(k), self.frame(k + 1), H, self.valid)


def run(name: str, root: Path, fraction: float, scan_ms: list[float]) -> None:
    rec = load_recording(root / SEQUENCES[name])
    R, ok = pair_rotations(rec, rec.time_offset_ns)
    ang = np.degrees(rotation_angle(R))
    ang_ok = np.where(ok, ang, -1.0)
    n_sel = max(1, int(round(fraction * ok.sum())))
    sel = np.argsort(-ang_ok, kind='stable')[:n_sel]
    scorer = PairScorer(rec)
    K = rec.camera.K
    rows = {'no warp': [], 'K R^T K^-1': [], 'K R K^-1': []}
    for k in sel:
        rows['no warp'].append(scorer.score(k, np.eye(3)))
        rows['K R^T K^-1'].append(scorer.score(k, rotation_homography(K, R[k])))
        rows['K R K^-1'].append(scorer.score(k, rotation_homography(K, R[k].T)))
    m = {key: float(np.mean(v)) for key, v in rows.items()}
    print(
        f'\n{name}: {len(rec)} frames, {ok.sum()}/{len(ok)} pairs covered by the gyro; fastest '
        f'{100 * fraction:.0f} % = {n_sel} pairs (rotation '
        f'{ang[sel].min():.2f}-{ang[sel].max():.2f} deg, '
        f'mean {ang[sel].mean():.2f}); '
        f'{"undistorted" if rec.camera.has_distortion else "no distortion"}; '
        f'time offset {rec.time_offset_ns / 1e6:+.0f} ms'
    )
    print(
        f'  mean |grey difference|   no warp {m["no warp"]:6.2f}   K R^T K^-1 '
        f'{m["K R^T K^-1"]:6.2f}   '
        f'K R K^-1 {m["K R K^-1"]:6.2f}'
    )
    print(
        '  ratio to no warp                          '
        f'{m["K R^T K^-1"] / m["no warp"]:6.3f}             '
        f'{m["K R K^-1"] / m["no warp"]:6.3f}'
    )
    better = np.mean(np.array(rows['K R^T K^-1']) < np.array(rows['K R K^-1']))
    print(f'  pairs where K R^T K^-1 beats K R K^-1: {100 * better:.0f} %')
    if scan_ms:
        out = []
        for d in scan_ms:
            Rd, okd = pair_rotations(rec, rec.time_offset_ns + int(round(d * 1e6)))
            s = [scorer.score(k, rotation_homography(K, Rd[k])) for k in sel if okd[k]]
            out.append(f'{rec.time_offset_ns / 1e6 + d:+.0f} ms: {np.mean(s):.2f}')
        print('  time-offset scan (K R^T K^-1):  ' + '   '.join(out))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--imu-root', type=Path, default=DEFAULT_ROOT, help='folder of the recordings')
    ap.add_argument(
        '--fraction', type=float, default=0.10, help='fastest fraction of frame pairs (0-1]'
    )
    ap.add_argument(
        '--sequences', nargs='+', default=['desk', 'aerial', 'phone'], choices=sorted(SEQUENCES)
    )
    ap.add_argument(
        '--scan-ms',
        type=float,
        nargs='*',
        default=[-20, -10, 0, 10, 20],
        help="time-offset deltas (ms) around the recording's offset; none to skip",
    )
    args = ap.parse_args(argv)
    if not 0 < args.fraction <= 1:
        print(f'error: --fraction must be in (0, 1], got {args.fraction}', file=sys.stderr)
        return 2
    if not args.imu_root.is_dir():
        print(f'error: recordings folder not found: {args.imu_root}', file=sys.stderr)
        return 2
    try:
        for name in args.sequences:
            run(name, args.imu_root, args.fraction, args.scan_ms)
    except ValueError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    return 0


if __name__ == '__main__':
    sys.exit(main())
