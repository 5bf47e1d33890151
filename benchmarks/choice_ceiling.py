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
Ceiling of the tracker's choices: its own average overlap against an oracle that chooses for it.

    PYTHONPATH=. python benchmarks/choice_ceiling.py [--split train|validation] [--sequences Car4]
                                                     [--jobs 2]

Every sequence of ``../shared`` (OTB and drone) is tracked from the ground truth five times:

* ``tracker``: the shipped tracker as it is;
* ``start``: on every annotated frame the search is handed only the start (the prediction, the
  flow's, the filter's or the colour model's window) whose centre is nearest the true centre; the
  rest (the occlusion check, the scale, learning, the lost state) is the tracker's own;
* ``scale``: the scale filter's estimate replaced by the true size over the window's size (the
  area; the window keeps its aspect ratio);
* ``aspect``: the window's aspect ratio set to the true one after the scale filter, its area the
  tracker's own;
* ``both``: ``start`` and ``scale`` together.

Printed: the average overlap per sequence and the mean, per variant.  The gap between ``tracker``
and ``start`` is what a better choice among the starts the tracker already has could win, with
nothing new to find the target; ``scale`` and ``aspect`` are the same for the size
(docs/decisions.md#choice-ceiling, docs/decisions.md#aspect-ratio).
"""
import argparse
import dataclasses
from multiprocessing import Pool
import sys

from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import load_sequence
from iemd_ros.evaluation.ope import evaluate_sequence, IemdAdapter, sequence_names
from iemd_ros.evaluation.split import in_part, PARTS, split_names
from iemd_ros.tracking.tracker import IemdTracker
import numpy as np

# each variant and what the ground truth decides in it
VARIANTS = {
    'tracker': frozenset(),
    'start': frozenset({'start'}),
    'scale': frozenset({'scale'}),
    'aspect': frozenset({'aspect'}),
    'both': frozenset({'start', 'scale'}),
}


class OracleTracker(IemdTracker):
    """The shipped tracker, its start choice, scale or aspect taken from the ground truth."""

    def __init__(self, gt: np.ndarray, oracles: frozenset):
        super().__init__()
        self._gt, self._oracles = gt, oracles
        self._frame = 0  # the index of the frame being tracked

    def _truth(self):
        """Return the ground-truth box of the frame being tracked, or None where it is absent."""
        box = self._gt[self._frame]
        return box if np.all(np.isfinite(box)) else None

    def _search(self, models, prediction):
        truth = self._truth()
        if 'start' in self._oracles and truth is not None:
            centre = box_centre(truth)
            models = [min(models, key=lambda m: float(np.linalg.norm(m.center - centre)))]
        return super()._search(models, prediction)

    def _estimate_scale(self, frame, best, bounds):
        found, scale = super()._estimate_scale(frame, best, bounds)
        truth = self._truth()
        if 'scale' in self._oracles and truth is not None:
            scale = float(np.sqrt(truth[2] * truth[3] / np.prod(best.model.size)))
        if 'aspect' in self._oracles and truth is not None:
            # the same area at the true width / height: a scale per axis (update reports their
            # geometric mean, the area's scale)
            area = float(np.prod(best.model.size)) * scale ** 2
            ratio = truth[2] / truth[3]
            scale = np.sqrt([area * ratio, area / ratio]) / best.model.size
        return found, scale

    def update(self, frame, prior=None, interval=None):
        self._frame += 1
        result = super().update(frame, prior, interval)
        # the geometric mean: the aspect oracle's pair gives its area's scale, one scale itself
        return dataclasses.replace(result, scale=float(np.exp(np.mean(np.log(result.scale)))))


class OracleAdapter(IemdAdapter):
    """:class:`OracleTracker` in `iemd-eval`'s one-pass run and scoring."""

    def __init__(self, gt: np.ndarray, oracles: frozenset):
        super().__init__()
        self._tracker = OracleTracker(gt, oracles)


def run(job) -> tuple[str, str, float]:
    """Return (sequence, variant, average overlap) of one run from the ground truth."""
    name, variant = job
    seq = load_sequence(name)
    oracle = OracleAdapter(np.asarray(seq.gt_boxes, dtype=float), VARIANTS[variant])
    return name, variant, evaluate_sequence(seq, oracle)[0].average_overlap


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    p.add_argument('--split', choices=PARTS, default=None, help='one part of the fixed split')
    p.add_argument('--sequences', default=None, help='comma-separated names (default: all)')
    p.add_argument('--jobs', type=int, default=2, help='runs side by side (processes)')
    args = p.parse_args(argv)
    try:
        names = sequence_names(args.sequences)
    except ValueError as e:
        print(f'choice_ceiling.py: {e}', file=sys.stderr)
        return 2
    if args.split is not None:
        names = [n for n in names if in_part(n, split_names(args.split))]
    jobs = [(n, v) for n in names for v in VARIANTS]
    with Pool(max(args.jobs, 1)) as pool:
        ao = {(n, v): a for n, v, a in pool.map(run, jobs)}
    print(f'{"sequence":16s}' + ''.join(f'{v:>9s}' for v in VARIANTS))
    for n in names:
        print(f'{n:16s}' + ''.join(f'{100 * ao[n, v]:9.1f}' for v in VARIANTS))
    means = [100 * np.mean([ao[n, v] for n in names]) for v in VARIANTS]
    print(f'{"mean":16s}' + ''.join(f'{m:9.1f}' for m in means))
    return 0


if __name__ == '__main__':
    sys.exit(main())
