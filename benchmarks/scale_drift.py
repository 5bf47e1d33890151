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
Drift of the scale filter alone: fed the true centre on every frame, how far its size goes off.

    PYTHONPATH=. python benchmarks/scale_drift.py [--split train|validation] [--sequences Car4]

For each sequence of ``../shared`` (OTB and drone) the tracker's scale filter (fDSST, the tracker's
``scale_step``) starts from the first ground-truth box; on every frame where the target is
annotated it estimates the relative scale at the true centre and learns there at its own size, as
in the tracker.  Prints the mean and the largest |log(size / true size)| per sequence and over all
(size: the square root of the box's area).  It isolates the scale estimate from the search: the
tracker's box can be no better than this on scale.
"""
import argparse
import sys

from iemd_ros import TrackerConfig
from iemd_ros.evaluation.ope import collect_sequences
from iemd_ros.evaluation.split import in_part, PARTS, split_names
from iemd_ros.tracking.scale_filter import ScaleFilter
import numpy as np


def drift(seq, scale_step: float) -> np.ndarray:
    """|log(size / true size)| on the annotated frames after the first of ``seq``."""
    frames = seq.frames()
    first = np.asarray(seq.gt_boxes[0], float)
    size = first[2:].copy()
    sf = ScaleFilter(scale_step=1.0 + scale_step)
    sf.init(next(frames), first[:2] + first[2:] / 2, size)
    errors = []
    for frame, box in zip(frames, seq.gt_boxes[1:]):
        if not np.all(np.isfinite(box)):
            continue
        centre = box[:2] + box[2:] / 2
        size = size * sf.estimate(frame, centre, size)
        sf.update(frame, centre, size)
        errors.append(0.5 * abs(np.log(np.prod(size) / np.prod(box[2:]))))
    return np.asarray(errors)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    p.add_argument('--split', choices=PARTS, default=None, help='one part of the fixed split')
    p.add_argument('--sequences', default=None, help='comma-separated names (default: all)')
    args = p.parse_args(argv)
    wanted = args.sequences.split(',') if args.sequences else None
    try:
        seqs = collect_sequences([], wanted)  # ../shared/data/otb and uav
    except ValueError as e:
        print(f'scale_drift.py: {e}', file=sys.stderr)
        return 2
    if args.split is not None:
        seqs = [s for s in seqs if in_part(s.name, split_names(args.split))]
    step = TrackerConfig().scale_step
    everything = []
    print(f'{"sequence":16s} {"frames":>7s} {"mean |log|":>11s} {"max |log|":>10s}')
    for seq in seqs:
        e = drift(seq, step)
        everything.append(e)
        print(f'{seq.name:16s} {len(e):7d} {e.mean():11.3f} {e.max():10.3f}')
    e = np.concatenate(everything)
    print(f'{"ALL":16s} {len(e):7d} {e.mean():11.3f} {e.max():10.3f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
