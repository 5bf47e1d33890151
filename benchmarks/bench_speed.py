#!/usr/bin/env python3
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
Speed of iEMD against OpenCV CSRT (and KCF) on the same frames, measured in the same run.

For each sequence the first ``--frames`` frames are decoded into memory once, then every tracker
runs on them back to back (interleaved per sequence, so load changes on the shared machine hit all
trackers alike).  Only ``update`` calls are timed; iEMD's update returns before its models learn
from the frame and the next update waits for them, so back to back each timed update carries the
learning of the frame before: the times are whole frames.  A tracker that has lost the target may
run faster (OpenCV skips its model update on a failed frame), so the number of frames each tracker
reported failed is shown.  Prints median / p95 update time (ms) and fps per tracker, and the fps
ratio of each tracker against the reference (CSRT by default) per sequence and pooled.  With
``--repeats N`` every sequence is run N times (the trackers interleaved each time), the figures
pool all runs, and the pooled ratio is also printed per repeat with its median and range: on a
shared machine one run's ratio swings by a tenth or more.

Sequences: a few OTB sequences and 1280x720 drone sequences (init on their first GT box) plus the
640x480 CMU desk frames (``../shared/data/imu/cmu_hwangbo_desk``, init on the first box of
``gt_eagle_head.txt``).  Besides each sequence, the frames are pooled by class: up to 640x480
pixels, and larger (the 1280x720 drone frames).

    PYTHONPATH=. .venv/bin/python benchmarks/bench_speed.py [--trackers iemd,csrt] [--frames 150] \
        [--repeats 3]
"""
from __future__ import annotations

from pathlib import Path
import sys

import cv2
from iemd_ros.common.cli import cli_main, CliParser
from iemd_ros.datasets.otb import default_roots, list_sequences, load_sequence
from iemd_ros.datasets.recordings import load_recording
from iemd_ros.evaluation.ope import make_tracker, run_tracker, TRACKERS
import numpy as np

DESK = Path(__file__).resolve().parents[1].parent / 'shared' / 'data' / 'imu' / 'cmu_hwangbo_desk'


def desk_sequence(n: int) -> tuple[str, list[np.ndarray], np.ndarray]:
    """First ``n`` CMU desk frames (640x480) and the first eagle-head GT box."""
    rec = load_recording(DESK)
    return 'desk-640x480', [rec.load_frame(i) for i in range(min(n, len(rec)))], rec.gt_boxes[0]


def otb_sequence(name: str, n: int) -> tuple[str, list[np.ndarray], np.ndarray]:
    seq = load_sequence(name).head(n)
    frames = list(seq.frames())
    return f"{name}-{'x'.join(map(str, frames[0].shape[1::-1]))}", frames, seq.gt_boxes[0]


def main(argv=None) -> int:
    return cli_main('bench_speed', lambda: _main(argv))


def _main(argv) -> int:
    p = CliParser(prog='bench_speed', description=__doc__.split('\n\n')[0])
    p.add_argument(
        '--trackers', default='iemd,csrt', help=f'comma-separated from {",".join(TRACKERS)}'
    )
    p.add_argument('--reference', default='csrt', help='tracker the fps ratios are taken against')
    p.add_argument(
        '--sequences',
        default='Car4,Bolt2,Woman,DragonBaby,boat5,truck2,wakeboard10,building5',
        help='sequences of ../shared/data/otb and ../shared/data/uav',
    )
    p.add_argument('--frames', type=int, default=150)
    p.add_argument('--repeats', type=int, default=1, help='runs of every sequence, interleaved')
    p.add_argument('--no-desk', action='store_true', help='skip the 640x480 CMU desk frames')
    p.add_argument(
        '--cv-threads',
        type=int,
        default=None,
        help="cv2.setNumThreads(N) before timing (default: OpenCV's own choice)",
    )
    args = p.parse_args(argv)
    trackers = [t.strip() for t in args.trackers.split(',') if t.strip()]
    if args.frames < 2:
        raise ValueError(f'--frames must be >= 2, got {args.frames}')
    if args.repeats < 1:
        raise ValueError(f'--repeats must be >= 1, got {args.repeats}')
    for t in trackers:
        make_tracker(t)
    if args.reference not in trackers:
        raise ValueError(f'--reference {args.reference!r} is not among --trackers {trackers}')
    roots = default_roots()
    if not roots:
        raise ValueError('../shared/data/otb and ../shared/data/uav not found')
    names = [n for n in args.sequences.split(',') if n]
    unknown = sorted(set(names) - {s for root in roots for s in list_sequences(root)})
    if unknown:
        raise ValueError(
            f'unknown sequence(s) {", ".join(unknown)} in {", ".join(map(str, roots))}'
        )
    loaders = [lambda n=n: otb_sequence(n, args.frames) for n in names]
    if not args.no_desk and DESK.is_dir():
        loaders.append(lambda: desk_sequence(args.frames))

    if args.cv_threads is not None:
        cv2.setNumThreads(args.cv_threads)
    # per class, tracker and repeat: the update times (ms) of every sequence's run
    pooled: dict[str, dict[str, list[list[np.ndarray]]]] = {
        c: {t: [[] for _ in range(args.repeats)] for t in trackers} for c in CLASSES
    }
    failed: dict[str, dict[str, int]] = {c: {t: 0 for t in trackers} for c in CLASSES}
    print(
        f'OpenCV {cv2.__version__}, cv2.getNumThreads() = {cv2.getNumThreads()}; {args.frames} '
        f'frames/sequence, {args.repeats} run(s) of each'
    )
    print(
        f'{"sequence":<22} {"tracker":<6} {"median ms":>10} {"p95 ms":>8} {"fps":>8} {"ratio":>7} '
        f'{"failed":>7}'
    )
    for load in loaders:
        name, frames, box = load()
        kind = CLASSES[0] if frames[0].shape[0] * frames[0].shape[1] <= 640 * 480 else CLASSES[1]
        ms, fails = {t: [] for t in trackers}, {t: 0 for t in trackers}
        for r in range(args.repeats):
            for t in trackers:
                run = run_tracker(make_tracker(t), frames, box)
                ms[t].append(1e3 * run.update_seconds)
                pooled[kind][t][r].append(ms[t][-1])
                fails[t] += int((~run.ok).sum())
        for t in trackers:
            failed[kind][t] += fails[t]
        _report(name, {t: np.concatenate(v) for t, v in ms.items()}, fails, args.reference)
    for kind in CLASSES:
        if not pooled[kind][args.reference][0]:
            continue
        runs = {t: [np.concatenate(v) for v in repeats] for t, repeats in pooled[kind].items()}
        _report(
            f'{kind} (pooled)',
            {t: np.concatenate(v) for t, v in runs.items()},
            failed[kind],
            args.reference,
        )
        if args.repeats > 1:
            for t in trackers:
                if t == args.reference:
                    continue
                ratios = [
                    runs[args.reference][r].mean() / runs[t][r].mean() for r in range(args.repeats)
                ]
                print(
                    f'{"":<22} {t}/{args.reference} per repeat: '
                    + ', '.join(f'{x:.2f}' for x in ratios)
                    + f'; median {np.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f})'
                )
    return 0


CLASSES = ('<= 640x480', '1280x720')  # frame classes pooled: up to VGA's area, and larger


def _report(name: str, ms: dict[str, np.ndarray], fails: dict[str, int], reference: str) -> None:
    """
    Per tracker: median / p95 update ms, fps = 1000 / mean ms, fps ratio.

    Frames reported failed.
    """
    ref_fps = 1e3 / ms[reference].mean()
    for t, v in ms.items():
        fps = 1e3 / v.mean()
        print(
            f'{name:<22} {t:<6} {np.median(v):10.2f} {np.percentile(v, 95):8.2f} {fps:8.1f} '
            f'{fps / ref_fps:7.2f} {fails[t]:7d}'
        )
    print(
        f'{"":<22} fps ratio vs {reference}: '
        + ', '.join(
            f'{t}/{reference} = {1e3 / v.mean() / ref_fps:.2f}'
            for t, v in ms.items()
            if t != reference
        )
    )


if __name__ == '__main__':
    sys.exit(main())
