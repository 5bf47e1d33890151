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
The installed executable, as ``ros2 run iemd_ros tracker`` resolves it.

Package prefix through ament_index_python, then ``<prefix>/lib/iemd_ros/tracker``; run as its own
process with the shipped params file, driven over DDS, stopped with SIGINT.
"""
import os
from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
pytest.importorskip('vision_msgs.msg')
from ament_index_python.packages import (  # noqa: E402, I100
    get_package_prefix,
    PackageNotFoundError,
)
from iemd_ros.datasets.synthetic import generate  # noqa: E402
from iemd_ros.messages.conversions import bbox_values, stamp_ns  # noqa: E402
from ros_harness import child_env, Driver, isolated_ros_env, ros_context, spinning  # noqa: E402


def _prefix_env() -> dict:
    """
    Return the environment ``ros2 run`` would see.

    A ROS/colcon set-up has the prefix on AMENT_PREFIX_PATH already; the pip-only set-up installs
    into this interpreter's prefix (the venv), which the README adds to AMENT_PREFIX_PATH -- do the
    same here when it is missing.
    """
    env = dict(os.environ)
    paths = [p for p in env.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    marker = (
        Path(sys.prefix) / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'iemd_ros'
    )
    if marker.exists() and sys.prefix not in paths:
        paths.append(sys.prefix)
    env['AMENT_PREFIX_PATH'] = os.pathsep.join(paths)
    return env


@pytest.fixture(scope='module')
def executable():
    env = _prefix_env()
    saved = os.environ.get('AMENT_PREFIX_PATH')
    os.environ['AMENT_PREFIX_PATH'] = env['AMENT_PREFIX_PATH']
    try:
        prefix = Path(get_package_prefix('iemd_ros'))
    except (PackageNotFoundError, OSError) as exc:
        pytest.fail(
            f'iemd_ros is not installed in an ament prefix ({exc}); run `make venv` or colcon '
            'build'
        )
    finally:
        if saved is None:
            os.environ.pop('AMENT_PREFIX_PATH', None)
        else:
            os.environ['AMENT_PREFIX_PATH'] = saved
    exe = prefix / 'lib' / 'iemd_ros' / 'tracker'
    params = prefix / 'share' / 'iemd_ros' / 'config' / 'tracker.yaml'
    assert exe.is_file() and os.access(exe, os.X_OK), f'{exe} missing or not executable'
    assert params.is_file(), f'{params} missing'
    return exe, params, env


def test_launch_file_is_installed_in_the_share_folder(executable):
    exe, params, _ = executable
    # $(find-pkg-share iemd_ros)/launch
    installed = params.parents[1] / 'launch' / 'tracker.launch.xml'
    assert installed.is_file(), (
        f'{installed} missing: `ros2 launch iemd_ros tracker.launch.xml` would not find it'
    )
    assert (
        installed.read_text()
        == (Path(__file__).resolve().parents[1] / 'launch' / 'tracker.launch.xml').read_text()
    )


def _start(exe, args, env):
    return subprocess.Popen(
        [str(exe), *args], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def test_invalid_parameter_exits_2_with_one_line(executable):
    exe, params, env = executable
    with isolated_ros_env():
        proc = subprocess.run(
            [str(exe), '--ros-args', '--params-file', str(params), '-p', 'tracker.step_px:=0.1'],
            env=child_env(env),
            capture_output=True,
            text=True,
            timeout=60,
        )
    assert proc.returncode == 2, proc.stderr
    assert 'Traceback' not in proc.stderr
    assert (
        'invalid parameters: tracker.min_step_px (0.5) must not exceed step_px (0.1)'
        in proc.stderr
    )


def test_installed_executable_tracks_over_dds_and_stops_on_sigint(executable, stop_process):
    exe, params, env = executable
    seq = generate(n_frames=20, max_rate_deg_s=60.0, seed=5)
    s = [int(v) for v in seq.frame_stamps_ns]
    box0 = ','.join(f'{v:.3f}' for v in seq.gt_boxes[0])
    with ros_context() as context:  # isolated domain, localhost-only discovery
        env = child_env(env)
        proc = _start(
            exe,
            [
                '--ros-args',
                '--params-file',
                str(params),
                '-r',
                'image:=/cam/image_raw',
                '-p',
                f'initial_box:=[{box0}]',
                '-p',
                'diagnostics_period_s:=0.2',
                '-p',
                'imu_wait_ms:=200.0',
            ],
            env,
        )
        try:
            # sensor-data QoS, as a camera
            drv = Driver(context, image_topic='/cam/image_raw', reliable=False)
            with spinning(context, drv.node):
                assert drv.wait_connected(30.0), (
                    'the tracker process did not show up on DDS within 30 s'
                )
                sent = 0
                for k in range(len(s)):
                    # seq.time_offset_ns is 0 here
                    sent = drv.publish_imu_until(seq, s[k], sent)
                    # lock-step: each frame is answered before the next; best effort may lose a
                    # frame, so send it again (a repeat of a frame already processed is rejected,
                    # harmless)
                    for _ in range(3):
                        drv.publish_camera_info(seq)  # with every frame, as camera drivers do
                        drv.publish_image(seq.frames[k], s[k])
                        if drv.wait_for(
                            lambda k=k: any(stamp_ns(d.header) == s[k] for d in drv.detections),
                            2.0,
                        ):
                            break
                dets = [d for d in drv.detections_since(0) if d.detections]
                assert len(dets) >= len(s) // 2, f'only {len(dets)} detections for {len(s)} frames'
                for arr in dets:
                    k = s.index(stamp_ns(arr.header))
                    cx, cy, _, _ = bbox_values(arr.detections[0].bbox)
                    assert np.hypot(cx - seq.gt_centres[k][0], cy - seq.gt_centres[k][1]) < 3.0
                st = drv.wait_status('imu', lambda x: True, 5.0)
                assert st is not None and 'gyro prior used' in st.message, st and st.message
        finally:
            drv.node.destroy_node()
            out, err, stopped = stop_process(proc)
            if not stopped:
                pytest.fail(f'tracker did not stop within 15 s of SIGINT; stderr:\n{err}')
    assert proc.returncode == 0, err
    assert 'Traceback' not in err + out, err
    assert "tracking '/cam/image_raw' -> '/detections'" in err + out


@pytest.mark.parametrize('signal_name', ['SIGTERM', 'SIGINT'])
def test_a_signal_during_a_60hz_burst_exits_0_without_a_traceback(executable, signal_name):
    """
    A signal during a 60 Hz burst: exit 0, no traceback (docs/decisions.md#node-soak).

    Three runs per signal, each stopped at another moment of the burst, the signal sent again 50 ms
    later (a second Ctrl-C, or launch's SIGTERM after its SIGINT) while the node is being taken
    down.
    """
    import signal
    import time

    exe, params, env = executable
    seq = generate(n_frames=30, max_rate_deg_s=60.0, seed=6)
    box0 = ','.join(f'{v:.3f}' for v in seq.gt_boxes[0])
    rng = np.random.default_rng(28)
    with ros_context() as context:
        env = child_env(env)
        for delay in rng.uniform(0.05, 0.45, 3):
            proc = _start(
                exe,
                ['--ros-args', '--params-file', str(params), '-p', f'initial_box:=[{box0}]'],
                env,
            )
            drv = Driver(context, reliable=False)
            try:
                with spinning(context, drv.node):
                    assert drv.wait_connected(30.0), (
                        'the tracker process did not show up on DDS within 30 s'
                    )
                    t0 = time.monotonic()
                    signals = [delay, delay + 0.05]
                    for k in range(len(seq.frames)):
                        time.sleep(max(0.0, t0 + k / 60.0 - time.monotonic()))
                        drv.publish_image(seq.frames[k], int(seq.frame_stamps_ns[k]))
                        if signals and time.monotonic() - t0 >= signals[0] and proc.poll() is None:
                            proc.send_signal(getattr(signal, signal_name))
                            signals.pop(0)
                    out, err = proc.communicate(timeout=20)
            finally:
                drv.node.destroy_node()
                if proc.poll() is None:
                    proc.kill()
                    proc.communicate()
            assert proc.returncode == 0, (signal_name, delay, err[-2000:])
            assert 'Traceback' not in out + err, err[-2000:]
