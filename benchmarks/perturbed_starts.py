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
Robustness to the initial box.

Average overlap from shifted starts, iEMD against CSRT in the same run.

    python benchmarks/perturbed_starts.py [--sequences Car4,Bolt2] [--shift 0.1] [--starts sre] \
        [--config "{}" --config "{'alpha': 0.4}"] [--jobs 2]

OTB's one-pass evaluation starts every tracker from the exact ground truth, and a single run of a
tracker whose result swings with small changes says little.  As OTB's spatial robustness evaluation
(SRE) does, every sequence is also started from the ground truth shifted by ``shift`` of its size
along the four diagonals (5 starts in all); with ``--starts sre`` also along the four axes and with
the box scaled by 0.8, 0.9, 1.1 and 1.2 about its centre (13 starts: OTB's 8 spatial shifts and 4
scale variations, and the ground truth).  With ``--starts tre``, as OTB's temporal robustness
evaluation (TRE) does, each sequence is started from the ground truth at 20 evenly spaced frames
(the first annotated one at or after each) and run to its end: a user starts tracking wherever the
footage happens to be.  Each run is scored over all its frames against the ground truth
(iemd_ros.evaluation.metrics).  Printed per tracker: the mean average overlap over sequences
and starts, its mean per start, per sequence, and the median update time.  ``--config`` runs iEMD
with other TrackerConfig values (default: the defaults), each against the same peers.

A difference between two trackers is printed run by run (``paired_difference``: the mean difference
in points, its 95 % interval with whole sequences resampled, the runs better, worse and equal; then
the mean difference per sequence and per start, in the order of the starts above):
every configuration after the first against the first, and, with ``--against FILE``, every tracker
of this run against the first of a run saved by ``--save FILE`` (the same starts, shift and
resolution; another source tree, say).  A saved run records the digest of the
``iemd_ros.tracking`` sources it ran and when; the comparison prints both digests, so that a
reference saved from an older tracker is seen as such.

``--resolution 0.5`` runs every tracker on the frames resized to half their width and height
(OpenCV's area interpolation, as a camera binning its pixels) with the ground truth scaled alike:
footage of lower resolution than the shared sequences, and smaller targets
(docs/decisions.md#resolution-probe).  ``--mono`` runs every tracker on one-channel grey frames
(OpenCV's BGR-to-grey weights), as a monochrome camera's ``mono8`` images
(docs/decisions.md#mono-camera).  ``--jpeg-quality 30`` runs every tracker on the frames encoded
as JPEG at that quality and decoded again, as a compressed image stream delivers them
(docs/decisions.md#jpeg-probe).  ``--exposure 1`` runs every tracker on frames whose levels are
multiplied by a gain swinging 1 stop (a factor of 2) either way of 1, sinusoidally over
``EXPOSURE_PERIOD`` frames, as a camera's auto exposure swings when it hunts
(docs/decisions.md#exposure-probe).  ``--noise 8`` adds to every level Gaussian noise of standard
deviation 8, as a sensor in low light (docs/decisions.md#noise-probe).  ``--blur 8`` smears every
frame along a line 8 px long whose direction turns by the golden angle from frame to frame, as a
shaking camera moves while its shutter is open (docs/decisions.md#blur-probe).  ``--figure recall``
measures every run by its recall instead of its average overlap: the frames a tracker reported
lost count as 0, as its published detections do (docs/decisions.md#published-recall).
"""
from __future__ import annotations

import argparse
import ast
import datetime
import hashlib
import itertools
import json
from multiprocessing import Pool
from pathlib import Path
from typing import NamedTuple

import cv2
from iemd_ros import TrackerConfig, tracking
from iemd_ros.common.boxes import box_centre, centre_box
from iemd_ros.common.cli import positive_float
from iemd_ros.datasets.otb import load_sequence
from iemd_ros.evaluation.metrics import paired_difference, score_sequence, valid_boxes
from iemd_ros.evaluation.ope import make_tracker, run_tracker, sequence_names
from iemd_ros.evaluation.split import PARTS, split_names
from iemd_ros.messages.conversions import array_to_compressed_fields, compressed_to_array
from iemd_ros.tracking.appearance import grey_levels
import numpy as np

# Starts as (x, y) shift of the centre in units of ``shift`` times the box's size, the box's
# scale, and the fraction of the sequence's frames before the start.
DIAGONALS = (
    (0.0, 0.0, 1.0, 0.0),
    (1.0, 1.0, 1.0, 0.0),
    (-1.0, 1.0, 1.0, 0.0),
    (1.0, -1.0, 1.0, 0.0),
    (-1.0, -1.0, 1.0, 0.0),
)
AXES = tuple((dx, dy, 1.0, 0.0) for dx, dy in ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)))
SCALES = tuple((0.0, 0.0, s, 0.0) for s in (0.8, 0.9, 1.1, 1.2))
SEGMENTS = 20  # OTB's temporal robustness evaluation: starts at 20 evenly spaced frames
TEMPORAL = tuple((0.0, 0.0, 1.0, k / SEGMENTS) for k in range(SEGMENTS))
START_SETS = {'diagonal': DIAGONALS, 'sre': DIAGONALS + AXES + SCALES, 'tre': TEMPORAL}


class Camera(NamedTuple):
    """The camera a run's frames are converted to; each field is the option of its name."""

    resolution: float = 1.0  # times the frames' width and height
    mono: bool = False  # one grey channel
    every: int = 1  # every N-th frame
    jpeg_quality: int | None = None  # through a compressed stream at this JPEG quality
    exposure: float = 0.0  # stops of the gain's swing
    noise: float = 0.0  # standard deviation of the Gaussian noise, levels
    blur: float = 0.0  # length of the motion blur, px of the sequence's frames


# the options a saved run records, and the value a file saved before an option existed ran with:
# its default, for the camera's options the default of Camera's field
SETTINGS = {
    'starts': None,
    'shift': None,
    **Camera._field_defaults,
    'frame_rate': None,
    'figure': 'ao',
}
EXPOSURE_PERIOD = 60  # frames of one swing of --exposure's gain: 2 s at OTB's 30 Hz
BLUR_TURN = np.pi * (3.0 - np.sqrt(5.0))  # rad, the golden angle: --blur's turn per frame
# the figures --figure chooses from, in the order run() returns them, with their short names
FIGURES = {'ao': 'AO', 'recall': 'R'}


def start_box(first: np.ndarray, dx: float, dy: float, scale: float, shift: float) -> np.ndarray:
    """
    Return the box (x, y, w, h) ``first`` with its centre moved by (dx, dy) x ``shift`` x its size.

    Then scaled by ``scale`` about that centre.
    """
    return centre_box(
        box_centre(first) + np.array([dx, dy]) * shift * first[2:], first[2:] * scale
    )


def start_frame(truth: np.ndarray, at: float) -> int:
    """
    Return the first frame at or after ``at`` of the sequence where the target is annotated.

    At most the second last frame, so that a run tracks at least one frame; before ``at`` when no
    later frame is annotated.
    """
    n = len(truth)
    valid = np.flatnonzero(valid_boxes(truth)[: n - 1])
    later = valid[valid >= int(at * n)]
    return int(later[0] if later.size else valid[-1])


def run(job):
    """
    [(average overlap, recall, median update ms) per start] of each run on one sequence.

    Decoded once.
    """
    name, runs, shift, starts, camera, interval = job
    seq = load_sequence(name)
    frames, truth = _as_camera(seq.frames(), seq.gt_boxes, camera)
    begins = []  # (first frame, box) of each start, the same for every tracker
    for dx, dy, scale, at in starts:
        k = start_frame(truth, at)
        begins.append((k, start_box(truth[k], dx, dy, scale, shift)))
    out = []
    for label, tracker_name, config in runs:
        rows = []
        for k, start in begins:
            tracker = make_tracker(tracker_name, config)
            result = run_tracker(tracker, frames[k:], start, interval)
            scores = score_sequence(result.boxes, truth[k:], name, reported=result.ok)
            rows.append(
                (
                    scores.average_overlap,
                    scores.recall,
                    float(np.median(result.update_seconds) * 1e3),
                )
            )
        out.append(rows)
    return out


def _as_camera(frames, boxes, camera: Camera) -> tuple[list, np.ndarray]:
    """
    Return the decoded frames and 0-based ground-truth boxes as another camera would give them.

    That camera has ``resolution`` times the frames' resolution, with ``mono`` one grey channel,
    and takes every ``every``-th frame; with ``jpeg_quality`` its frames come through a compressed
    image stream, encoded as JPEG at that quality and decoded again as the node does.  With
    ``exposure`` the levels of the k-th frame it gives are multiplied by
    ``exposure_gain(k, exposure)`` (rounded, at most 255); with ``noise``, Gaussian noise of that
    standard deviation is added to each level (rounded, within 0-255; seeded by k, so that every
    run sees the same noise), both before any JPEG coding.  With ``blur`` each frame, as read, is
    first convolved with ``blur_kernel(k, blur)``.

    Each frame is converted as it is decoded, so a sequence is never held twice.  A box's 0-based
    corner and size scale by the resized frame's own ratio on each axis: pixel ``i`` spans
    ``[i - 1/2, i + 1/2]`` and the resize maps the image's edges onto each other.
    """
    factor, mono, every, jpeg_quality, exposure, noise, blur = camera
    boxes = np.asarray(boxes, dtype=float)[::every]
    out, ratio = [], np.ones(2)
    levels = np.arange(256.0)
    for k, frame in enumerate(itertools.islice(frames, 0, None, every)):
        if blur:
            frame = cv2.filter2D(frame, -1, blur_kernel(k, blur), borderType=cv2.BORDER_REFLECT)
        if mono:
            frame = grey_levels(frame)
        if factor != 1.0:
            h, w = frame.shape[:2]
            size = (max(1, round(w * factor)), max(1, round(h * factor)))
            frame = cv2.resize(frame, size, interpolation=cv2.INTER_AREA)
            ratio = np.array([size[0] / w, size[1] / h])
        if exposure:
            table = np.minimum(np.round(levels * exposure_gain(k, exposure)), 255.0)
            frame = cv2.LUT(frame, table.astype(np.uint8))
        if noise:
            grain = np.random.default_rng(k).normal(0.0, noise, frame.shape)
            frame = np.clip(np.round(frame + grain), 0, 255).astype(np.uint8)
        if jpeg_quality is not None:
            fields = array_to_compressed_fields(frame, 'jpeg', jpeg_quality)
            frame = compressed_to_array(fields['format'], fields['data'])
        out.append(frame)
    return out, boxes * np.tile(ratio, 2)


def exposure_gain(k: int, stops: float) -> float:
    """
    Return the gain of the ``k``-th frame: ``2 ** (stops sin(2 pi k / EXPOSURE_PERIOD))``.

    1 on the first frame, ``2 ** stops`` a quarter period later.
    """
    return float(2.0 ** (stops * np.sin(2.0 * np.pi * k / EXPOSURE_PERIOD)))


def blur_kernel(k: int, length: float) -> np.ndarray:
    """
    Return the motion blur of the ``k``-th frame: a line ``length`` px long through the centre.

    The line is at ``k * BLUR_TURN`` from the image's x axis (y down), sampled every 1/16 px
    with bilinear weights; the kernel sums to 1 and is odd-sized, so it does not shift the
    image.
    """
    half = int(np.ceil(length / 2.0)) + 1
    t = np.linspace(-length / 2.0, length / 2.0, int(np.ceil(16.0 * length)) + 1)
    x = half + t * np.cos(k * BLUR_TURN)
    y = half + t * np.sin(k * BLUR_TURN)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = x - x0, y - y0
    kernel = np.zeros((2 * half + 1, 2 * half + 1))
    for dy, dx, weight in (
        (0, 0, (1 - fy) * (1 - fx)),
        (0, 1, (1 - fy) * fx),
        (1, 0, fy * (1 - fx)),
        (1, 1, fy * fx),
    ):
        np.add.at(kernel, (y0 + dy, x0 + dx), weight)
    return (kernel / kernel.sum()).astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        '--sequences',
        default=None,
        help='comma-separated (default: all in ../shared/data/otb and ../shared/data/uav)',
    )
    parser.add_argument(
        '--split', choices=PARTS, default=None, help='only this part of the fixed split'
    )
    parser.add_argument(
        '--peers', default='csrt', help='comma-separated OpenCV peers (default: csrt)'
    )
    parser.add_argument(
        '--config', action='append', help='iEMD TrackerConfig values as a Python dict (repeatable)'
    )
    parser.add_argument(
        '--shift', type=float, default=0.1, help='start shift, fraction of the box size'
    )
    parser.add_argument(
        '--starts',
        choices=sorted(START_SETS),
        default='diagonal',
        help='diagonal: the ground truth and 4 diagonal shifts; sre: also 4 axis shifts, 4 '
        f'scales; tre: the ground truth at {SEGMENTS} evenly spaced frames',
    )
    parser.add_argument(
        '--resolution',
        type=float,
        help='frames and ground truth resized by this factor, in (0, 1] (default: 1)',
    )
    parser.add_argument(
        '--mono', action='store_true', help='frames turned to one-channel grey (a mono camera)'
    )
    parser.add_argument(
        '--jpeg-quality',
        type=int,
        metavar='Q',
        help='frames encoded as JPEG at this quality, 1-100, and decoded again, as a compressed '
        'image stream delivers them (default: as read)',
    )
    parser.add_argument(
        '--exposure',
        type=float,
        metavar='STOPS',
        help='frames multiplied by a gain swinging this many stops either way of 1 over '
        f'{EXPOSURE_PERIOD} frames, as an auto exposure hunting, in [0, 3] (default: 0, none)',
    )
    parser.add_argument(
        '--noise',
        type=float,
        metavar='SIGMA',
        help='Gaussian noise of this standard deviation added to every level, as a sensor in low '
        'light, in [0, 64] (default: 0, none)',
    )
    parser.add_argument(
        '--blur',
        type=float,
        metavar='PX',
        help='frames smeared along a line this long, in px of the frames as read, turning by the '
        'golden angle from frame to frame, as a shaking camera, in [0, 64] (default: 0, none)',
    )
    parser.add_argument(
        '--frame-rate',
        type=positive_float,
        default=None,
        metavar='HZ',
        help="the sequences' own frame rate, which iEMD is told (default: unknown)",
    )
    parser.add_argument(
        '--every',
        type=int,
        help='every N-th frame only, as a camera at 1/N of the rate; iEMD is told the interval, '
        'N frames at --frame-rate or, unknown, at the default reference_rate '
        '(default: 1)',
    )
    parser.add_argument(
        '--figure',
        choices=sorted(FIGURES),
        default='ao',
        help='what a run is measured by: ao, its average overlap; recall, the same with the '
        'frames the tracker reported lost counted as 0 (default: ao)',
    )
    parser.add_argument('--jobs', type=int, default=2)
    parser.add_argument(
        '--save', type=Path, help='write the figure of every run to this JSON file'
    )
    parser.add_argument(
        '--against', type=Path, help='compare with the first tracker of a run saved by --save'
    )
    parser.set_defaults(**Camera._field_defaults)  # the camera's options
    args = parser.parse_args()
    if not 0.0 < args.resolution <= 1.0:
        parser.error(f'--resolution must be in (0, 1], got {args.resolution}')
    if args.every < 1:
        parser.error(f'--every must be >= 1, got {args.every}')
    if args.jpeg_quality is not None and not 1 <= args.jpeg_quality <= 100:
        parser.error(f'--jpeg-quality must be in 1-100, got {args.jpeg_quality}')
    if not 0.0 <= args.exposure <= 3.0:
        parser.error(f'--exposure must be in [0, 3], got {args.exposure}')
    if not 0.0 <= args.noise <= 64.0:
        parser.error(f'--noise must be in [0, 64], got {args.noise}')
    if not 0.0 <= args.blur <= 64.0:
        parser.error(f'--blur must be in [0, 64], got {args.blur}')
    rate = args.frame_rate or (None if args.every == 1 else TrackerConfig().reference_rate)
    interval = None if rate is None else args.every / rate
    settings = {key: getattr(args, key) for key in SETTINGS}
    names = sequence_names(args.sequences)
    if args.split is not None:
        names = [n for n in names if n in split_names(args.split)]
    # checked before any run: a saved run without these sequences fails at once
    reference = None if args.against is None else _load_reference(args.against, settings, names)
    digest = _tracker_digest()
    # Checked here, before any run: a bad key or peer fails at once with its own message.
    runs = [
        (
            f'iemd {c}' if args.config else 'iemd',
            'iemd',
            TrackerConfig.from_dict(ast.literal_eval(c)),
        )
        for c in (args.config or ['{}'])
    ]
    peers = [peer for peer in args.peers.split(',') if peer]
    for peer in peers:
        make_tracker(peer)
    runs += [(peer, peer, None) for peer in peers]
    with Pool(args.jobs) as pool:
        results = pool.map(
            run,
            [
                (
                    name,
                    runs,
                    args.shift,
                    START_SETS[args.starts],
                    Camera(*(getattr(args, field) for field in Camera._fields)),
                    interval,
                )
                for name in names
            ],
            chunksize=1,
        )
    groups = {n: load_sequence(n).group for n in names}
    n_starts = len(START_SETS[args.starts])
    which = {
        'diagonal': f'ground truth, and shifted by {args.shift:g} of its size along the diagonals',
        'sre': f'ground truth, and shifted by {args.shift:g} of its size along the diagonals and '
        'the axes, and scaled by 0.8-1.2',
        'tre': f'ground truth at {SEGMENTS} evenly spaced frames, each run to the end',
    }[args.starts]
    print(
        f'{len(names)} sequences x {n_starts} starts ({which})'
        + ('' if args.resolution == 1.0 else f', frames at {args.resolution:g} of their size')
        + (', one-channel grey frames' if args.mono else '')
        + ('' if args.jpeg_quality is None else f', JPEG at quality {args.jpeg_quality}')
        + ('' if not args.exposure else f', exposure times {2 ** args.exposure:g} either way')
        + ('' if not args.noise else f', Gaussian noise of std {args.noise:g} levels')
        + ('' if not args.blur else f', motion blur {args.blur:g} px long')
        + ('' if args.every == 1 else f', one frame in {args.every}')
        + ('' if interval is None else f', iEMD told the frames are {interval * 1e3:.1f} ms apart')
    )
    overlaps = {}
    first = runs[0][0]
    figure, short = list(FIGURES).index(args.figure), FIGURES[args.figure]
    for i, (label, _, _) in enumerate(runs):
        rows = [row for per_sequence in results for row in per_sequence[i]]
        overlap = np.array([row[figure] for row in rows]).reshape(len(names), n_starts) * 100
        overlaps[label] = overlap
        speed = np.median([row[-1] for row in rows])
        starts = ' '.join(f'{v:4.1f}' for v in overlap.mean(axis=0))
        print(
            f'{label:60s} mean {short} {overlap.mean():5.1f} %  per start {starts}  median update '
            f'{speed:.1f} ms'
        )
        for group in sorted(set(groups.values())):
            rows_of = [k for k, n in enumerate(names) if groups[n] == group]
            print(
                f'    {group}: mean {short} {overlap[rows_of].mean():5.1f} % over {len(rows_of)} '
                f'sequences x {n_starts}'
            )
        print('    ' + ' '.join(f'{n}={v:.1f}' for n, v in zip(names, overlap.mean(axis=1))))
        if i > 0 and runs[i][1] == 'iemd':
            _print_difference(overlap, overlaps[first], first, names)
        if reference is not None:
            ref_label, ref_overlap, ref_source = reference
            _print_difference(
                overlap,
                ref_overlap,
                f'{ref_label} ({args.against}: {ref_source}; this run: tracker sources {digest})',
                names,
            )
    if args.save is not None:
        args.save.write_text(
            json.dumps(
                {
                    **settings,
                    'tracker_sources': digest,
                    'saved': datetime.datetime.now().isoformat(timespec='seconds'),
                    'runs': {
                        label: {n: [float(v) for v in row] for n, row in zip(names, o)}
                        for label, o in overlaps.items()
                    },
                },
                indent=1,
            )
        )


def _print_difference(
    ours: np.ndarray, reference: np.ndarray, label: str, names: list[str]
) -> None:
    d = paired_difference(ours, reference)
    print(
        f'    against {label}: {d.mean:+.1f} points, 95 % interval over sequences {d.low:+.1f} .. '
        f'{d.high:+.1f}; runs better / worse / equal {d.better} / {d.worse} / {d.equal}'
    )
    print('      by sequence: ' + ' '.join(f'{n} {v:+.1f}' for n, v in zip(names, d.per_sequence)))
    print('      by start: ' + ' '.join(f'{v:+.1f}' for v in d.per_start))


def _tracker_digest() -> str:
    """First 12 hex digits of the SHA-256 of the ``iemd_ros.tracking`` sources this run imports."""
    root = Path(tracking.__file__).parent
    h = hashlib.sha256()
    for path in sorted(root.rglob('*.py')):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


def _load_reference(path: Path, settings: dict, names) -> tuple[str, np.ndarray, str]:
    """
    (label, AO % per sequence of ``names`` and start, source) of the first tracker saved by --save.

    Its source: the digest of the tracker sources it ran and when, as far as the file records them.

    SystemExit with one line for a file that is not such a run, or one run with other
    ``settings`` (the options of :data:`SETTINGS`; a file without one ran with its default), or
    without a run of one of ``names``.
    """
    try:
        saved = json.loads(path.read_text())
        label, runs = next(iter(saved['runs'].items()))
    except (OSError, ValueError, KeyError, StopIteration, AttributeError) as exc:
        raise SystemExit(f'--against {path}: not a run saved by --save ({exc})') from None
    differ = [
        f'--{key.replace("_", "-")} {saved.get(key, default)} (this run: {settings[key]})'
        for key, default in SETTINGS.items()
        if saved.get(key, default) != settings[key]
    ]
    if differ:
        raise SystemExit(f'--against {path}: saved with {", ".join(differ)}')
    missing = [n for n in names if n not in runs]
    if missing:
        raise SystemExit(f'--against {path}: no run of {", ".join(missing)}')
    source = (
        f'tracker sources {saved.get("tracker_sources", "not recorded")}, '
        f'saved {saved.get("saved", "at an unrecorded time")}'
    )
    return label, np.array([runs[n] for n in names]), source


if __name__ == '__main__':
    main()
