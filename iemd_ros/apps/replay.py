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
``iemd-replay``: run the tracker over a bag offline, as fast as the CPU allows.

Also ``ros2 run iemd_ros replay``.

    iemd-replay BAG --init X,Y,W,H [--image-topic T] [--imu-topic T] [--camera-info-topic T]
                [--no-gyro] --csv OUT.csv [--out-bag DIR] [--video OUT.mp4] [--gt FILE]
                [--config YAML] [--camera-yaml FILE] [--time-offset-ms MS]
                [--progress | --no-progress]
    iemd-replay BAG_OR_FOLDER [...] --init X,Y,W,H [--init ...] --out-dir DIR [--out-bags]
                [--jobs N | --cluster tcp://HOST:8786] [the topic, gyro and config options]

What it does and writes: :mod:`iemd_ros.bags.replay`.  With ``--gt`` (OTB ``x,y,w,h`` or the desk
``x,y,w,h,flag`` format, one line per image, 1-based) it prints the evaluation's metrics.  The gyro
time offset ``t_d`` is ``gyro.time_offset_ns`` of the config (default 0: bags made by
``iemd-make-bag`` carry IMU stamps on the camera clock).  With ``--out-dir`` it replays a batch:
several bags, or folders of bags, one job per bag on every local core by default (``--jobs``) or on
a Dask cluster (``--cluster``), each writing ``DIR/<bag>.csv`` (and with ``--out-bags``
``DIR/<bag>_result``), the same bytes as a replay of that bag alone (:mod:`iemd_ros.bags.batch`);
``--init`` is then given once for every bag or once per bag, in order.  Bad input prints one line
on stderr and exits with status 2.
"""
from __future__ import annotations

import argparse
from dataclasses import replace
import math
from pathlib import Path
import sys
import time

from iemd_ros.bags.batch import (
    bag_name,
    bags_in,
    find_bags,
    replay_batch,
    replay_jobs,
    RESULT_BAG_SUFFIX,
)
from iemd_ros.bags.replay import CSV_HEADER, parse_box, replay, ReplayResult
from iemd_ros.common.cli import cli_main, CliParser, finite_float, split_ros_args
from iemd_ros.common.parallel import add_worker_arguments, Workers
from iemd_ros.datasets.otb import parse_groundtruth
from iemd_ros.evaluation.metrics import score_sequence, SequenceScores
from iemd_ros.evaluation.ope import format_table, MEAN, mean_scores
from iemd_ros.gyro import CameraModel
from iemd_ros.pipeline import PipelineConfig
import numpy as np

__all__ = ['main', 'score_replay', 'evaluation_table']


def score_replay(result: ReplayResult, gt: np.ndarray, name: str) -> SequenceScores:
    """
    Return the evaluation's scores of a replay against ``gt``.

    Fps counts the tracker's processing time only.
    """
    boxes = result.boxes
    if len(gt) != len(boxes):
        raise ValueError(
            f'the ground truth has {len(gt)} boxes for {len(boxes)} images in the bag'
        )
    fps = len(boxes) / result.track_s if result.track_s > 0 else math.inf
    reported = [r.tracking for r in result.results]
    return score_sequence(boxes, gt, name, fps=fps, reported=reported)


def evaluation_table(
    result: ReplayResult, gt: np.ndarray, name: str, label: str = 'iemd'
) -> tuple[str, object]:
    """Return the scores of the replay against ``gt`` and their table (``format_table``)."""
    scores = score_replay(result, gt, name)
    table = format_table(
        {label: {name: scores.to_dict(), MEAN: mean_scores([scores])}}, [label], [name]
    )
    return table, scores


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(
        prog='iemd-replay',
        description=__doc__.split('\n\n')[0],
        epilog='Details: python -m pydoc iemd_ros.bags.replay',
    )
    p.add_argument(
        'bags',
        nargs='+',
        metavar='BAG',
        help='rosbag2 folder (sqlite3/mcap) or ROS 1 .bag file; with --out-dir several, or '
        'folders of bags',
    )
    p.add_argument(
        '--init',
        required=True,
        action='append',
        type=str,
        metavar='X,Y,W,H',
        help='initial box on the first image (0-based pixels, top-left + size); with --out-dir '
        'once for '
        'every bag or once per bag, in order',
    )
    p.add_argument(
        '--image-topic',
        default=None,
        help='sensor_msgs/Image or CompressedImage topic (default: the '
        "bag's one image topic; X/compressed yields to its raw X)",
    )
    p.add_argument('--imu-topic', default=None)
    p.add_argument('--camera-info-topic', default=None)
    p.add_argument('--no-gyro', action='store_true', help='track without the gyro prior')
    p.add_argument(
        '--csv', type=Path, default=None, help=f'per-image results ({",".join(CSV_HEADER)})'
    )
    p.add_argument(
        '--out-bag',
        type=Path,
        default=None,
        help='write detections + diagnostics into this new rosbag2 (mcap) folder',
    )
    p.add_argument('--video', type=Path, default=None, help='write an annotated MP4 (mp4v)')
    p.add_argument(
        '--gt',
        type=Path,
        default=None,
        help='ground truth (OTB or desk format): print the metrics',
    )
    p.add_argument(
        '--config',
        type=Path,
        default=None,
        help="pipeline configuration: the node's parameter file (config/tracker.yaml) or "
        '{tracker: {...}, gyro: {...}, imu_wait_ms: ...}',
    )
    p.add_argument(
        '--camera-yaml',
        type=Path,
        default=None,
        help="ROS camera_info YAML to use instead of the bag's camera info",
    )
    p.add_argument(
        '--time-offset-ms',
        type=finite_float,
        default=None,
        help='gyro time offset t_d (t_imu = t_cam + t_d); default from --config, else 0',
    )
    p.add_argument(
        '--progress',
        action=argparse.BooleanOptionalAction,
        default=None,
        help='progress bar on stderr (default: when stderr is a terminal)',
    )
    batch = p.add_argument_group('batch (several bags, in parallel)')
    batch.add_argument(
        '--out-dir',
        type=Path,
        default=None,
        help='replay every bag given (folders: the bags in them), writing DIR/<bag>.csv',
    )
    batch.add_argument(
        '--out-bags',
        action='store_true',
        help="with --out-dir: also write each bag's detections + diagnostics, "
        f'DIR/<bag>{RESULT_BAG_SUFFIX}',
    )
    add_worker_arguments(batch)
    return p


def _summary(res: ReplayResult) -> str:
    """One line about a replay: images, topics, gyro use, lost and rejected frames, speed."""
    d = res.diagnostics
    return (
        f'{len(res.results)} images from {res.topics.image}'
        f'{f", IMU {res.topics.imu}" if res.topics.imu else ""}: gyro prior on {res.gyro_used} '
        'frames, '
        f'lost on {d.get("frames_lost", 0)}, rejected '
        f'{d.get("frames_rejected", 0) + d.get("images_malformed", 0)}; '
        f'{res.wall_s:.1f} s wall for {res.duration_s:.1f} s of bag = {res.realtime_factor:.2f}x '
        'real time'
    )


def _one_bag(a, options: dict) -> int:
    if len(a.bags) > 1 or bags_in(Path(a.bags[0])):
        raise ValueError(
            f'{" ".join(a.bags)}: several bags: replay them with --out-dir DIR (one CSV per bag)'
        )
    if a.csv is None:
        raise ValueError('--csv is required (or --out-dir DIR for a batch of bags)')
    if len(a.init) > 1:
        raise ValueError(f'--init is given {len(a.init)} times for one bag')
    if a.out_bags or a.jobs is not None or a.cluster is not None:
        raise ValueError('--out-bags, --jobs and --cluster apply to a batch (--out-dir DIR)')
    box = parse_box(a.init[0])
    gt = parse_groundtruth(a.gt, with_flags=True)[0] if a.gt else None
    if a.out_bag is not None and a.out_bag.exists():
        raise ValueError(f'--out-bag {a.out_bag} exists already; choose a new folder')
    res = replay(
        a.bags[0],
        box,
        csv_path=a.csv,
        out_bag=a.out_bag,
        video=a.video,
        progress=a.progress,
        **options,
    )
    print(f'iemd-replay: {_summary(res)}')
    print(
        f'iemd-replay: results -> {a.csv}'
        + (f', {a.out_bag}' if a.out_bag else '')
        + (f', {a.video}' if a.video else '')
    )
    if gt is not None:
        table, _ = evaluation_table(
            res,
            gt,
            Path(a.bags[0]).name.removesuffix('.bag')[:14],
            'iemd' if a.no_gyro else 'iemd+g',
        )
        print()
        print(table)
    return 0


def _batch(a, options: dict) -> int:
    single = [
        flag
        for flag, value in (
            ('--csv', a.csv),
            ('--out-bag', a.out_bag),
            ('--video', a.video),
            ('--gt', a.gt),
        )
        if value is not None
    ]
    if single:
        raise ValueError(
            f"{', '.join(single)} replay one bag; with --out-dir each bag's CSV is DIR/<bag>.csv "
            f'(and --out-bags writes DIR/<bag>{RESULT_BAG_SUFFIX})'
        )
    workers = Workers.from_args(a)
    bags = find_bags(a.bags)
    jobs = replay_jobs(bags, a.init, a.out_dir, out_bags=a.out_bags, **options)
    t_start = time.perf_counter()
    print(f'iemd-replay: {len(jobs)} bag(s) {workers.describe(len(jobs))} -> {a.out_dir}')
    results = replay_batch(
        jobs,
        workers,
        progress=a.progress,
        report=lambda i, res: f'  {bag_name(jobs[i].bag)}: {_summary(res)}',
    )
    for job, res in zip(jobs, results):
        for text in res.warnings:
            print(f'iemd-replay: warning: {bag_name(job.bag)}: {text}', file=sys.stderr)
    print(
        f'iemd-replay: {len(jobs)} bag(s) in {time.perf_counter() - t_start:.1f} s wall; results '
        f'in {a.out_dir}'
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        # from `ros2 run` / launch: the replay has no ROS arguments
        args, _ = split_ros_args(argv)
        a = build_parser().parse_args(args)
        cfg = PipelineConfig.from_yaml(a.config) if a.config else PipelineConfig()
        if a.time_offset_ms is not None:
            cfg = replace(
                cfg, gyro=replace(cfg.gyro, time_offset_ns=int(round(a.time_offset_ms * 1e6)))
            )
        camera = CameraModel.from_yaml(a.camera_yaml) if a.camera_yaml else None
        options = {
            'image_topic': a.image_topic,
            'imu_topic': a.imu_topic,
            'camera_info_topic': a.camera_info_topic,
            'config': cfg,
            'use_gyro': not a.no_gyro,
            'camera': camera,
        }
        return _one_bag(a, options) if a.out_dir is None else _batch(a, options)

    return cli_main('iemd-replay', body)


if __name__ == '__main__':
    sys.exit(main())
