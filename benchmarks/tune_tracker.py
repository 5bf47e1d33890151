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
Compare IemdTracker configurations on OTB sequences: average overlap and EMD discrimination.

    python benchmarks/tune_tracker.py --sequences Car4,Bolt2,Woman \
        --config "{}" --config "{'lam': 0.2}" [--frames N] [--discrimination]

Average overlap is the paper's metric over the whole sequence (or its first N
frames).  ``--discrimination`` also reports, on a few frames per sequence, the
percentage of windows within +-40 px of the ground truth (but away from it)
whose EMD is *lower* than the EMD at the ground truth, for a tracker
initialized on frame 1 without updates: 0 % means the EMD singles out the
target, 100 % means everything else looks more like it.
"""
from __future__ import annotations

import argparse
import ast
from multiprocessing import Pool

from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.evaluation.ope import evaluate_sequence, make_tracker
from iemd_ros.tracking.analysis import search_context
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.tracking.candidate import CandidateModel
import numpy as np


def overlap(job):
    name, config, frames = job
    seq = load_sequence(name)
    if frames:
        seq = seq.head(frames)
    scores, run = evaluate_sequence(seq, make_tracker('iemd', config))
    return scores.average_overlap, float(np.median(run.update_seconds) * 1e3)


def discrimination(job, radius=40, grid=4):
    name, config, _ = job
    seq = load_sequence(name)
    tracker = IemdTracker(config)
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    picks = np.linspace(10, len(seq) - 1, 5).astype(int)
    scores = []
    for k in picks:
        pyramid = ImagePyramid(to_gray(read_frame(seq.frame_paths[k])))
        context, center, size = (
            search_context(tracker, pyramid),
            box_centre(seq.gt_boxes[k]),
            seq.gt_boxes[k][2:],
        )
        at_gt = CandidateModel(context, center, size).emd()[0]
        others = [
            CandidateModel(context, center + (dx, dy), size).emd()[0]
            for dy in range(-radius, radius + 1, grid)
            for dx in range(-radius, radius + 1, grid)
            if abs(dx) >= 0.3 * size[0] or abs(dy) >= 0.3 * size[1]
        ]
        scores.append(100.0 * np.mean(np.array(others) < at_gt))
    return scores


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument('--sequences', default='Car4,Bolt2,Woman')
    parser.add_argument(
        '--config', action='append', default=[], help='TrackerConfig overrides as a dict literal'
    )
    parser.add_argument('--frames', type=int, default=0, help='first N frames only (0: all)')
    parser.add_argument('--discrimination', action='store_true')
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    overrides = [ast.literal_eval(c) for c in (args.config or ['{}'])]
    configs = [TrackerConfig.from_dict(o) for o in overrides]  # checked before any run
    names = args.sequences.split(',')
    jobs = [(n, c, args.frames) for c in configs for n in names]
    with Pool(args.jobs) as pool:
        results = pool.map(overlap, jobs)
        disc = pool.map(discrimination, jobs) if args.discrimination else None
    for ci, config in enumerate(overrides):
        rows = results[ci * len(names): (ci + 1) * len(names)]
        cells = ' '.join(f'{n}={ao * 100:5.1f}%' for n, (ao, _) in zip(names, rows))
        speed = np.median([ms for _, ms in rows])
        line = (f'{str(config):70s} {cells}  mean={np.mean([r[0] for r in rows]) * 100:5.1f}%  '
                f'median update {speed:.1f} ms')
        if disc:
            d = disc[ci * len(names): (ci + 1) * len(names)]
            line += '  discrimination ' + ' '.join(
                f'{n}={np.mean(s):.0f}%' for n, s in zip(names, d)
            )
        print(line, flush=True)


if __name__ == '__main__':
    main()
