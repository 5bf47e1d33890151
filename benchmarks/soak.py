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
Bounded soak of the tracker node as its own process.

RSS and CPU time sampled over a run of fixed length, and the RSS's slope.

    .venv/bin/python benchmarks/soak.py [--minutes 30] [--rate 30] [--width 640 --height 480]
                                        [--sample-s 10]

The tracker runs as ``python -m iemd_ros.ros.node`` (the installed package unless PYTHONPATH says
otherwise) on an isolated DDS domain on this host; this process publishes a synthetic shaky-camera
sequence over and over (bgr8 frames with increasing stamps, IMU at 200 Hz, CameraInfo with every
frame, sensor-data QoS, over ``config/fastdds_shm.xml`` unless ``--default-transport``), restarting
the target with ``~/init`` at each pass.  Every ``--sample-s`` seconds it reads the tracker's RSS
(``/proc/<pid>/status``) and CPU time (user and system, ``/proc/<pid>/stat``), the frames
answered, and the tracker's own counts and worst status (tracking, image input) from
/diagnostics.  It prints the RSS at the start, after 1 minute and at the end, the slope of a
least-squares line through the samples after the first minute and through those of the second
half (MB per hour), and the tracker's CPU use after the first minute (CPU time over wall time, %
of one core).  It stops by itself after ``--minutes`` and stops the tracker with SIGINT.  The
tracker's log goes to ``--log`` or is discarded: never to a pipe nobody reads, where it would block
the tracker once the pipe is full.
"""
from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np


def rss_mb(pid: int) -> float:
    """Resident set size of the process ``pid``, MB (``VmRSS`` of ``/proc/<pid>/status``)."""
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError(f'no VmRSS for process {pid}')


def cpu_s(pid: int) -> float:
    """User and system CPU time of the process ``pid`` (all its threads) so far, s."""
    with open(f'/proc/{pid}/stat') as f:
        # the fields after the command name (which may hold spaces), from field 3 (state) on
        fields = f.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def slope_mb_per_hour(t_s, rss) -> float:
    """
    Slope of the least-squares line through (t_s, rss).

    MB per hour (nan with fewer than two samples).
    """
    if len(t_s) < 2:
        return float('nan')
    return float(np.polyfit(np.asarray(t_s) / 3600.0, np.asarray(rss), 1)[0])


def main(argv=None) -> int:
    """Run the soak; return the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.strip().split('\n')[0])
    ap.add_argument('--minutes', type=float, default=30.0, help='length of the soak, min')
    ap.add_argument('--rate', type=float, default=30.0, help='input rate, Hz')
    ap.add_argument('--width', type=int, default=640, help='frame width, px')
    ap.add_argument('--height', type=int, default=480, help='frame height, px')
    ap.add_argument(
        '--frames', type=int, default=150, help='frames of the sequence played over and over'
    )
    ap.add_argument('--sample-s', type=float, default=10.0, help='interval between samples, s')
    ap.add_argument('--log', default=None, help="file for the tracker's log (default: discarded)")
    ap.add_argument(
        '--default-transport',
        action='store_true',
        help="Fast DDS's default transport instead of config/fastdds_shm.xml "
        '(docs/node.md#transport)',
    )
    args = ap.parse_args(argv)
    # read once per process, before rclpy starts; the tracker inherits it
    if not args.default_transport:
        os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'] = os.path.join(
            os.path.dirname(os.path.abspath(__file__)), '..', 'config', 'fastdds_shm.xml'
        )
    os.environ.setdefault('ROS_DOMAIN_ID', str(np.random.default_rng().integers(30, 100)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

    from diagnostic_msgs.msg import DiagnosticArray
    from iemd_ros.datasets.synthetic import generate
    from iemd_ros.messages.conversions import box_to_bbox, fill_bbox, fill_image_msg, ns_to_stamp
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import qos_profile_sensor_data, QoSProfile
    from sensor_msgs.msg import CameraInfo, Image, Imu
    from vision_msgs.msg import Detection2D, Detection2DArray

    seq = generate(
        n_frames=args.frames,
        width=args.width,
        height=args.height,
        max_rate_deg_s=60.0,
        target_size_px=64.0,
        seed=1,
    )
    log = open(args.log, 'w') if args.log else subprocess.DEVNULL
    proc = subprocess.Popen(
        [
            sys.executable,
            '-m',
            'iemd_ros.ros.node',
            '--ros-args',
            '-p',
            'diagnostics_period_s:=1.0',
        ],
        stdout=log,
        stderr=log,
        text=True,
    )
    rclpy.init()
    node = rclpy.create_node('iemd_soak_driver')
    img_pub = node.create_publisher(Image, 'image', qos_profile_sensor_data)
    imu_pub = node.create_publisher(
        Imu, 'imu', QoSProfile(depth=200, reliability=qos_profile_sensor_data.reliability)
    )
    info_pub = node.create_publisher(CameraInfo, 'camera_info', qos_profile_sensor_data)
    init_pub = node.create_publisher(Detection2D, '/iemd_tracker/init', 10)
    counts = {'answered': 0, 'detected': 0}
    lock = threading.Lock()

    def on_det(msg):
        with lock:
            counts['answered'] += 1
            counts['detected'] += bool(msg.detections)

    node.create_subscription(Detection2DArray, 'detections', on_det, 50)
    diag: dict = {}

    def on_diag(msg):  # the tracker's own counts and its worst status
        with lock:
            for st in msg.status:
                part = st.name.split(': ', 1)[-1]
                diag[part] = (
                    st.level[0] if isinstance(st.level, bytes) else int(st.level),
                    st.message,
                )
                diag.update({kv.key: kv.value for kv in st.values if kv.key.startswith('frames_')})

    node.create_subscription(DiagnosticArray, '/diagnostics', on_diag, 10)
    ex = SingleThreadedExecutor()
    ex.add_node(node)
    spin = threading.Thread(target=ex.spin, daemon=True)
    spin.start()
    try:
        deadline = time.monotonic() + 60
        while (
            img_pub.get_subscription_count() == 0 or init_pub.get_subscription_count() == 0
        ) and time.monotonic() < deadline:
            time.sleep(0.1)
        if img_pub.get_subscription_count() == 0:
            raise RuntimeError('the tracker did not show up on DDS within 60 s')
        time.sleep(1.0)
        info = CameraInfo()
        info.width, info.height = args.width, args.height
        info.k = [float(v) for v in seq.K.ravel()]
        info.d = [float(v) for v in seq.dist]
        info.distortion_model = 'plumb_bob'
        frames = [fill_image_msg(Image(), f) for f in seq.frames]
        stamps = np.asarray(seq.frame_stamps_ns, dtype=np.int64)
        period = int(stamps[-1] - stamps[0]) + int(np.median(np.diff(stamps)))
        gyro_t = np.asarray(seq.gyro_t_ns, dtype=np.int64)
        print(
            f'soak: {args.minutes:g} min, {args.width}x{args.height} bgr8 at {args.rate:g} Hz, '
            'tracker pid '
            f'{proc.pid}; RSS every {args.sample_s:g} s',
            flush=True,
        )

        # (s since the start, RSS MB, answered, with a detection, CPU s), taken under the lock
        def sample(t_s: float) -> tuple[float, float, int, int, float]:
            return t_s, rss_mb(proc.pid), counts['answered'], counts['detected'], cpu_s(proc.pid)

        samples: list[tuple[float, float, int, int, float]] = []
        t0 = time.monotonic()
        end = t0 + args.minutes * 60.0
        n, gi, next_sample = 0, 0, t0
        while time.monotonic() < end and proc.poll() is None:
            k, loop = n % len(frames), n // len(frames)
            time.sleep(max(0.0, t0 + n / args.rate - time.monotonic()))
            offset = loop * period
            t_cam = int(stamps[k]) + offset
            if k == 0:
                gi = 0
            while gi < len(gyro_t) and gyro_t[gi] <= stamps[k] + 5_000_000:
                imu = Imu()
                imu.header.stamp.sec, imu.header.stamp.nanosec = ns_to_stamp(
                    int(gyro_t[gi]) + offset
                )
                imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = (
                    float(v) for v in seq.gyro[gi]
                )
                imu_pub.publish(imu)
                gi += 1
            msg = frames[k]
            msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_stamp(t_cam)
            info_pub.publish(info)
            img_pub.publish(msg)
            if k == 0:  # each pass restarts the target on its first frame
                init = Detection2D()
                init.header.stamp.sec, init.header.stamp.nanosec = ns_to_stamp(t_cam)
                fill_bbox(init.bbox, box_to_bbox(seq.gt_boxes[0]))
                init_pub.publish(init)
            n += 1
            now = time.monotonic()
            if now >= next_sample:
                with lock:
                    samples.append(sample(now - t0))
                    worst = max(diag.get(p, (0, '')) for p in ('tracking', 'image input'))
                    seen = {
                        k: diag.get(f'frames_{k}', '?')
                        for k in ('received', 'processed', 'dropped')
                    }
                next_sample += args.sample_s
                s = samples[-1]
                cpu = (
                    (s[4] - samples[-2][4]) / (s[0] - samples[-2][0])
                    if len(samples) > 1
                    else float('nan')
                )
                print(
                    f'  {s[0] / 60:6.2f} min  RSS {s[1]:7.1f} MB  CPU {cpu:6.1%}  sent {n}  '
                    f'answered {s[2]}  with a detection {s[3]}  tracker: received '
                    f'{seen["received"]} processed {seen["processed"]} dropped {seen["dropped"]}, '
                    f'level {worst[0]} {worst[1][:80]}',
                    flush=True,
                )
        if proc.poll() is not None:
            print(f'soak: the tracker exited early with status {proc.returncode}', file=sys.stderr)
            return 1
        with lock:
            samples.append(sample(time.monotonic() - t0))
    finally:
        ex.shutdown(timeout_sec=2.0)
        node.destroy_node()
        rclpy.try_shutdown()
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
    t = np.array([s[0] for s in samples])
    rss = np.array([s[1] for s in samples])
    cpu = np.array([s[4] for s in samples])
    one = int(np.argmin(np.abs(t - 60.0)))
    later = t >= 60.0
    last = samples[-1]
    half = t >= t[-1] / 2
    print(
        f'RSS start {rss[0]:.1f} MB, after 1 min {rss[one]:.1f} MB ({t[one] / 60:.2f} min), at '
        'the end '
        f'{rss[-1]:.1f} MB ({t[-1] / 60:.2f} min); slope after the first minute '
        f'{slope_mb_per_hour(t[later], rss[later]):+.2f} MB/h, over the second half '
        f'{slope_mb_per_hour(t[half], rss[half]):+.2f} MB/h'
    )
    if t[-1] > t[one]:
        used, span = cpu[-1] - cpu[one], t[-1] - t[one]
        print(
            f'tracker CPU after the first minute: {used / span:.1%} of one core '
            f'({used:.1f} s in {span:.1f} s)'
        )
    print(
        f'frames sent {n}, answered {last[2]} ({last[2] / max(n, 1):.1%}), with a detection '
        f'{last[3]} '
        f'({last[3] / max(n, 1):.1%}); tracker exit status {proc.returncode}'
    )
    return 0


if __name__ == '__main__':
    sys.exit(main())
