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
``iemd-eval``: one-pass evaluation of trackers on OTB-layout sequences.

The evaluation is :mod:`iemd_ros.evaluation.ope`.

    iemd-eval [ROOT_OR_SEQ ...] [--trackers iemd,csrt,kcf] [--sequences Car4,Bolt2]
              [--split train|validation] [--max-frames N] [--out DIR]
              [--config config/tracker.yaml] [--published [FILE]]
              [--jobs N | --cluster tcp://HOST:8786]

Without a folder it evaluates every sequence of ``../shared/data/otb`` and ``../shared/data/uav``.
Prints the average overlap, success AUC, precision at 20 px, the recall R (the average overlap
with the frames the tracker reported lost counted as 0) and fps per sequence and on average,
and writes ``results.json`` and one success plot per sequence plus an overall one into ``--out``.
Bad input prints one line on stderr and exits with status 2.  ``--split`` keeps the training or the
validation part of the fixed split (:mod:`iemd_ros.evaluation.split`); ``--published`` ranks the
run among the published trackers on the same sequences (:mod:`iemd_ros.evaluation.published`).

Each tracker on each sequence is one job; the jobs run on every local core by default (``--jobs``),
or on a Dask distributed cluster (``--cluster``), with a progress bar on stderr when it is a
terminal (:mod:`iemd_ros.common.parallel`).  ``results.json`` is the same whichever workers ran the
jobs, but for its wall-clock fields (fps, timings): the last line prints its digest without them
(:func:`iemd_ros.evaluation.ope.results_digest`).
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
import sys
import time

from iemd_ros.common.cli import cli_main, CliParser, positive_float
from iemd_ros.common.parallel import add_worker_arguments, Workers
from iemd_ros.evaluation.ope import (
    collect_sequences,
    DEFAULT_OUT,
    DEFAULT_TRACKERS,
    evaluate,
    format_long_term,
    format_table,
    make_tracker,
    results_digest,
    TRACKERS,
    WALL_CLOCK_FIELDS,
)
from iemd_ros.evaluation.published import default_published, format_published, load_published
from iemd_ros.evaluation.split import in_part, PARTS, split_names
from iemd_ros.pipeline import PipelineConfig

PUBLISHED_DEFAULT = Path('<default>')  # --published without a file

__all__ = ['main', 'build_parser']


def _csv(text: str) -> list[str]:
    items = [t.strip() for t in text.split(',') if t.strip()]
    if not items:
        raise argparse.ArgumentTypeError(f'empty list {text!r}')
    return items


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not an integer: {text!r}') from None
    if v < 2:
        raise argparse.ArgumentTypeError(
            f'must be >= 2 (init frame + at least one update), got {v}'
        )
    return v


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(
        prog='iemd-eval',
        description=__doc__.split('\n\n')[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        'inputs',
        nargs='*',
        metavar='ROOT_OR_SEQ',
        help='folder(s) of OTB-layout sequences and/or sequence folder(s); default '
        '../shared/data/otb '
        'and ../shared/data/uav',
    )
    p.add_argument(
        '--trackers',
        type=_csv,
        default=list(DEFAULT_TRACKERS),
        help=f'comma-separated, from {",".join(TRACKERS)} (default: all)',
    )
    p.add_argument(
        '--sequences',
        type=_csv,
        default=None,
        help='comma-separated sequence names (Jogging selects Jogging-1 and Jogging-2)',
    )
    p.add_argument(
        '--split',
        choices=PARTS,
        default=None,
        help='only the sequences of this part of the fixed split (iemd_ros/evaluation/split.json)',
    )
    p.add_argument(
        '--max-frames', type=_positive_int, default=None, help='evaluate only the first N frames'
    )
    p.add_argument(
        '--frame-rate',
        type=positive_float,
        default=None,
        metavar='HZ',
        help="the sequences' frame rate, which the OTB layout does not record: iEMD's models "
        "learn for the frames' interval (default: unknown, one frame at its reference rate)",
    )
    p.add_argument(
        '--out', type=Path, default=DEFAULT_OUT, help='output folder (default out/eval)'
    )
    p.add_argument(
        '--config',
        type=Path,
        default=None,
        help="iEMD parameters: the node's parameter file (config/tracker.yaml) or {tracker: "
        '{...}}; '
        'its tracker.* values apply (OTB has no IMU)',
    )
    p.add_argument(
        '--published',
        nargs='?',
        type=Path,
        const=PUBLISHED_DEFAULT,
        default=None,
        metavar='FILE',
        help="print the published trackers' results on the same sequences beside the run "
        '(default file: ../shared/anchors/published_results.json)',
    )
    add_worker_arguments(p)
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        args = build_parser().parse_args(argv)
        workers = Workers.from_args(args)  # an argument's error before any data is read
        trackers = list(dict.fromkeys(args.trackers))
        for t in trackers:
            make_tracker(t)  # fail early on an unknown tracker or one this OpenCV build lacks
        if args.config and 'iemd' not in trackers:
            raise ValueError(
                "--config sets the iemd tracker's parameters, but iemd is not among --trackers"
            )
        configs = {'iemd': PipelineConfig.from_yaml(args.config).tracker} if args.config else {}
        published = None
        if args.published is not None:
            path = default_published() if args.published == PUBLISHED_DEFAULT else args.published
            if path is None:
                raise ValueError(
                    '--published: ../shared/anchors/published_results.json does not exist; give '
                    'the file'
                )
            published = load_published(path)
        sequences = collect_sequences(args.inputs, args.sequences)
        if args.split is not None:
            # the part's sequences the inputs hold, and their cuts (Car4 -> Car4-follow40)
            part = split_names(args.split)
            sequences = [s for s in sequences if in_part(s.name, part)]
            if not sequences:
                raise ValueError(f"the inputs hold none of the {args.split} part's sequences")
        if args.max_frames is not None:
            sequences = [s.head(args.max_frames) for s in sequences]
        if args.frame_rate is not None:
            sequences = [dataclasses.replace(s, frame_rate=args.frame_rate) for s in sequences]
        n_jobs = len(trackers) * len(sequences)
        t_start = time.perf_counter()
        print(
            f'iemd-eval: {len(trackers)} tracker(s) x {len(sequences)} sequence(s) = {n_jobs} '
            'jobs '
            f'{workers.describe(n_jobs)} -> {args.out}'
            + (f' (iEMD parameters from {args.config})' if args.config else '')
        )
        # unreadable image, unwritable --out, unreachable cluster: one line, exit 2
        doc = evaluate(sequences, trackers, args.out, configs=configs, workers=workers)
        print()
        print(format_table(doc['results'], trackers, doc['sequences']))
        long_term = format_long_term(doc)
        if long_term:
            print()
            print(long_term)
        if published is not None:
            print()
            print(format_published(published, doc['results'], trackers))
            if args.max_frames is not None:
                print(
                    f'(this run scored the first {args.max_frames} frames only; the published '
                    'figures are over '
                    'whole sequences)'
                )
        print(
            f'\nwall time {time.perf_counter() - t_start:.1f} s; results in '
            f'{args.out / "results.json"}, '
            f'digest without {", ".join(WALL_CLOCK_FIELDS)}: {results_digest(doc)}'
        )
        return 0

    return cli_main('iemd-eval', body)


if __name__ == '__main__':
    sys.exit(main())
