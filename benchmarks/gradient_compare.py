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
Which EMD gradient drives Algorithm 1 best?  Descents from perturbed starts on real frames.

For each sequence and a few frames k, the tracker is initialized on frame k-1 at its ground truth
and Algorithm 1 (``analysis.descend``, the paper's iterations: ``descent_tracker``) runs from
starts moved by a random offset of up to --offset px:

* next frame: on frame k, from around its ground truth (the model has to bridge a real change of
  appearance, and the ground truth itself is only good to a pixel or two);
* known shift: on frame k-1 translated by a random sub-pixel offset of up to 3 px (cubic
  interpolation), from around where that puts the target: the descent's own precision, with an
  exact model.

Printed per case and gradient: the mean and median final centre error (px), the share of starts
that end within 0.5 and 2 px, and the mean number of iterations.

    python benchmarks/gradient_compare.py [--sequences Car4,Bolt2,Woman] [--offset 3] [--starts 8]
"""
from __future__ import annotations

import argparse

import cv2
from iemd_ros.common.boxes import box_centre, centre_box
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.tracking.analysis import descend, descent_tracker
import numpy as np

GRADIENTS = ('paper', 'appearance')
CASES = ('next frame', 'known shift')


def shifted(frame: np.ndarray, offset) -> np.ndarray:
    """``frame`` translated by ``offset`` (dx, dy) px, borders reflected."""
    shift = np.float32([[1, 0, offset[0]], [0, 1, offset[1]]])
    return cv2.warpAffine(
        frame, shift, frame.shape[1::-1], flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT
    )


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument('--sequences', default='Car4,Bolt2,Woman')
    parser.add_argument('--offset', type=float, default=3.0)
    parser.add_argument('--starts', type=int, default=8)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    errors = {(case, g): [] for case in CASES for g in GRADIENTS}
    iterations = {key: [] for key in errors}
    for name in args.sequences.split(','):
        seq = load_sequence(name)
        for k in np.linspace(5, len(seq) - 1, 6).astype(int):
            prev = read_frame(seq.frame_paths[k - 1])
            tracker = descent_tracker()
            tracker.init(prev, seq.gt_boxes[k - 1])
            motion = rng.uniform(-3.0, 3.0, 2)
            frames = {
                'next frame': (read_frame(seq.frame_paths[k]), seq.gt_boxes[k]),
                'known shift': (shifted(prev, motion), seq.gt_boxes[k - 1]),
            }
            for case, (frame, box) in frames.items():
                truth = box_centre(box) + (motion if case == 'known shift' else 0.0)
                size = np.asarray(box[2:], dtype=float)
                for offset in rng.uniform(-args.offset, args.offset, (args.starts, 2)):
                    start = centre_box(truth + offset, size)
                    for gradient in GRADIENTS:
                        tracker.config.gradient = gradient  # only the descent reads it
                        result = descend(tracker, frame, start)
                        errors[case, gradient].append(
                            np.linalg.norm(box_centre(result.box) - truth)
                        )
                        iterations[case, gradient].append(result.iterations)
    for case in CASES:
        print(
            f'{case}: starts up to {args.offset} px off, {len(errors[case, "paper"])} per gradient'
        )
        for g in GRADIENTS:
            e = np.array(errors[case, g])
            print(
                f'  {g:10s} final error mean {e.mean():5.2f} px  median {np.median(e):5.2f} px  '
                'within 0.5 px '
                f'{np.mean(e < 0.5) * 100:5.1f}%  2 px {np.mean(e < 2) * 100:5.1f}%  '
                f'iterations {np.mean(iterations[case, g]):4.1f}'
            )


if __name__ == '__main__':
    main()
