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
Start-up of the installed package: node start -> first detection, and a 2-frame replay.

Time from starting the node to its first detection, and the whole run of ``iemd-replay`` on a
2-frame bag, with numba's cache empty (a fresh install without ``iemd-compile``) and full (after
it, as ``scripts/setup_venv.sh`` and ``setup.py install`` leave it), in the same run.

    .venv/bin/python benchmarks/startup.py [--runs 3]

The node is ``<venv>/lib/iemd_ros/tracker`` (what ``ros2 run iemd_ros tracker`` starts) with
``initial_box``; a driver node here publishes a synthetic 640x480 sequence at 30 Hz with IMU and
CameraInfo from the moment the process starts.  The cache is emptied by deleting the
``*.nbi``/``*.nbc`` files beside the installed package, and filled again at the end
(``iemd-compile``).
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np

PREFIX = Path(sys.prefix)


def _package_dir() -> Path:
    out = subprocess.run(
        [sys.executable, '-c', 'import iemd_ros, os; print(os.path.dirname(iemd_ros.__file__))'],
        capture_output=True,
        text=True,
        cwd='/',
        check=True,
    )
    return Path(out.stdout.strip())


def _empty_cache(package: Path) -> int:
    files = [p for p in package.rglob('__pycache__/*') if p.suffix in ('.nbi', '.nbc')]
    for p in files:
        p.unlink()
    return len(files)


def _first_detection(seq, timeout: float = 120.0) -> float:
    """Seconds from starting the tracker process to its first non-empty Detection2DArray."""
    from iemd_ros.messages.conversions import fill_image_msg, ns_to_stamp
    import rclpy
    from rclpy.qos import QoSProfile, QoSReliabilityPolicy
    from sensor_msgs.msg import CameraInfo, Image, Imu
    from vision_msgs.msg import Detection2DArray

    box = ','.join(f'{float(v)}' for v in seq.gt_boxes[0])
    cmd = [
        str(PREFIX / 'lib' / 'iemd_ros' / 'tracker'),
        '--ros-args',
        '-p',
        f'initial_box:=[{box}]',
        '-p',
        'reliable_qos:=true',
    ]
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node('iemd_startup_driver', context=context)
    qos = QoSProfile(depth=5, reliability=QoSReliabilityPolicy.RELIABLE)
    img_pub = node.create_publisher(Image, 'image', qos)
    imu_pub = node.create_publisher(
        Imu, 'imu', QoSProfile(depth=200, reliability=QoSReliabilityPolicy.RELIABLE)
    )
    info_pub = node.create_publisher(CameraInfo, 'camera_info', qos)
    first: list[float] = []
    node.create_subscription(
        Detection2DArray,
        'detections',
        lambda m: m.detections and not first and first.append(time.monotonic()),
        10,
    )
    ex = rclpy.executors.SingleThreadedExecutor(context=context)
    ex.add_node(node)
    th = threading.Thread(target=ex.spin, daemon=True)
    th.start()
    info = CameraInfo(
        width=seq.config.width, height=seq.config.height, distortion_model='plumb_bob'
    )
    info.k = [float(v) for v in seq.K.ravel()]
    info.d = [float(v) for v in seq.dist]
    frames = [fill_image_msg(Image(), f) for f in seq.frames]
    t_start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        k, gi = 0, 0
        while not first and time.monotonic() - t_start < timeout and proc.poll() is None:
            i = k % len(frames)
            t_cam = int(seq.frame_stamps_ns[0]) + k * int(1e9 / 30)
            # 240 Hz of the sequence's rates, on the frames' clock
            while gi < 8 * (k + 1):
                imu = Imu()
                imu.header.stamp.sec, imu.header.stamp.nanosec = ns_to_stamp(
                    t_cam - int(1e9 / 30) + gi % 8 * int(1e9 / 240)
                )
                imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = (
                    float(v) for v in seq.gyro[min(gi, len(seq.gyro) - 1)]
                )
                imu_pub.publish(imu)
                gi += 1
            info_pub.publish(info)
            msg = frames[i]
            msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_stamp(t_cam)
            img_pub.publish(msg)
            k += 1
            time.sleep(max(0.0, t_start + k / 30 - time.monotonic()))
    finally:
        proc.send_signal(2)
        try:
            proc.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
        ex.shutdown(timeout_sec=2.0)
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    return first[0] - t_start if first else float('nan')


def _replay_run(bag: Path, init: str) -> float:
    t = time.monotonic()
    subprocess.run(
        [
            str(PREFIX / 'bin' / 'iemd-replay'),
            str(bag),
            '--init',
            init,
            '--csv',
            str(bag) + '.csv',
        ],
        check=True,
        cwd='/',
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    return time.monotonic() - t


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument(
        '--runs', type=int, default=3, help='runs with the cache empty, and as many with it full'
    )
    a = ap.parse_args(argv)
    os.environ.setdefault('ROS_DOMAIN_ID', str(np.random.default_rng().integers(30, 100)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    from iemd_ros.bags.make import source_from_synthetic, write_bag
    from iemd_ros.datasets.synthetic import generate

    seq = generate(
        n_frames=30, width=640, height=480, max_rate_deg_s=30.0, target_size_px=64.0, seed=1
    )
    package = _package_dir()
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / 'two'
        write_bag(source_from_synthetic(generate(n_frames=2, width=640, height=480, seed=1)), bag)
        init = ','.join(
            f'{float(v)}' for v in generate(n_frames=2, width=640, height=480, seed=1).gt_boxes[0]
        )
        rows = {}
        for label, cold in (
            ('empty cache (fresh install, no iemd-compile)', True),
            ('full cache (after iemd-compile)', False),
        ):
            node_s, replay_s = [], []
            for _ in range(a.runs):
                if cold:
                    _empty_cache(package)
                node_s.append(_first_detection(seq))
                if cold:
                    _empty_cache(package)
                replay_s.append(_replay_run(bag, init))
            rows[label] = (node_s, replay_s)
    subprocess.run([str(PREFIX / 'bin' / 'iemd-compile')], check=True, cwd='/')
    print(
        f'{"numba cache":46s} {"node: start -> first detection, s":>36s} '
        f'{"iemd-replay 2 frames, whole run, s":>36s}'
    )
    for label, (node_s, replay_s) in rows.items():
        print(
            f'{label:46s} {" ".join(f"{v:5.1f}" for v in node_s):>36s} '
            f'{" ".join(f"{v:5.1f}" for v in replay_s):>36s}'
        )
    return 0


if __name__ == '__main__':
    sys.exit(main())
