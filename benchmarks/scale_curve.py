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
How well does the EMD see the target's scale?  Real OTB sequences, ground truth as reference.

    python benchmarks/scale_curve.py [--sequences Car4,Woman,David,Bolt2] [--stride 5] [--jobs 2]

* curve: on every ``stride``-th frame, the EMD between the frame-1 target model (no template
  update) and the window at the ground-truth centre with the ground-truth size times s, for s in
  0.80-1.25.  Printed: the median over frames of EMD(s) / EMD(1) (a scale-sensitive score rises on
  both sides of 1), the share of frames whose lowest EMD lies within 5 % of the true scale, and as
  a peer the same share for the normalized cross-correlation (NCC) of the frame-1 window.
* in the loop: the tracker run with an oracle translation (a translation prior that takes its
  window to the ground-truth centre before each update; no descent, flow start or coarse stage), so
  only its scale moves: the mean |log| of its size against the ground truth's (sqrt of the areas),
  with the scale filter (the default), the paper's EMD scale variants, and no scale search at all.
  The translation filter (and on colour frames the colour model) stays on, so its start can move
  the window off the true centre (docs/decisions.md#scale-estimator);
  ``translation_weight=0`` and ``colour_weight=0`` in the config make the translation exact.
"""
from __future__ import annotations

import argparse
from multiprocessing import Pool

from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.evaluation.ope import sequence_names
from iemd_ros.tracking.analysis import search_context
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.tracking.candidate import CandidateModel
import numpy as np

SCALES = np.exp(np.linspace(np.log(0.8), np.log(1.25), 23))  # 2.0 % apart; SCALES[11] = 1
SHOWN = (0, 4, 8, 10, 12, 14, 18, 22)  # 0.80, 0.87, 0.94, 0.98, 1.02, 1.06, 1.15, 1.25


def curve(job):
    """
    Per scored frame, the EMD and the negative NCC at each of SCALES.

    (frames, 2, len(SCALES)).
    """
    name, stride = job
    seq = load_sequence(name)
    tracker = IemdTracker(TrackerConfig(update_templates=False))
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    reference = tracker.dictionary.templates[0].ravel()
    template_size = tracker.config.template_size
    rows = []
    for k in range(stride, len(seq), stride):
        truth = np.asarray(seq.gt_boxes[k], dtype=float)
        pyramid = ImagePyramid(to_gray(read_frame(seq.frame_paths[k])))
        context, centre = search_context(tracker, pyramid), box_centre(truth)
        emd = [CandidateModel(context, centre, truth[2:] * s).emd()[0] for s in SCALES]
        ncc = [
            -np.corrcoef(reference, pyramid.sample(centre, truth[2:] * s, template_size).ravel())[
                0, 1
            ]
            for s in SCALES
        ]
        rows.append((emd, ncc))
    return name, np.array(rows)


def oracle_translation(job):
    """
    Mean |log(size / ground-truth size)| of the tracker with an oracle translation prior.

    The prior moves the tracker's window to the ground-truth centre before each update (the public
    API: no private state is set).
    """
    name, config = job
    seq = load_sequence(name)
    tracker = IemdTracker(TrackerConfig.from_dict(dict(n_iter=0, flow_start=False, **config)))
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    errors = []
    # the tracker's window centre (it moves only on frames not lost)
    centre = box_centre(seq.gt_boxes[0])
    for k in range(1, len(seq)):
        truth = np.asarray(seq.gt_boxes[k], dtype=float)
        prior = np.eye(3)
        # a translation prior that takes the window to the true centre
        prior[:2, 2] = box_centre(truth) - centre
        result = tracker.update(read_frame(seq.frame_paths[k]), prior=prior)
        box = result.box
        if not result.lost:
            centre = box_centre(box)
        errors.append(0.5 * abs(np.log(box[2] * box[3] / (truth[2] * truth[3]))))
    return float(np.mean(errors))


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        '--sequences', default=None, help='comma-separated (default: all in ../shared/data/otb)'
    )
    parser.add_argument('--stride', type=int, default=5)
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    names = sequence_names(args.sequences)
    configs = {
        'scale filter': {},
        'EMD variants': {'scale_estimator': 'emd'},
        'no scale search': {'scale_step': 0.0},
    }
    with Pool(args.jobs) as pool:
        curves = pool.map(curve, [(name, args.stride) for name in names])
        loop = {
            label: pool.map(oracle_translation, [(name, config) for name in names])
            for label, config in configs.items()
        }
    one = int(np.argmin(np.abs(SCALES - 1.0)))
    print(
        'median EMD(s) / EMD(1) at the ground-truth centre (frame-1 model); lowest score within 5 '
        '% of the '
        'true scale, EMD and NCC (% of frames)'
    )
    print(
        f'{"sequence":14s} ' + ' '.join(f'{SCALES[i]:5.2f}' for i in SHOWN) + '   EMD<5%  NCC<5%'
    )
    for name, rows in curves:
        ratio = np.median(rows[:, 0, :] / rows[:, 0, one: one + 1], axis=0)
        near = [
            100.0 * np.mean(np.abs(np.log(SCALES[np.argmin(rows[:, j, :], axis=1)])) < 0.05)
            for j in range(2)
        ]
        print(
            f'{name:14s} '
            + ' '.join(f'{ratio[i]:5.2f}' for i in SHOWN)
            + f'   {near[0]:6.0f}  {near[1]:6.0f}'
        )
    print('\nin the loop with an oracle translation: mean |log(size / ground-truth size)| (%)')
    print(f'{"sequence":14s} ' + ' '.join(f'{label:>16s}' for label in configs))
    for i, name in enumerate(names):
        print(f'{name:14s} ' + ' '.join(f'{100 * loop[label][i]:16.1f}' for label in configs))
    print(f'{"mean":14s} ' + ' '.join(f'{100 * np.mean(loop[label]):16.1f}' for label in configs))


if __name__ == '__main__':
    main()
