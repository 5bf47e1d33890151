#!/usr/bin/env python3
"""Which EMD gradient drives Algorithm 1 best?  Descent from perturbed starts on real frames.

For each sequence and a few frames k, the tracker is initialized on frame k-1 at
its ground truth and Algorithm 1 descends on frame k from the ground truth moved
by a random offset of up to --offset px.  Printed per gradient: the mean and
median final centre error (px) against the ground truth, the share of starts
that end within 2 px, and the mean number of iterations.

    python benchmarks/gradient_compare.py [--sequences Car4,Bolt2,Woman] [--offset 6] [--starts 8]
"""
from __future__ import annotations

import argparse

import numpy as np

from iemd_ros import IemdTracker
from iemd_ros.boxes import box_centre, centre_box
from iemd_ros.otb import default_root, load_sequence, read_frame

GRADIENTS = ("paper", "envelope", "appearance")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sequences", default="Car4,Bolt2,Woman")
    parser.add_argument("--offset", type=float, default=6.0)
    parser.add_argument("--starts", type=int, default=8)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    errors = {g: [] for g in GRADIENTS}
    iterations = {g: [] for g in GRADIENTS}
    for name in args.sequences.split(","):
        seq = load_sequence(name, default_root())
        for k in np.linspace(5, len(seq) - 1, 6).astype(int):
            prev, cur = read_frame(seq.frame_paths[k - 1]), read_frame(seq.frame_paths[k])
            truth, size = box_centre(seq.gt_boxes[k]), np.asarray(seq.gt_boxes[k][2:], dtype=float)
            offsets = rng.uniform(-args.offset, args.offset, (args.starts, 2))
            tracker = IemdTracker()
            tracker.init(prev, seq.gt_boxes[k - 1])
            for offset in offsets:
                start = centre_box(truth + offset, size)
                for gradient in GRADIENTS:
                    tracker.config.gradient = gradient  # only the descent reads it
                    result = tracker.descend(cur, start)
                    errors[gradient].append(np.linalg.norm(box_centre(result.box) - truth))
                    iterations[gradient].append(result.iterations)
    print(f"starts up to {args.offset} px from the ground truth, {len(errors['paper'])} per gradient")
    for g in GRADIENTS:
        e = np.array(errors[g])
        print(f"{g:10s} final error mean {e.mean():5.2f} px  median {np.median(e):5.2f} px  "
              f"within 2 px {np.mean(e < 2) * 100:5.1f}%  iterations {np.mean(iterations[g]):4.1f}")


if __name__ == "__main__":
    main()
