#!/usr/bin/env python3
"""How much of the peer's lead comes from its settings?  OpenCV's CSRT with some of its parameters changed.

    python benchmarks/csrt_params.py [--sequences Jogging-1,Jogging-2,Woman,Bolt2] [--jobs 2]

Each variant sets a few fields of ``cv2.TrackerCSRT_Params`` (the rest are OpenCV's defaults, which
``iemd-eval`` runs) and tracks every sequence once from the ground truth; printed: the average overlap
per sequence (iemd_ros.evaluation.metrics), per variant.  The README ("Where the gap to CSRT is") quotes it.
"""
from __future__ import annotations

import argparse
from functools import partial
from multiprocessing import Pool

import cv2

from iemd_ros.evaluation.ope import OpenCVTracker, run_tracker, sequence_names
from iemd_ros.evaluation.metrics import score_sequence
from iemd_ros.datasets.otb import load_sequence

VARIANTS = {
    "defaults": {},
    "no segmentation": {"use_segmentation": False},
    "no colour names": {"use_color_names": False},
    "HOG only": {"use_color_names": False, "use_gray": False, "use_rgb": False},
    "no HOG": {"use_hog": False},
    "padding 1.5": {"padding": 1.5},
    "template 100 px": {"template_size": 100},
    "template 64 px": {"template_size": 64},
}


def create(fields: dict) -> "cv2.Tracker":
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
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sequences", default="Jogging-1,Jogging-2,Woman,Bolt2")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    names = sequence_names(args.sequences)
    with Pool(args.jobs) as pool:
        results = pool.map(run, names, chunksize=1)
    print(f"{'CSRT variant':18s} " + " ".join(f"{n:>12s}" for n in names) + "   (average overlap %)")
    for i, label in enumerate(VARIANTS):
        print(f"{label:18s} " + " ".join(f"{per_sequence[i]:12.1f}" for per_sequence in results))


if __name__ == "__main__":
    main()
