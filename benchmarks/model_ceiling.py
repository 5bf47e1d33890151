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
How good can iEMD's appearance model be?  Its ceiling against a plain template, on real sequences.

    python benchmarks/model_ceiling.py [--sequences Car4,Bolt2,Woman] [--stride 10] [--jump 3]

For every ``stride``-th frame k, with the target model of frame 1 (no template update):

* grid argmin: the window of the ground-truth size with the lowest score on a 13 x 13 grid of
  offsets within +-0.6 window sizes of the ground truth; its IoU with the ground truth.  Scores:
  the EMD of iEMD, and as a peer the negative normalized cross-correlation (NCC) of the frame-1
  window resampled to the template size.  This is what a perfect search could reach with the model.
* one descent: Algorithm 1 (``analysis.descend``, the paper's iterations: ``descent_tracker``) on
  frame k from the ground truth of frame k - ``jump`` (IoU with the ground truth of k), against
  staying at the start.
* capture range (``--capture``): on 6 frames per sequence, a tracker initialized on that frame (an
  exact model) descends on the same frame from starts 0.05-0.4 window sizes away from the target in
  8 directions; the share of starts that end within 0.05 window sizes of it.

All other numbers are mean IoU in %.
"""
from __future__ import annotations

import argparse
from multiprocessing import Pool

from iemd_ros.common.boxes import box_centre, centre_box
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.evaluation.metrics import iou
from iemd_ros.evaluation.ope import sequence_names
from iemd_ros.tracking.analysis import descend, descent_tracker, search_context
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.tracking.candidate import CandidateModel
import numpy as np

OFFSETS = np.linspace(-0.6, 0.6, 13)
CAPTURE_STARTS = (0.05, 0.1, 0.2, 0.3, 0.4)


def grid_argmin(score, centre, size, offsets=OFFSETS) -> np.ndarray:
    """
    Offset (dx, dy), in window sizes.

    Of the lowest ``score(window centre)`` on the grid of ``offsets``.
    """
    values = np.array(
        [[score(centre + (dx * size[0], dy * size[1])) for dx in offsets] for dy in offsets]
    )
    iy, ix = np.unravel_index(np.argmin(values), values.shape)
    return np.array([offsets[ix], offsets[iy]])


def _grid_argmin_iou(score, truth) -> float:
    """Return the IoU with ``truth`` of the window of the lowest ``score(centre)`` on the grid."""
    size = truth[2:]
    dx, dy = grid_argmin(score, box_centre(truth), size)
    best = (truth[0] + dx * size[0], truth[1] + dy * size[1], size[0], size[1])
    return float(iou(np.array([best]), truth[None])[0])


def measure(job):
    name, stride, jump = job
    seq = load_sequence(name)
    first = read_frame(seq.frame_paths[0])
    tracker = descent_tracker()  # descend() and search_context() leave the frame-1 model as it is
    tracker.init(first, seq.gt_boxes[0])
    template_size = tracker.config.template_size
    # the frame-1 window init() sampled (never updated here)
    reference = tracker.dictionary.templates[0].ravel()
    rows = []
    for k in range(max(stride, jump), len(seq), stride):
        truth = np.asarray(seq.gt_boxes[k], dtype=float)
        frame = read_frame(seq.frame_paths[k])
        pyramid = ImagePyramid(to_gray(frame))
        context, size = search_context(tracker, pyramid), truth[2:]

        def emd(centre):
            return CandidateModel(context, centre, size).emd()[0]

        def ncc(centre):
            window = pyramid.sample(centre, size, template_size).ravel()
            return -np.corrcoef(reference, window)[0, 1]

        start = np.asarray(seq.gt_boxes[k - jump], dtype=float)
        stepped = descend(tracker, frame, start).box
        rows.append(
            (
                _grid_argmin_iou(emd, truth),
                _grid_argmin_iou(ncc, truth),
                iou(np.array([stepped]), truth[None])[0],
                iou(start[None], truth[None])[0],
            )
        )
    return name, 100.0 * np.mean(rows, axis=0)


def capture(name):
    """
    Per start distance in CAPTURE_STARTS.

    The share of searches that end within 0.05 window sizes.
    """
    seq = load_sequence(name)
    converged, searches = np.zeros(len(CAPTURE_STARTS)), 0
    for k in np.linspace(0, len(seq) - 1, 6).astype(int):
        frame, truth = read_frame(seq.frame_paths[k]), np.asarray(seq.gt_boxes[k], dtype=float)
        tracker = descent_tracker()
        tracker.init(frame, truth)
        centre, size = box_centre(truth), truth[2:]
        for angle in np.linspace(0, 2 * np.pi, 8, endpoint=False):
            direction = np.array([np.cos(angle), np.sin(angle)])
            for i, distance in enumerate(CAPTURE_STARTS):
                start = centre_box(centre + distance * size * direction, size)
                end = box_centre(descend(tracker, frame, start).box)
                converged[i] += np.linalg.norm((end - centre) / size) < 0.05
            searches += 1
    return name, 100.0 * converged / searches


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        '--sequences', default=None, help='comma-separated (default: all in ../shared/data/otb)'
    )
    parser.add_argument('--stride', type=int, default=10)
    parser.add_argument('--jump', type=int, default=3)
    parser.add_argument('--jobs', type=int, default=2)
    parser.add_argument(
        '--capture', action='store_true', help="also measure the descent's capture range"
    )
    args = parser.parse_args()
    names = sequence_names(args.sequences)
    jobs = [(name, args.stride, args.jump) for name in names]
    with Pool(args.jobs) as pool:
        results = pool.map(measure, jobs)
    print(
        f'{"sequence":14s} {"grid EMD":>9s} {"grid NCC":>9s} {"descent":>10s} {"stay":>6s}   '
        '(mean IoU %)'
    )
    for name, values in results:
        print(f'{name:14s} {values[0]:9.1f} {values[1]:9.1f} {values[2]:10.1f} {values[3]:6.1f}')
    mean = np.mean([values for _, values in results], axis=0)
    print(f'{"mean":14s} {mean[0]:9.1f} {mean[1]:9.1f} {mean[2]:10.1f} {mean[3]:6.1f}')
    if args.capture:
        with Pool(args.jobs) as pool:
            shares = pool.map(capture, names)
        print(
            '\ncapture range: % of searches ending within 0.05 window sizes, by start distance '
            '(window sizes)'
        )
        print(f'{"sequence":14s} ' + ' '.join(f'{d:>6}' for d in CAPTURE_STARTS))
        for name, share in shares + [('mean', np.mean([v for _, v in shares], axis=0))]:
            print(f'{name:14s} ' + ' '.join(f'{v:6.0f}' for v in share))


if __name__ == '__main__':
    main()
