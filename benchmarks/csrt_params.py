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
OpenCV's CSRT with some of its parameters changed: how much of the peer's lead is its settings.

    python benchmarks/csrt_params.py [--sequences Jogging-1,Jogging-2,Woman,Bolt2] [--jobs 2]

Each variant sets a few fields of ``cv2.TrackerCSRT_Params`` (the rest are OpenCV's defaults, which
``iemd-eval`` runs) and tracks every sequence once from the ground truth; printed: the average
overlap per sequence (iemd_ros.evaluation.metrics), per variant.  The README ("Where the gap to
CSRT is") quotes it.
"""

from __future__ import annotations

import argparse
from functools import partial
from multiprocessing import Pool

import cv2
from iemd_ros.datasets.otb import load_sequence
from iemd_ros.evaluation.metrics import score_sequence
from iemd_ros.evaluation.ope import OpenCVTracker, run_tracker, sequence_names

VARIANTS = {
    'defaults': {},
    'no segmentation': {'use_segmentation': False},
    'no colour names': {'use_color_names': False},
    'HOG only': {'use_color_names': False, 'use_gray': False, 'use_rgb': False},
    'no HOG': {'use_hog': False},
    'padding 1.5': {'padding': 1.5},
    'template 100 px': {'template_size': 100},
    'template 64 px': {'template_size': 64},
}


def create(fields: dict) -> 'cv2.Tracker':
    params = cv2.TrackerCSRT_Params()
    for key, value in fields.items():
        setattr(params, key, value)
    return cv2.TrackerCSRT.create(params)


def run(name: str) -> list[float]:
    """Average overlap (%) of every variant on sequence ``name``."""
    seq = load_sequence(name)
    frames = list(seq.frames())
    overlaps = []
    for fields in VARIANTS.values():
        result = run_tracker(OpenCVTracker(partial(create, fields)), frames, seq.gt_boxes[0])
        overlaps.append(100.0 * score_sequence(result.boxes, seq.gt_boxes, name).average_overlap)
    return overlaps


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument('--sequences', default='Jogging-1,Jogging-2,Woman,Bolt2')
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    names = sequence_names(args.sequences)
    with Pool(args.jobs) as pool:
        results = pool.map(run, names, chunksize=1)
    print(
        f'{"CSRT variant":18s} ' + ' '.join(f'{n:>12s}' for n in names) + '   (average overlap %)'
    )
    for i, label in enumerate(VARIANTS):
        print(f'{label:18s} ' + ' '.join(f'{per_sequence[i]:12.1f}' for per_sequence in results))


if __name__ == '__main__':
    main()
