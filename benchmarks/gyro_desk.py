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
The paper's gyro experiment (Table "Evaluation results on the CMU dataset").

iEMD with and without the gyro prior on the CMU desk sequence (eagle-head ground truth,
gt_eagle_head.txt).

The tracker is initialised on the first frame whose GT flag is ``ok`` and run causally over the raw
(distorted) frames; the gyro prior for frame k is the lens-aware local homography at the tracker's
current window (``GyroPredictor.predict``), integrated from the previous frame (the node's
pipeline: a lost window keeps moving with the camera).  Scores (iemd_ros.evaluation.metrics) over
the first 100 frames (the paper's sequence length) and over the whole sequence, from the init frame
on (the init frame included, as in OTB); frames whose GT is absent are excluded (the desk GT has
none).  Both modes use the tracker's scale estimator (``--scale-estimator``); with the paper's EMD
scale variants, the ±10 % scale search of its gyro experiment (``--scale-range``,
TrackerConfig.scale_range).

    PYTHONPATH=. .venv/bin/python benchmarks/gyro_desk.py [--frames N] [--scale-estimator emd]
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

from iemd_ros import TrackerConfig
from iemd_ros.datasets.recordings import load_recording
from iemd_ros.evaluation.metrics import score_sequence
from iemd_ros.evaluation.recording import track_recording
import numpy as np

DEFAULT_ROOT = Path(__file__).resolve().parents[1].parent / 'shared' / 'data' / 'imu'


def run(rec, start: int, stop: int, use_gyro: bool, config: TrackerConfig):
    """
    Tracker boxes for frames start..stop-1 (the init frame gets its GT box), lost count.

    Prior notes.
    """
    results, no_prior = track_recording(rec, start, stop, use_gyro, config)
    boxes = [np.asarray(rec.gt_boxes[start], float)] + [np.asarray(r.box, float) for r in results]
    return np.array(boxes), sum(r.lost for r in results), no_prior


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--imu-root', type=Path, default=DEFAULT_ROOT)
    ap.add_argument(
        '--frames', type=int, default=0, help='track only this many frames (0: whole sequence)'
    )
    ap.add_argument(
        '--scale-range',
        type=float,
        default=0.1,
        help="with --scale-estimator emd: largest scale change per frame searched (paper's gyro "
        'experiment: 0.1)',
    )
    ap.add_argument(
        '--scale-estimator',
        choices=('filter', 'emd'),
        default=TrackerConfig.scale_estimator,
        help='TrackerConfig.scale_estimator (default: %(default)s)',
    )
    ap.add_argument(
        '--save', type=Path, help='write the boxes of both runs and the GT to this .npz file'
    )
    args = ap.parse_args(argv)
    folder = args.imu_root / 'cmu_hwangbo_desk'
    if not folder.is_dir():
        print(f'error: desk recording not found: {folder}', file=sys.stderr)
        return 2
    if args.frames < 0 or args.frames == 1:
        print(f'error: --frames must be 0 (all) or >= 2, got {args.frames}', file=sys.stderr)
        return 2
    try:
        rec = load_recording(folder)
    except ValueError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    ok = np.nonzero(rec.gt_flags == 'ok')[0]
    start = int(ok[0])
    stop = len(rec) if args.frames == 0 else min(len(rec), start + args.frames)
    config = TrackerConfig(scale_estimator=args.scale_estimator, scale_range=args.scale_range)
    results = {}
    for use_gyro in (True, False):
        t0 = time.perf_counter()
        boxes, n_lost, no_prior = run(rec, start, stop, use_gyro, config)
        dt = time.perf_counter() - t0
        results[use_gyro] = boxes
        label = 'gyro-aided' if use_gyro else 'no gyro'
        print(
            f'{label}: {len(boxes)} frames in {dt:.0f} s ({(len(boxes) - 1) / dt:.1f} fps), '
            f'{n_lost} frames reported lost'
            + (f', {len(no_prior)} frames without a gyro prior' if use_gyro else '')
        )
        for note in no_prior[:5]:
            print(f'  {note}')
    gt = rec.gt_boxes[start:stop]
    if args.save:
        np.savez(args.save, gyro=results[True], no_gyro=results[False], gt=gt, first_frame=start)
    n_absent = int((~np.isfinite(gt).all(axis=1)).sum())
    print(
        f'\nCMU desk, eagle head; init on frame {start + 1} (first GT flag ok); '
        f'{n_absent} frames excluded for absent GT (the desk GT has no absent frame)'
    )
    spans = [('first 100 frames', 100)] if stop - start > 100 else []
    spans.append((f'whole run ({stop - start} frames)', stop - start))
    print(
        f'{"":36s} {"Gyro-aided":>11s} {"No gyro-aided":>14s}   (paper, first 100 frames: 50.7 / '
        '11.9, '
        f'100 / 70.7, 66.7 / 9.1)'
    )
    for name, n in spans:
        s = {g: score_sequence(results[g][:n], gt[:n], name) for g in (True, False)}
        print(f'{name}: {s[True].n_frames} scored frames')
        print(
            f'  {"Average overlap (%)":34s} {100 * s[True].average_overlap:11.1f} '
            f'{100 * s[False].average_overlap:14.1f}'
        )
        print(
            f'  {"Overlap > 0 (% frames)":34s} {100 * s[True].overlap_gt_0:11.1f} '
            f'{100 * s[False].overlap_gt_0:14.1f}'
        )
        print(
            f'  {"Overlap > 40% (% frames)":34s} {100 * s[True].overlap_gt_04:11.1f} '
            f'{100 * s[False].overlap_gt_04:14.1f}'
        )
    return 0


if __name__ == '__main__':
    sys.exit(main())
