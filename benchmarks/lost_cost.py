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

Runs iEMD from the ground truth over each sequence (``iemd-eval``'s one-pass run) and times every
update; an update counts as lost when it starts or ends with the target lost (the frames that pay
for re-detection), tracked otherwise.  Prints the mean update time of each kind per sequence and
over all, and their ratio, both measured in the same run.
"""
import argparse
import sys

from iemd_ros.evaluation.ope import collect_sequences, IemdAdapter, run_tracker
import numpy as np


def _times(seq) -> tuple[np.ndarray, np.ndarray]:
    """(tracked, lost) update seconds over ``seq`` from its first box."""
    run = run_tracker(IemdAdapter(), seq.frames(), seq.gt_boxes[0])
    lost = ~run.ok[1:] | ~run.ok[:-1]  # update k ends at frame k + 1, starts from frame k
    return run.update_seconds[~lost], run.update_seconds[lost]


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
        all_tracked.append(tracked)
        all_lost.append(lost)
        t_ms = 1e3 * tracked.mean() if len(tracked) else float('nan')
        l_ms = 1e3 * lost.mean() if len(lost) else float('nan')
        print(
            f'{seq.name:24s} {len(tracked):8d} {t_ms:7.2f} {len(lost):6d} {l_ms:7.2f} '
            f'{l_ms / t_ms:13.2f}'
        )
    all_tracked, all_lost = np.concatenate(all_tracked), np.concatenate(all_lost)
    t_ms, l_ms = 1e3 * all_tracked.mean(), 1e3 * all_lost.mean()
    print(
        f'{"ALL":24s} {len(all_tracked):8d} {t_ms:7.2f} {len(all_lost):6d} {l_ms:7.2f} '
        f'{l_ms / t_ms:13.2f}'
    )
    return 0


if __name__ == '__main__':
    sys.exit(main())
