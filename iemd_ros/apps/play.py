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
``iemd-play``: publish a bag onto ROS 2 topics with its original timing, like ``ros2 bag play``.

    iemd-play BAG [--rate R] [--topics T ...] [--remap FROM:=TO ...] [--delay S]
              [--wait-subscribers S] [--clock] [--ros-args ...]

What it publishes and how: :mod:`iemd_ros.ros.play`.  Bad input prints one line on stderr and exits
with status 2.
"""
from __future__ import annotations

import argparse
from pathlib import Path
import sys

from iemd_ros.common.cli import (
    cli_main,
    CliParser,
    non_negative_float,
    positive_float,
    split_ros_args,
)
from iemd_ros.ros.play import parse_remaps, play

__all__ = ['main', 'build_parser']


def build_parser() -> argparse.ArgumentParser:
    p = CliParser(prog='iemd-play', description=__doc__.split('\n\n')[0])
    p.add_argument('bag', type=Path, help='rosbag2 folder (sqlite3/mcap) or ROS 1 .bag file')
    p.add_argument(
        '--rate', type=positive_float, default=1.0, help='playback rate factor (default 1.0)'
    )
    p.add_argument('--topics', nargs='+', default=None, help='play only these topics')
    p.add_argument(
        '--remap', action='append', default=[], metavar='FROM:=TO', help='publish FROM under TO'
    )
    p.add_argument(
        '--delay',
        type=non_negative_float,
        default=0.0,
        metavar='S',
        help='sleep S seconds before playing',
    )
    p.add_argument(
        '--wait-subscribers',
        type=non_negative_float,
        default=0.0,
        metavar='S',
        help='wait up to S seconds until every topic has a subscriber',
    )
    p.add_argument('--clock', action='store_true', help='also publish /clock with the log times')
    p.add_argument(
        '--qos-depth', type=int, default=100, help='publisher queue depth (default 100)'
    )
    p.add_argument(
        '--progress',
        action=argparse.BooleanOptionalAction,
        default=None,
        help='progress bar on stderr (default: when stderr is a terminal)',
    )
    return p


def main(argv: list[str] | None = None) -> int:
    def body() -> int:
        args, ros_args = split_ros_args(argv)
        a = build_parser().parse_args(args)
        stats = play(
            a.bag,
            a.rate,
            a.topics,
            parse_remaps(a.remap),
            a.delay,
            a.wait_subscribers,
            a.clock,
            a.qos_depth,
            progress=a.progress,
            ros_args=ros_args,
        )
        n = sum(stats.published.values())
        print(
            f'iemd-play: published {n} messages on {len(stats.published)} topics: '
            f'{stats.bag_s:.2f} s of bag in '
            f'{stats.wall_s:.2f} s wall (rate {a.rate:g}); late by {stats.mean_late_ms:.2f} ms on '
            'average, '
            f'{stats.max_late_ms:.1f} ms at most'
        )
        return 0

    return cli_main('iemd-play', body)


if __name__ == '__main__':
    sys.exit(main())
