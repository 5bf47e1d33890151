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
``iemd-make-lookaway``: "look away and back" sequences cut from OTB-layout footage.

They are for the long-term measures.

    iemd-make-lookaway [ROOT_OR_SEQ ...] --out DIR [--crop 0.5] [--follow 15[,40,...]] [--away 30]
                       [--pan-px 40]

Without a folder it cuts every sequence of ``../shared/data/otb`` and ``../shared/data/uav`` whose
target can leave the virtual camera's window (:mod:`iemd_ros.datasets.lookaway`); the others are
listed and skipped.  Each output is an OTB-layout sequence named like its source, ``NaN`` where the
target is out of view: ``iemd-eval DIR`` scores it.  Bad arguments print one line on stderr and
exit with status 2.
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys

from iemd_ros.common.cli import cli_main, CliParser
from iemd_ros.datasets.lookaway import LookAway, write_look_away
from iemd_ros.evaluation.ope import collect_sequences

__all__ = ['main', 'build_parser']


def build_parser() -> CliParser:
    p = CliParser(prog='iemd-make-lookaway', description=__doc__.split('\n\n')[0])
    p.add_argument(
        'inputs',
        nargs='*',
        metavar='ROOT_OR_SEQ',
        help='folder(s) of OTB-layout sequences or sequence folders; default ../shared/data/otb '
        'and uav',
    )
    p.add_argument(
        '--out', type=Path, required=True, help='output folder (one sequence folder per source)'
    )
    p.add_argument('--sequences', default=None, help='comma-separated names to keep')
    d = LookAway()
    p.add_argument(
        '--crop', type=float, default=d.crop, help=f'window size / frame size (default {d.crop})'
    )
    p.add_argument(
        '--follow',
        type=_follows,
        default=(d.follow_frames,),
        help='frames followed before panning off; several (15,40,80): one cut of each source per '
        f'value, named <source>-follow<N> (default {d.follow_frames})',
    )
    p.add_argument(
        '--away', type=int, default=d.away_frames, help='frames the target stays out of view'
    )
    p.add_argument('--pan-px', type=float, default=d.pan_px, help='pan speed, px per source frame')
    return p


def _follows(text: str) -> tuple[int, ...]:
    """Parse ``--follow``: the distinct positive frame counts of a comma-separated list."""
    try:
        values = tuple(dict.fromkeys(int(v) for v in text.split(',') if v.strip()))
    except ValueError:
        values = ()
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f'expected frame counts like 15,40,80, not {text!r}')
    return values


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        a = build_parser().parse_args(argv)
        cuts = [(k, LookAway(a.crop, k, a.away, a.pan_px)) for k in a.follow]
        wanted = [s for s in a.sequences.split(',') if s] if a.sequences else None
        made = skipped = 0
        for seq in collect_sequences(a.inputs, wanted):
            for k, cfg in cuts:
                # iemd-eval's --sequences and --split select <source>-follow<N> by <source>
                name = seq.name if len(cuts) == 1 else f'{seq.name}-follow{k}'
                try:
                    folder = write_look_away(seq, a.out / seq.group, cfg, name)
                except ValueError as exc:
                    print(f'iemd-make-lookaway: skipped {name}: {exc}')
                    skipped += 1
                    continue
                made += 1
                print(f'iemd-make-lookaway: {name} -> {folder}')
        print(f'iemd-make-lookaway: {made} sequence(s) written under {a.out}, {skipped} skipped')
        return 0 if made else 2

    return cli_main('iemd-make-lookaway', body)


if __name__ == '__main__':
    sys.exit(main())
