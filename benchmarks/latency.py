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
Image-in to detection-out latency of the tracker node (p50 / p95), 640x480 at 30 Hz.

    .venv/bin/python benchmarks/latency.py [--frames 150] [--rate 30] [--width 640 --height 480]
                                           [--targets 3]

A driver node publishes a synthetic shaky-camera sequence (bgr8 frames, IMU at 200 Hz, CameraInfo)
with sensor-data QoS, as a camera driver would, and times each frame from just before ``publish``
to the arrival of the Detection2DArray carrying its stamp (both on the driver's clock).  Setups:

* ``inproc``: tracker node and driver in one process (one DDS participant);
* ``process``: the tracker as its own process (``python -m iemd_ros.ros.node``), default transport;
* ``process-shm``: the same with ``config/fastdds_shm.xml`` (FASTRTPS_DEFAULT_PROFILES_FILE) in
  both;
* ``process-jpeg``: the tracker process with ``image_transport`` "compressed", the frames published
  as JPEG (quality 95) CompressedImage on ``image/compressed``; its latency includes the decoding
  ("track ms" is the tracker alone; docs/decisions.md#transport-profile).

Peer, measured in the same run and setup: an echo node that answers each image with an empty
Detection2DArray at once (transport + rclpy overhead only).  Frames the tracker drops as stale (it
keeps up with the newest frame) get no answer: "answered" is the fraction of published frames with
a detection array, "delivered" the fraction that reached the node, "processed" and "dropped" the
tracker's own counts (from its /diagnostics counters).  ``--rate 60`` gives more frames than the
tracker can process.  ``--targets 3``: the tracker follows the target and two more regions of the
scene beside it, added through ``~/init`` with ids after the first frame; "targets" is the smallest
number of detections in the arrays timed (frames from the fourth on).
"""
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import subprocess
import sys
import threading
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHM_PROFILE = ROOT / 'config' / 'fastdds_shm.xml'


def _qos(reliable: bool):
    """
    Return the image QoS of a run.

    reliable, or sensor-data (best effort) like a camera driver.
    """
    from rclpy.qos import qos_profile_sensor_data, QoSProfile, QoSReliabilityPolicy

    return (
        QoSProfile(depth=5, reliability=QoSReliabilityPolicy.RELIABLE)
        if reliable
        else qos_profile_sensor_data
    )


def _add_echo(node, reliable: bool, compressed: bool) -> None:
    """
    Make ``node`` answer every image.

    (CompressedImage if ``compressed``, not decoded) with an empty Detection2DArray (header
    copied).
    """
    from iemd_ros.messages.conversions import compressed_topic
    from sensor_msgs.msg import CompressedImage, Image
    from vision_msgs.msg import Detection2DArray

    pub = node.create_publisher(Detection2DArray, 'detections', 10)

    def on_image(msg):
        out = Detection2DArray()
        out.header = msg.header
        pub.publish(out)

    if compressed:
        node.create_subscription(
            CompressedImage, compressed_topic('image'), on_image, _qos(reliable)
        )
    else:
        node.create_subscription(Image, 'image', on_image, _qos(reliable))


def _echo_main(reliable: bool, compressed: bool) -> int:
    """--serve-echo: the echo as its own process."""
    from iemd_ros.ros.spin import spin_until_shutdown
    import rclpy

    rclpy.init()
    node = rclpy.create_node('iemd_echo')
    _add_echo(node, reliable, compressed)
    spin_until_shutdown(node)
    return 0


def _run(args, seq, setup: str, subject: str) -> dict:
    from diagnostic_msgs.msg import DiagnosticArray
    from iemd_ros.messages.conversions import (
        array_to_compressed_fields,
        box_to_bbox,
        compressed_topic,
        fill_bbox,
        fill_image_msg,
        ns_to_stamp,
        stamp_ns,
    )
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rclpy.qos import QoSProfile
    from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu
    from vision_msgs.msg import Detection2D, Detection2DArray

    env = dict(os.environ)  # the caller set FASTRTPS_DEFAULT_PROFILES_FILE for -shm
    box0 = [float(v) for v in seq.gt_boxes[0]]
    compressed = setup.endswith('-jpeg')  # JPEG CompressedImage on image/compressed
    params = {
        'initial_box': box0,
        'reliable_qos': args.reliable,
        'diagnostics_period_s': 0.2,
        'image_transport': 'compressed' if compressed else 'raw',
    }
    context = rclpy.Context()
    rclpy.init(context=context)
    proc = None
    nodes = []
    try:
        if setup == 'inproc':
            if subject == 'tracker':
                from iemd_ros.ros.node import TrackerNode

                nodes.append(
                    TrackerNode(
                        context=context,
                        parameter_overrides=[Parameter(k, value=v) for k, v in params.items()],
                    )
                )
            else:
                echo = rclpy.create_node('iemd_echo', context=context)
                _add_echo(echo, args.reliable, compressed)
                nodes.append(echo)
        else:
            if subject == 'tracker':
                cmd = [sys.executable, '-m', 'iemd_ros.ros.node', '--ros-args']
                for k, v in params.items():
                    cmd += ['-p', f'{k}:={str(v).lower() if isinstance(v, bool) else v}']
            else:
                cmd = (
                    [sys.executable, __file__, '--serve-echo']
                    + (['--reliable'] if args.reliable else [])
                    + (['--compressed'] if compressed else [])
                )
            proc = subprocess.Popen(
                cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
            )

        drv = rclpy.create_node('iemd_latency_driver', context=context)
        qos = _qos(args.reliable)
        img_pub = (
            drv.create_publisher(CompressedImage, compressed_topic('image'), qos)
            if compressed
            else drv.create_publisher(Image, 'image', qos)
        )
        imu_pub = drv.create_publisher(
            Imu, 'imu', QoSProfile(depth=200, reliability=qos.reliability)
        )
        info_pub = drv.create_publisher(CameraInfo, 'camera_info', qos)
        init_pub = drv.create_publisher(Detection2D, '/iemd_tracker/init', 10)
        sent: dict[int, int] = {}
        got: dict[int, int] = {}
        counts: dict[int, int] = {}
        diag: dict = {}
        lock = threading.Lock()

        def on_det(msg):
            t = time.perf_counter_ns()
            with lock:
                got.setdefault(stamp_ns(msg.header), t)
                counts.setdefault(stamp_ns(msg.header), len(msg.detections))

        def on_diag(msg):
            for st in msg.status:
                if st.name.endswith(': image input'):
                    diag.update({kv.key: kv.value for kv in st.values})
                if st.name.endswith(': tracking'):
                    diag.update({'tracking.' + kv.key: kv.value for kv in st.values})

        drv.create_subscription(Detection2DArray, 'detections', on_det, 50)
        drv.create_subscription(DiagnosticArray, '/diagnostics', on_diag, 50)
        ex = SingleThreadedExecutor(context=context)
        for n in [drv, *nodes]:
            ex.add_node(n)
        th = threading.Thread(target=ex.spin, daemon=True)
        th.start()

        deadline = time.monotonic() + 30
        while (
            img_pub.get_subscription_count() == 0 or drv.count_publishers('detections') == 0
        ) and time.monotonic() < deadline:
            time.sleep(0.05)
        if img_pub.get_subscription_count() == 0:
            raise RuntimeError(f'{setup}/{subject}: subject not discovered within 30 s')
        time.sleep(0.5)

        info = CameraInfo()
        info.width, info.height = seq.config.width, seq.config.height
        info.k = [float(v) for v in seq.K.ravel()]
        info.d = [float(v) for v in seq.dist]
        info.distortion_model = 'plumb_bob'
        msgs = []
        for k, frame in enumerate(seq.frames):
            m = (
                CompressedImage(**array_to_compressed_fields(frame, 'jpeg'))
                if compressed
                else fill_image_msg(Image(), frame)
            )
            m.header.frame_id = 'cam'
            m.header.stamp.sec, m.header.stamp.nanosec = ns_to_stamp(int(seq.frame_stamps_ns[k]))
            msgs.append(m)
        gi = 0
        t0 = time.monotonic()
        for k, m in enumerate(msgs):
            # the other targets, on the first frame (~/init by stamp)
            if k == 1 and subject == 'tracker':
                x, y, w, h = box0
                for j, box in enumerate(
                    [(x - 1.6 * w, y, w, h), (x, y + 1.4 * h, w, h)][: args.targets - 1]
                ):
                    det = Detection2D(id=f'target{j + 2}')
                    det.header.stamp.sec, det.header.stamp.nanosec = ns_to_stamp(
                        int(seq.frame_stamps_ns[0])
                    )
                    fill_bbox(det.bbox, box_to_bbox(box))
                    init_pub.publish(det)
            time.sleep(max(0.0, t0 + k / args.rate - time.monotonic()))
            t_cam = int(seq.frame_stamps_ns[k])
            while gi < len(seq.gyro_t_ns) and seq.gyro_t_ns[gi] <= t_cam + 5_000_000:
                imu = Imu()
                imu.header.stamp.sec, imu.header.stamp.nanosec = ns_to_stamp(
                    int(seq.gyro_t_ns[gi])
                )
                imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = (
                    float(v) for v in seq.gyro[gi]
                )
                imu_pub.publish(imu)
                gi += 1
            info_pub.publish(info)  # with every frame, as camera drivers do
            sent[t_cam] = time.perf_counter_ns()
            img_pub.publish(m)
        time.sleep(1.5)
        ex.shutdown(timeout_sec=2.0)
        th.join(timeout=5)
    finally:
        for n in nodes:
            n.destroy_node()
        rclpy.try_shutdown(context=context)
        if proc is not None:
            proc.send_signal(2)
            try:
                proc.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
    first = int(seq.frame_stamps_ns[3])  # frame 0 initializes, the other targets join on frame 1
    lat = np.array([(got[s] - t) / 1e6 for s, t in sent.items() if s in got and s >= first])
    n = sum(1 for s in sent if s >= first)
    delivered = (
        (int(diag['frames_received']) / len(sent)) if 'frames_received' in diag else float('nan')
    )
    if subject == 'echo':
        delivered = (len(lat) + (1 if int(seq.frame_stamps_ns[0]) in got else 0)) / len(sent)
    return {
        'setup': setup,
        'subject': subject,
        'answered': len(lat) / n,
        'delivered': delivered,
        'p50': float(np.percentile(lat, 50)) if len(lat) else float('nan'),
        'p95': float(np.percentile(lat, 95)) if len(lat) else float('nan'),
        'proc': float(diag.get('tracking.processing_ms_mean', 'nan')),
        'sent': len(sent),
        'targets': min((c for s, c in counts.items() if s >= first), default=0),
        'processed': int(diag.get('frames_processed', -1)),
        'dropped': int(diag.get('frames_dropped', -1)),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--frames', type=int, default=150, help='frames published per measurement')
    ap.add_argument('--rate', type=float, default=30.0, help='input rate, Hz')
    ap.add_argument('--width', type=int, default=640, help='frame width, px')
    ap.add_argument('--height', type=int, default=480, help='frame height, px')
    ap.add_argument(
        '--setups',
        default='inproc,process,process-shm,process-jpeg',
        help='comma-separated: inproc, process, process-shm, process-jpeg',
    )
    ap.add_argument(
        '--subjects', default='echo,tracker', help='comma-separated: echo (the reference), tracker'
    )
    ap.add_argument(
        '--targets', type=int, default=1, choices=(1, 2, 3), help='targets the tracker follows'
    )
    ap.add_argument(
        '--reliable', action='store_true', help='reliable QoS instead of sensor-data (best effort)'
    )
    ap.add_argument('--serve-echo', action='store_true', help=argparse.SUPPRESS)
    ap.add_argument('--compressed', action='store_true', help=argparse.SUPPRESS)
    ap.add_argument('--measure', nargs=2, metavar=('SETUP', 'SUBJECT'), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.serve_echo:
        return _echo_main(args.reliable, args.compressed)
    if args.measure:
        from iemd_ros.datasets.synthetic import generate

        seq = generate(
            n_frames=args.frames,
            width=args.width,
            height=args.height,
            max_rate_deg_s=60.0,
            target_size_px=64.0,
            seed=1,
        )
        print('RESULT ' + json.dumps(_run(args, seq, *args.measure)))
        return 0
    # an isolated DDS domain on this host only (the subject processes inherit it)
    os.environ.setdefault('ROS_DOMAIN_ID', str(np.random.default_rng().integers(30, 100)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    print(
        f'{args.frames} frames {args.width}x{args.height} bgr8 at {args.rate:.0f} Hz, '
        f'{"reliable" if args.reliable else "sensor-data (best effort)"} QoS'
    )
    print(
        f'{"setup":12s} {"subject":8s} {"delivered":>9s} {"answered":>8s} {"p50 ms":>7s} '
        f'{"p95 ms":>7s} '
        f'{"track ms":>8s} {"sent":>5s} {"processed":>9s} {"dropped":>7s} {"targets":>7s}'
    )
    rows = []
    for setup in args.setups.split(','):
        for subject in args.subjects.split(','):
            # a fresh driver process per measurement: Fast DDS reads its XML profile once per
            # process
            env = dict(os.environ)
            if setup == 'process-shm':
                env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(SHM_PROFILE)
            cmd = [
                sys.executable,
                __file__,
                '--measure',
                setup,
                subject,
                '--frames',
                str(args.frames),
                '--rate',
                str(args.rate),
                '--width',
                str(args.width),
                '--height',
                str(args.height),
                '--targets',
                str(args.targets),
            ]
            out = subprocess.run(
                cmd + (['--reliable'] if args.reliable else []),
                env=env,
                capture_output=True,
                text=True,
                timeout=600,
            )
            lines = [ln for ln in out.stdout.splitlines() if ln.startswith('RESULT ')]
            if not lines:
                print(f'{setup}/{subject} failed:\n{out.stderr[-2000:]}', file=sys.stderr)
                return 1
            r = json.loads(lines[-1][7:])
            rows.append(r)
            counted = (
                f'{r["processed"]:9d} {r["dropped"]:7d} {r["targets"]:7d}'
                if subject == 'tracker'
                else f'{"":9s} {"":7s} {"":7s}'
            )
            print(
                f'{setup:12s} {subject:8s} {r["delivered"]:9.0%} {r["answered"]:8.0%} '
                f'{r["p50"]:7.1f} '
                f'{r["p95"]:7.1f} {r["proc"]:8.1f} {r["sent"]:5d} {counted}',
                flush=True,
            )
    for setup in args.setups.split(','):
        pair = {r['subject']: r for r in rows if r['setup'] == setup}
        if len(pair) < 2:
            continue
        e, t = pair['echo'], pair['tracker']
        print(
            f'{setup}: tracker p95 / echo p95 = {t["p95"] / e["p95"]:.1f}; tracker p95 minus its '
            'mean '
            f'processing time = {t["p95"] - t["proc"]:.1f} ms'
        )
    return 0


if __name__ == '__main__':
    sys.exit(main())
