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
``iemd-demo`` (``make demo``): the README's main job on an embedded default input, no data needed.

1. Generates a shaky-camera sequence with :func:`iemd_ros.datasets.synthetic.generate` (hand-held
   shake up to ``--max-rate`` deg/s, simulated gyro with noise, bias and a camera-IMU time offset;
   deterministic from ``--seed``) and writes it with :func:`iemd_ros.bags.make.write_bag` as a
   rosbag2 (mcap): Image, Imu, CameraInfo; plus its ground truth.
2. Replays the bag with :func:`iemd_ros.bags.replay.replay` -- the node's pipeline -- with and
   without the gyro prior (init on the first ground-truth box).
3. Prints the comparison table (average overlap, success AUC, precision@20 px, frames with overlap
   > 0 and > 40 %, fps of the tracker) and writes a plot: IoU per frame for both modes and their
   OTB success curves.

Everything goes to ``--out`` (default ``out/demo``): ``shaky_camera/`` (the bag),
``ground_truth.txt``, ``replay_gyro.csv``, ``replay_no_gyro.csv``, ``demo.png``.  Re-running
replaces these files.
"""
from __future__ import annotations

import argparse
from pathlib import Path
import shutil
import sys
import time

from iemd_ros.apps.replay import score_replay
from iemd_ros.bags.make import source_from_synthetic, write_bag
from iemd_ros.bags.replay import replay
from iemd_ros.common.cli import cli_main, CliParser, non_negative_float
from iemd_ros.datasets.synthetic import generate, SyntheticConfig
from iemd_ros.evaluation.metrics import iou, OTB_THRESHOLDS
import numpy as np

DEFAULT_OUT = Path('out') / 'demo'
BAG_NAME = 'shaky_camera'
MODES = (('gyro', True), ('no-gyro', False))


def demo_config(
    n_frames: int = 90, seed: int = 1, max_rate_deg_s: float = 200.0
) -> SyntheticConfig:
    """
    Return the embedded default input.

    320x240 at 30 fps, hand-held shake, a 200 Hz gyro with white noise (0.005 rad/s), a small bias
    and a 5 ms camera-IMU offset (the bag shifts the IMU stamps by it).
    """
    return SyntheticConfig(
        n_frames=n_frames,
        seed=seed,
        max_rate_deg_s=max_rate_deg_s,
        gyro_noise_std=0.005,
        gyro_bias=(0.002, -0.001, 0.001),
        time_offset_s=0.005,
    )


def run_demo(
    out: Path = DEFAULT_OUT,
    n_frames: int = 90,
    seed: int = 1,
    max_rate_deg_s: float = 200.0,
    progress: bool | None = None,
    log=print,
) -> dict:
    """
    Generate, write, replay twice, score, plot.

    Returns ``{mode: (ReplayResult, SequenceScores)}`` plus the paths under ``"paths"``.
    """
    if n_frames < 2:
        raise ValueError(f'--frames must be >= 2, got {n_frames}')
    out = Path(out)
    bag = out / BAG_NAME
    if bag.exists():
        if not (bag / 'metadata.yaml').is_file():
            raise ValueError(
                f'{bag} exists and is not a bag written by iemd-demo; remove it or choose --out'
            )
        shutil.rmtree(bag)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    seq = generate(demo_config(n_frames, seed, max_rate_deg_s))
    gt_path = out / 'ground_truth.txt'
    info = write_bag(source_from_synthetic(seq), bag, 'mcap', gt_out=gt_path)
    log(
        f'iemd-demo: wrote {bag} ({info["frames"]} frames {info["size"][0]}x{info["size"][1]}, '
        f'{info["imu"]} gyro '
        f'samples, peak {max_rate_deg_s:g} deg/s shake) in {time.perf_counter() - t0:.1f} s'
    )
    init = tuple(float(v) for v in seq.gt_boxes[0])
    runs = {}
    csv_paths = {label: out / f'replay_{label.replace("-", "_")}.csv' for label, _ in MODES}
    for label, use in MODES:
        res = replay(bag, init, use_gyro=use, csv_path=csv_paths[label], progress=progress)
        runs[label] = (res, score_replay(res, seq.gt_boxes, label))
        log(
            f'iemd-demo: replay {label:<7}: {len(res.results)} frames, gyro prior on '
            f'{res.gyro_used}, '
            f'{res.wall_s:.1f} s -> {csv_paths[label]}'
        )
    plot = out / 'demo.png'
    plot_demo(runs, seq.gt_boxes, plot)
    runs['paths'] = {'bag': bag, 'ground_truth': gt_path, 'plot': plot, 'csv': csv_paths}
    return runs


def format_comparison(runs: dict) -> str:
    """Table: one row per mode (average overlap, success AUC, P@20, overlap > 0 / > 40 %, fps)."""
    head = (f'{"mode":<9} {"frames":>6} {"AO %":>6} {"AUC %":>6} {"P@20 %":>7} {">0 %":>6} '
            f'{">40 %":>6} {"fps":>6}')
    lines = [head, '-' * len(head)]
    for label, _ in MODES:
        s = runs[label][1]
        lines.append(
            f'{label:<9} {s.n_frames:>6d} {100 * s.average_overlap:6.1f} '
            f'{100 * s.success_auc:6.1f} '
            f'{100 * s.precision_20:7.1f} {100 * s.overlap_gt_0:6.1f} '
            f'{100 * s.overlap_gt_04:6.1f} '
            f'{s.fps:6.1f}'
        )
    return '\n'.join(lines)


def plot_demo(runs: dict, gt: np.ndarray, path: Path) -> None:
    """Plot the IoU per frame (both modes) and the OTB success curves, side by side."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4), dpi=100)
    for (label, _), colour in zip(MODES, ('tab:blue', 'tab:red')):
        res, s = runs[label]
        a.plot(
            np.arange(len(gt)),
            iou(res.boxes, gt),
            color=colour,
            lw=1.5,
            label=f'{label} (AO {100 * s.average_overlap:.1f} %)',
        )
        b.plot(
            OTB_THRESHOLDS,
            s.success_curve,
            color=colour,
            lw=2,
            label=f'{label} [AUC {s.success_auc:.3f}]',
        )
    a.axhline(0.4, color='grey', ls=':', lw=1)
    a.set(
        xlabel='frame',
        ylabel='overlap with ground truth (IoU)',
        ylim=(0, 1.02),
        title='Shaky camera: overlap per frame',
    )
    b.set(
        xlabel='overlap threshold',
        ylabel='success rate',
        xlim=(0, 1),
        ylim=(0, 1.02),
        title='Success plot',
    )
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
        ax.legend(loc='lower left')
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format='png')
    plt.close(fig)


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(prog='iemd-demo', description=__doc__.split('\n\n')[0])
    p.add_argument(
        '--out', type=Path, default=DEFAULT_OUT, help=f'output folder (default {DEFAULT_OUT})'
    )
    p.add_argument(
        '--frames',
        type=int,
        default=90,
        help='frames of the synthetic sequence (default 90 = 3 s)',
    )
    p.add_argument(
        '--seed', type=int, default=1, help='seed of the synthetic sequence (default 1)'
    )
    p.add_argument(
        '--max-rate',
        type=non_negative_float,
        default=200.0,
        help='peak camera rotation rate, deg/s (default 200)',
    )
    p.add_argument(
        '--progress',
        action=argparse.BooleanOptionalAction,
        default=None,
        help='progress bars on stderr (default: when stderr is a terminal)',
    )
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        a = build_parser().parse_args(argv)
        t0 = time.perf_counter()
        runs = run_demo(a.out, a.frames, a.seed, a.max_rate, a.progress)
        print()
        print('Gyro-aided iEMD on a shaky-camera bag (synthetic, exact ground truth):')
        print(format_comparison(runs))
        print()
        print(f'plot: {runs["paths"]["plot"]}   ({time.perf_counter() - t0:.0f} s in total)')
        return 0

    return cli_main('iemd-demo', body)


if __name__ == '__main__':
    sys.exit(main())
