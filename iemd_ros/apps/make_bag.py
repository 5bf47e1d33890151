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
``iemd-make-bag``: an image folder + IMU + calibration -> a bag.

The folder layouts: CMU desk/aerial, phone, OTB.

    iemd-make-bag SOURCE OUT [--format mcap|sqlite3|ros1] [--compress jpeg|png] [--first N]
                  [--count N] ...

What is written, stamps, clocks and frames: :mod:`iemd_ros.bags.make`.  Bad input prints one line
on stderr and exits with status 2.
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys

from iemd_ros.bags.io import FORMATS
from iemd_ros.bags.make import (
    CAMERA_FRAME,
    DEFAULT_TOPICS,
    ENCODINGS,
    IMU_FRAME,
    source_from_folder,
    write_bag,
)
from iemd_ros.common.cli import (
    cli_main,
    CliParser,
    finite_float,
    non_negative_float,
    positive_float,
)
from iemd_ros.common.progress import Progress
from iemd_ros.messages.conversions import COMPRESSED_CODECS, JPEG_QUALITY

__all__ = ['main', 'build_parser']


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(prog='iemd-make-bag', description=__doc__.split('\n\n')[0],
                  epilog='Stamps, clocks and frames: see `python -m pydoc iemd_ros.bags.make`.')
    p.add_argument(
        'source',
        type=Path,
        help='recording folder (CMU desk/aerial, phone), OTB sequence folder or image folder',
    )
    p.add_argument(
        'out', type=Path, help='output: rosbag2 folder (mcap/sqlite3) or FILE.bag (--format ros1)'
    )
    p.add_argument('--format', choices=FORMATS, default='mcap', help='bag format (default mcap)')
    p.add_argument(
        '--encoding', choices=ENCODINGS, default='bgr8', help='Image encoding (default bgr8)'
    )
    p.add_argument(
        '--compress',
        choices=COMPRESSED_CODECS,
        default=None,
        help='write sensor_msgs/CompressedImage (image_transport format) on '
        'IMAGE_TOPIC/compressed '
        'instead of raw Image (default: raw)',
    )
    p.add_argument(
        '--jpeg-quality',
        type=int,
        default=None,
        metavar='Q',
        help=f'JPEG quality 1..100 for --compress jpeg (default {JPEG_QUALITY})',
    )
    p.add_argument('--first', type=int, default=0, help='first frame (0-based, default 0)')
    p.add_argument(
        '--count', type=int, default=None, help='number of frames (default: to the end)'
    )
    p.add_argument(
        '--imu-margin',
        type=non_negative_float,
        default=0.5,
        metavar='S',
        help='keep IMU samples this many seconds around the frames (default 0.5)',
    )
    p.add_argument(
        '--fps',
        type=positive_float,
        default=None,
        help='frame rate for sources without stamps (default 30)',
    )
    p.add_argument(
        '--stamps',
        type=Path,
        default=None,
        help='image folder: frame times in seconds, one per line',
    )
    p.add_argument(
        '--imu-csv', type=Path, default=None, help='image folder: gyro log t_s,wx,wy,wz[,ax,ay,az]'
    )
    p.add_argument(
        '--camera-yaml',
        type=Path,
        default=None,
        help="ROS camera_info YAML (overrides the source's)",
    )
    p.add_argument(
        '--time-offset-ms',
        type=finite_float,
        default=None,
        help='image folder: t_imu = t_cam + offset (Kalibr); the IMU stamps are shifted by '
        '-offset',
    )
    p.add_argument('--image-topic', default=DEFAULT_TOPICS['image'])
    p.add_argument('--camera-info-topic', default=DEFAULT_TOPICS['camera_info'])
    p.add_argument('--imu-topic', default=DEFAULT_TOPICS['imu'])
    p.add_argument(
        '--frame-id', default=CAMERA_FRAME, help=f'camera frame_id (default {CAMERA_FRAME})'
    )
    p.add_argument(
        '--imu-frame-id',
        default=IMU_FRAME,
        help=f'IMU frame_id for --imu-csv (default {IMU_FRAME}); recordings with a camera-frame '
        'gyro use the camera frame_id',
    )
    p.add_argument(
        '--gt-out', type=Path, default=None, help="also write the frames' ground truth (OTB text)"
    )
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        a = build_parser().parse_args(argv)
        src = source_from_folder(
            a.source, a.fps, a.stamps, a.imu_csv, a.camera_yaml, a.time_offset_ms, a.imu_frame_id
        )
        n = (len(src) - a.first) if a.count is None else a.count
        bar = Progress(max(n, 0), 'iemd-make-bag')
        try:
            info = write_bag(
                src,
                a.out,
                a.format,
                a.encoding,
                a.first,
                a.count,
                a.imu_margin,
                {'image': a.image_topic, 'camera_info': a.camera_info_topic, 'imu': a.imu_topic},
                a.frame_id,
                a.gt_out,
                bar.update,
                a.compress,
                a.jpeg_quality,
            )
        finally:
            bar.close()
        print(
            f'iemd-make-bag: wrote {info["path"]} ({info["format"]}): {info["frames"]} images '
            f'{info["size"][0]}x{info["size"][1]} '
            f'{a.encoding}{f" {a.compress}" if a.compress else ""} on '
            f'{info["image_topic"]}, {info["imu"]} IMU samples '
            f'(shifted {info["imu_time_shift_ns"] / 1e6:+.1f} ms onto the camera clock), camera '
            'info '
            f'{"yes" if info["camera_info"] else "no"}'
            + (f'; ground truth -> {a.gt_out}' if a.gt_out else '')
        )
        return 0

    return cli_main('iemd-make-bag', body)


if __name__ == '__main__':
    sys.exit(main())
