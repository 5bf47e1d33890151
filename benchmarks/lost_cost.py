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
Cost of a lost frame against a tracked one, on look-away sequences (issue #25: at most about 2x).

    iemd-make-lookaway --out /tmp/lookaway
    PYTHONPATH=. python benchmarks/lost_cost.py /tmp/lookaway/otb /tmp/lookaway/uav

Runs IemdTracker from the ground truth over each sequence and times every update; a frame counts as
lost when the update returns ``lost`` or re-detects the target (the frames that pay for
re-detection), tracked otherwise.  Prints the mean update time of each kind per sequence and over
all, and their ratio, both measured in the same run.
"""
import argparse
import sys
import time

from iemd_ros import IemdTracker
from iemd_ros.datasets.otb import read_frame
from iemd_ros.evaluation.ope import collect_sequences
from iemd_ros.tracking import Cause
import numpy as np


def _times(seq) -> tuple[list[float], list[float]]:
    """(tracked, lost) update seconds over ``seq`` from its first box."""
    tracker = IemdTracker()
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    tracked, lost = [], []
    for path in seq.frame_paths[1:]:
        frame = read_frame(path)
        t0 = time.perf_counter()
        result = tracker.update(frame)
        dt = time.perf_counter() - t0
        (lost if result.lost or result.cause is Cause.REDETECTED else tracked).append(dt)
    return tracked, lost


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    p.add_argument('inputs', nargs='+', metavar='ROOT_OR_SEQ', help='look-away sequences')
    args = p.parse_args(argv)
    try:
        sequences = collect_sequences(args.inputs, None)
    except ValueError as e:
        print(f'lost_cost.py: {e}', file=sys.stderr)
        return 2
    all_tracked, all_lost = [], []
    print(
        f'{"sequence":24s} {"tracked":>8s} {"ms":>7s} {"lost":>6s} {"ms":>7s} '
        f'{"lost/tracked":>13s}'
    )
    for seq in sequences:
        tracked, lost = _times(seq)
        all_tracked += tracked
        all_lost += lost
        t_ms = 1e3 * np.mean(tracked) if tracked else float('nan')
        l_ms = 1e3 * np.mean(lost) if lost else float('nan')
        print(
            f'{seq.name:24s} {len(tracked):8d} {t_ms:7.2f} {len(lost):6d} {l_ms:7.2f} '
            f'{l_ms / t_ms:13.2f}'
        )
    t_ms, l_ms = 1e3 * np.mean(all_tracked), 1e3 * np.mean(all_lost)
    print(
        f'{"ALL":24s} {len(all_tracked):8d} {t_ms:7.2f} {len(all_lost):6d} {l_ms:7.2f} '
        f'{l_ms / t_ms:13.2f}'
    )
    return 0


if __name__ == '__main__':
    sys.exit(main())
