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
The paper's other reading of the sparse-coding histogram, measured against the tracker's.

    python benchmarks/vote_histogram.py [--sequences Car4,Bolt2,Woman] [--frames 100] [--stride 10]

Default: every sequence in ../shared/data/otb.

Section 4 can be read two ways.

(a) The tracker's (iemd_ros.tracking.candidate): every local patch r is a bin; its mass is its
    pooled code weight ||a_bar_r||_inf times the kernel, and its appearance eps_r and position c_r
    enter the ground distance.
(b) A vote histogram: the K bins are the dictionary's patch positions; every densely sampled patch
    r puts its weight ||a_bar_r||_inf into the bin u = argmax_j a_bar_rj of its largest pooled code
    (w_T,u = gamma sum_r k(c_r) |p_ru|), and the ground distance is taken between the dictionary
    atoms and their positions, so it does not depend on the window.

(b) can only localize if a patch's largest code names the place in the target it came from.  For
every ``stride``-th frame k of the first ``frames`` (target model and dictionary of frame 1, as the
tracker builds them; window of the frame-1 size at the ground truth of frame k), this prints:

* votes: the share of dense (step 2) patches inside the kernel whose largest code is an atom
  within one patch step (0.3 half-widths) of their own position;
* argmin: the distance in window sizes from the ground truth to the window with the lowest EMD on a
  9 x 9 grid of offsets within +-0.4 window sizes, for (a) and (b).  0 means that the EMD singles
  out the target.
"""
from __future__ import annotations

import argparse
from multiprocessing import Pool

from iemd_ros import IemdTracker
from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.evaluation.ope import sequence_names
from iemd_ros.tracking.analysis import search_context
from iemd_ros.tracking.appearance import ImagePyramid, PatchLayout, to_gray
from iemd_ros.tracking.candidate import CandidateModel
from iemd_ros.tracking.emd import ground_distance, solve_emd
from iemd_ros.tracking.histogram import candidate_weights
from model_ceiling import grid_argmin  # benchmarks/ is the script's directory
import numpy as np

OFFSETS = np.linspace(-0.4, 0.4, 9)
DENSE_STEP = 2
NEAR = 0.3  # one patch step of the 8x8 / step-4 layout is 0.25 half-widths


class VoteHistogram:
    """Reading (b) on the tracker's frame-1 dictionary (atoms = the patches of I_0's layout)."""

    def __init__(self, tracker: IemdTracker):
        cfg = tracker.config
        self.tracker = tracker
        self.coder = tracker.dictionary.coder
        self.bin_pos = tracker.layout.positions()
        atoms = self.coder.dictionary.T
        self.cost = ground_distance(atoms, self.bin_pos, atoms, self.bin_pos, cfg.alpha)
        self.dense = PatchLayout(cfg.template_size, cfg.patch_size, DENSE_STEP)
        self.w_t = self.histogram(tracker.dictionary.templates[0])

    def votes(self, template):
        """
        (bin, weight) of every dense patch of ``template``.

        The argmax atom and ||a_bar||_inf.
        """
        codes = self.coder.encode(self.dense.extract(template).T)
        return codes.argmax(axis=0), codes.max(axis=0)

    def histogram(self, template) -> np.ndarray:
        bins, weights = self.votes(template)
        w, _ = candidate_weights(
            weights, self.dense.positions(), np.zeros(2), self.tracker.config.kernel_bandwidth
        )
        return np.bincount(bins, w, minlength=len(self.bin_pos))

    def emd(self, template) -> float:
        w_c = self.histogram(template)
        kt, kc = np.flatnonzero(self.w_t > 0), np.flatnonzero(w_c > 0)
        if kc.size == 0:
            return np.inf
        return solve_emd(self.w_t[kt], w_c[kc], self.cost[np.ix_(kt, kc)]).value

    def vote_accuracy(self, template) -> float:
        bins, _ = self.votes(template)
        pos = self.dense.positions()
        inside = (pos**2).sum(axis=1) < self.tracker.config.kernel_bandwidth**2
        near = np.linalg.norm(self.bin_pos[bins] - pos, axis=1) < NEAR
        return float(near[inside].mean())


def measure(job):
    name, frames, stride = job
    seq = load_sequence(name)
    tracker = IemdTracker()
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    votes = VoteHistogram(tracker)
    tsize = tracker.config.template_size
    rows = []
    for k in range(stride, min(frames, len(seq)), stride):
        pyramid = ImagePyramid(to_gray(read_frame(seq.frame_paths[k])))
        # frame-1 size
        center, size = box_centre(seq.gt_boxes[k]), np.asarray(seq.gt_boxes[0][2:], dtype=float)
        accuracy = votes.vote_accuracy(pyramid.sample(center, size, tsize))
        context = search_context(tracker, pyramid)
        patch_bins = np.hypot(
            *grid_argmin(
                lambda c: CandidateModel(context, c, size).emd()[0], center, size, OFFSETS
            )
        )
        vote_bins = np.hypot(
            *grid_argmin(
                lambda c: votes.emd(pyramid.sample(c, size, tsize)), center, size, OFFSETS
            )
        )
        rows.append((accuracy, patch_bins, vote_bins))
    frame0 = votes.vote_accuracy(tracker.dictionary.templates[0])
    return name, frame0, np.array(rows)


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        '--sequences', default=None, help='comma-separated (default: all in ../shared/data/otb)'
    )
    parser.add_argument('--frames', type=int, default=100, help='frames 1..N of each sequence')
    parser.add_argument('--stride', type=int, default=10)
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    with Pool(args.jobs) as pool:
        names = sequence_names(args.sequences)
        results = pool.map(measure, [(n, args.frames, args.stride) for n in names])
    print(
        f'{"sequence":14s} {"votes f1 %":>10s} {"votes k %":>10s} {"argmin (a)":>11s} '
        f'{"argmin (b)":>11s}'
        '   (argmin: mean distance from the truth, window sizes)'
    )
    for name, frame0, rows in results:
        print(
            f'{name:14s} {100 * frame0:10.1f} {100 * rows[:, 0].mean():10.1f} '
            f'{rows[:, 1].mean():11.3f}'
            f' {rows[:, 2].mean():11.3f}'
        )
    allrows = np.vstack([r for _, _, r in results])
    print(
        f'{"MEAN":14s} {100 * np.mean([f for _, f, _ in results]):10.1f} '
        f'{100 * allrows[:, 0].mean():10.1f}'
        f' {allrows[:, 1].mean():11.3f} {allrows[:, 2].mean():11.3f}'
    )


if __name__ == '__main__':
    main()
