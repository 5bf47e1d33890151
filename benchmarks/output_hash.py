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
Hash of the tracker's outputs on real excerpts: behaviour-preserving changes keep it.

    PYTHONPATH=. python benchmarks/output_hash.py [--config "{'update_confidence': 0}"]

Runs IemdTracker (top-level API only) from the ground truth over fixed excerpts of ../shared and
prints, per excerpt and over all, a hash of every numeric TrackResult field (box, emd, scale,
angle, iterations, starts, codings, solver warnings, lost, held) to the bit.
"""
import argparse
import ast
import hashlib
from pathlib import Path
import re
import struct
import sys

import cv2
from iemd_ros import IemdTracker, TrackerConfig

DATA = Path(__file__).resolve().parents[1].parent / 'shared' / 'data'
EXCERPTS = (
    ('otb/Car4', 'groundtruth_rect.txt', 100),
    ('otb/Bolt2', 'groundtruth_rect.txt', 100),
    ('otb/Woman', 'groundtruth_rect.txt', 150),
    ('otb/Jogging', 'groundtruth_rect.2.txt', 80),
    ('otb/DragonBaby', 'groundtruth_rect.txt', 113),
    ('uav/boat5', 'groundtruth_rect.txt', 40),
)
FIELDS = (
    'emd',
    'scale',
    'angle',
    'iterations',
    'starts',
    'codings',
    'solver_warnings',
    'lost',
    'held',
)


def excerpt(folder: Path, gt_name: str, n: int):
    images = sorted(
        (p for p in (folder / 'img').iterdir() if p.suffix == '.jpg'),
        key=lambda p: int(re.sub(r'\D', '', p.stem)),
    )[:n]
    line = (folder / gt_name).read_text().splitlines()[0]
    x, y, w, h = (float(v) for v in re.split(r'[,\s]+', line.strip()))
    return images, (x - 1, y - 1, w, h)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('--config', default='{}')
    a = p.parse_args()
    config = TrackerConfig(**ast.literal_eval(a.config))
    total = hashlib.sha256()
    for rel, gt_name, n in EXCERPTS:
        images, box = excerpt(DATA / rel, gt_name, n)
        tracker = IemdTracker(config)
        tracker.init(cv2.imread(str(images[0])), box)
        h = hashlib.sha256()
        for path in images[1:]:
            r = tracker.update(cv2.imread(str(path)))
            values = [*r.box, *(float(getattr(r, f)) for f in FIELDS)]
            h.update(struct.pack(f'{len(values)}d', *values))
        total.update(h.digest())
        print(f'{rel:<16} {n:4d} frames  {h.hexdigest()[:16]}')
    print(f'{"all":<16} {"":10}  {total.hexdigest()[:16]}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
