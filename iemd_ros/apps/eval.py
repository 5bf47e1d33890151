"""``iemd-eval``: one-pass evaluation of trackers on OTB-layout sequences (:mod:`iemd_ros.evaluation.ope`).

    iemd-eval [ROOT_OR_SEQ ...] [--trackers iemd,csrt,kcf] [--sequences Car4,Bolt2] [--max-frames N] [--out DIR]
              [--config config/tracker.yaml]

Prints the average overlap, success AUC, precision at 20 px and fps per sequence and on average, and writes
``results.json`` and one success plot per sequence plus an overall one into ``--out``.  Bad input prints one line
on stderr and exits with status 2.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from iemd_ros.common.cli import CliParser, cli_main
from iemd_ros.evaluation.ope import (DEFAULT_OUT, DEFAULT_TRACKERS, TRACKERS, collect_sequences, evaluate,
                                     format_table, make_tracker)
from iemd_ros.pipeline import PipelineConfig

__all__ = ["main", "build_parser"]


def _csv(text: str) -> list[str]:
    items = [t.strip() for t in text.split(",") if t.strip()]
    if not items:
        raise argparse.ArgumentTypeError(f"empty list {text!r}")
    return items


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if v < 2:
        raise argparse.ArgumentTypeError(f"must be >= 2 (init frame + at least one update), got {v}")
    return v


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(prog="iemd-eval", description=__doc__.split("\n\n")[0],
                  formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("inputs", nargs="*", metavar="ROOT_OR_SEQ",
                   help="OTB root folder(s) and/or sequence folder(s); default ../shared/data/otb")
    p.add_argument("--trackers", type=_csv, default=list(DEFAULT_TRACKERS),
                   help=f"comma-separated, from {','.join(TRACKERS)} (default: all)")
    p.add_argument("--sequences", type=_csv, default=None,
                   help="comma-separated sequence names (Jogging selects Jogging-1 and Jogging-2)")
    p.add_argument("--max-frames", type=_positive_int, default=None, help="evaluate only the first N frames")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default out/eval)")
    p.add_argument("--config", type=Path, default=None,
                   help="iEMD parameters: the node's parameter file (config/tracker.yaml) or {tracker: {...}}; "
                        "its tracker.* values apply (OTB has no IMU)")
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        args = build_parser().parse_args(argv)
        trackers = list(dict.fromkeys(args.trackers))
        for t in trackers:
            make_tracker(t)  # fail early on an unknown tracker or one this OpenCV build lacks
        if args.config and "iemd" not in trackers:
            raise ValueError("--config sets the iemd tracker's parameters, but iemd is not among --trackers")
        configs = {"iemd": PipelineConfig.from_yaml(args.config).tracker} if args.config else {}
        sequences = collect_sequences(args.inputs, args.sequences)
        if args.max_frames is not None:
            sequences = [s.head(args.max_frames) for s in sequences]
        t_start = time.perf_counter()
        print(f"iemd-eval: {len(trackers)} tracker(s) x {len(sequences)} sequence(s) -> {args.out}"
              + (f" (iEMD parameters from {args.config})" if args.config else ""))
        doc = evaluate(sequences, trackers, args.out, configs=configs)  # unreadable image, unwritable --out: one line, exit 2
        print()
        print(format_table(doc["results"], trackers, doc["sequences"]))
        print(f"\nwall time {time.perf_counter() - t_start:.1f} s; results in {args.out / 'results.json'}")
        return 0

    return cli_main("iemd-eval", body)


if __name__ == "__main__":
    sys.exit(main())
