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
iemd-play: a bag onto ROS topics with its timing (rclpy, in-process).

And the live replay through the running tracker node agreeing frame by frame with the offline
replay.

Agreement (stated tolerance): on every frame the live node processed, the published box equals the
offline replay's to 1e-6 px and the score to 1e-9, and "lost" frames are empty on both sides.
Frames the live node dropped (a newer frame arrived while it was busy) have no output: they are
counted (the node's own ``frames_dropped`` counter must agree) and the offline reference is the
replay that skips the same frames (``replay(..., drop_stamps=...)``); with no drop it is the plain
offline replay.  The node waits up to ``imu_wait_ms = 1000`` ms of wall time for the gyro and the
offline replay up to 1000 ms of bag time, so on both sides every frame waits until the gyro covers
it.
"""
import threading
import time

from bag_fixtures import (
    by_topic,
    IMG,
    IMG_COMPRESSED,
    IMU,
    INFO,
    make_bag,
    read_all,
    shaky_sequence,
)
from helpers import cli_error, detection_box
import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
pytest.importorskip('vision_msgs.msg')

from iemd_ros.apps.play import main  # noqa: E402, I100
from iemd_ros.bags.make import source_from_folder, write_bag  # noqa: E402
from iemd_ros.bags.replay import replay  # noqa: E402
from iemd_ros.messages.conversions import stamp_ns  # noqa: E402
from iemd_ros.pipeline import PipelineConfig  # noqa: E402
from iemd_ros.ros.play import play  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import QoSProfile, QoSReliabilityPolicy  # noqa: E402
from ros_harness import spinning  # noqa: E402
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu  # noqa: E402
from vision_msgs.msg import Detection2DArray  # noqa: E402

BOX_TOL_PX = 1e-6
LIVE_RATE = 0.05  # the node must keep up on a loaded 2-core machine (~100-300 ms per update)
IMU_WAIT_MS = 1000.0


@pytest.fixture(scope='module')
def seq():
    return shaky_sequence(14)


class Recorder:
    def __init__(self, context):
        self.node = rclpy.create_node('iemd_test_recorder', context=context)
        self.lock = threading.Lock()
        self.got = {'img': [], 'compressed': [], 'imu': [], 'info': [], 'det': []}
        q = QoSProfile(depth=1000, reliability=QoSReliabilityPolicy.RELIABLE)
        n = self.node
        n.create_subscription(
            Image,
            IMG,
            lambda m: self._add(
                'img', (time.monotonic(), stamp_ns(m.header), bytes(m.data), m.encoding)
            ),
            q,
        )
        n.create_subscription(
            CompressedImage,
            IMG_COMPRESSED,
            lambda m: self._add('compressed', (stamp_ns(m.header), m.format, bytes(m.data))),
            q,
        )
        n.create_subscription(
            Imu, IMU, lambda m: self._add('imu', (stamp_ns(m.header), m.angular_velocity.x)), q
        )
        n.create_subscription(CameraInfo, INFO, lambda m: self._add('info', list(m.k)), q)
        n.create_subscription(Detection2DArray, '/detections', lambda m: self._add('det', m), q)

    def _add(self, key, value):
        with self.lock:
            self.got[key].append(value)

    def wait(self, predicate, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                if predicate(self.got):
                    return True
            time.sleep(0.02)
        return False


def _play_recorded(ctx, bag, arrived, **play_kw):
    """
    Play ``bag`` into a Recorder; wait until ``arrived(got, stats)`` holds.

    Return (stats, got).
    """
    rec = Recorder(ctx)
    player = rclpy.create_node('iemd_test_player', context=ctx)
    try:
        with spinning(ctx, rec.node):
            stats = play(bag, wait_subscribers_s=10.0, node=player, **play_kw)
            assert rec.wait(lambda g: arrived(g, stats), 10.0)
    finally:
        player.destroy_node()
        rec.node.destroy_node()
    return stats, rec.got


@pytest.mark.parametrize('fmt,name', [('mcap', 'b'), ('ros1', 'b.bag')])
def test_play_contents_and_timing(ctx, seq, tmp_path, fmt, name):
    make_bag(seq, tmp_path / name, fmt, imu_margin_s=0.1)
    stats, g = _play_recorded(
        ctx,
        tmp_path / name,
        lambda g, stats: (
            len(g['img']) == len(seq.frames) and len(g['imu']) == stats.published[IMU]
        ),
        rate=2.0,
    )
    assert stats.published[IMG] == stats.published[INFO] == len(seq.frames)
    assert [s for _, s, _, _ in g['img']] == seq.frame_stamps_ns.tolist()
    for k, (_, _, data, enc) in enumerate(g['img']):
        # the bag's bytes, unchanged
        assert enc == 'bgr8' and data == seq.frames[k].tobytes()
    t_cam = seq.gyro_t_ns - seq.time_offset_ns
    np.testing.assert_array_equal(
        sorted(s for s, _ in g['imu']), t_cam[np.isin(t_cam, [s for s, _ in g['imu']])]
    )
    np.testing.assert_allclose(np.reshape(g['info'][0], (3, 3)), seq.K)
    # timing: the bag's span divided by the rate (a player can be late, never early)
    span = stats.bag_s / 2.0
    assert span - 0.005 <= stats.wall_s <= span + 0.5 and stats.mean_late_ms < 50
    recv = [t for t, _, _, _ in g['img']]
    expect = (seq.frame_stamps_ns[-1] - seq.frame_stamps_ns[0]) * 1e-9 / 2.0
    assert abs((recv[-1] - recv[0]) - expect) < 0.25


@pytest.mark.parametrize('fmt,name', [('mcap', 'c'), ('ros1', 'c.bag')])
def test_play_compressed(ctx, seq, tmp_path, fmt, name):
    """
    A CompressedImage topic goes out as sensor_msgs/CompressedImage with the bag's stamps.

    Format and bytes (a ROS 1 bag through rosbags' converter).
    """
    make_bag(seq, tmp_path / name, fmt, compress='jpeg', imu_margin_s=0.0)
    topic = IMG_COMPRESSED
    want = [
        (stamp_ns(m.header), m.format, bytes(m.data))
        for m in by_topic(read_all(tmp_path / name), topic)
    ]
    stats, got = _play_recorded(
        ctx,
        tmp_path / name,
        lambda g, stats: len(g['compressed']) == len(seq.frames),
        rate=4.0,
        topics=[topic, INFO],
    )
    assert stats.published == {topic: len(seq.frames), INFO: len(seq.frames)} and got['img'] == []
    assert got['compressed'] == want and want[0][1] == 'bgr8; jpeg compressed bgr8'


def _live_vs_offline(ctx, bag, init, n_frames):
    """
    Play ``bag`` at LIVE_RATE into a TrackerNode.

    Return (live {stamp: Detection2DArray}, dropped, node counters).
    """
    from iemd_ros.ros.node import TrackerNode

    params = [
        Parameter('initial_box', value=[float(v) for v in init]),
        Parameter('imu_wait_ms', value=IMU_WAIT_MS),
        Parameter('reliable_qos', value=True),
    ]
    node = TrackerNode(context=ctx, parameter_overrides=params)
    rec = Recorder(ctx)
    player = rclpy.create_node('iemd_test_player', context=ctx)
    remap = {IMG: '/image', IMU: '/imu', INFO: '/camera_info'}
    try:
        with spinning(ctx, node, rec.node):
            stats = play(
                bag, rate=LIVE_RATE, remap=remap, wait_subscribers_s=10.0, delay_s=0.3, node=player
            )
            done = rec.wait(
                lambda g: len(g['det']) + node.pipeline.counters['frames_dropped'] >= n_frames,
                30.0,
            )
            counters = dict(node.pipeline.counters)
    finally:
        player.destroy_node()
        node.destroy_node()
        rec.node.destroy_node()
    assert stats.published[IMG] == n_frames
    assert done, f'the node answered {len(rec.got["det"])} of {n_frames} frames within 30 s'
    return {stamp_ns(m.header): m for m in rec.got['det']}, counters


def _compare(live: dict, offline, counters) -> tuple[int, int]:
    """
    Frame-by-frame check of the live detections against an offline ReplayResult.

    Returns (compared, dropped).
    """
    dropped = list(offline.dropped)
    assert counters['frames_dropped'] == len(dropped)
    # only dropped frames are missing
    assert set(live) == {r.stamp_ns for r in offline.results}
    for k, r in enumerate(offline.results):
        m = live[r.stamp_ns]
        if k == 0 or r.tracking:
            assert len(m.detections) == 1, f'frame {k}: offline {r.state}, live published nothing'
            box = detection_box(m.detections[0])
            np.testing.assert_allclose(box, r.box, rtol=0, atol=BOX_TOL_PX, err_msg=f'frame {k}')
            assert m.detections[0].results[0].hypothesis.score == pytest.approx(
                r.score, rel=1e-9, abs=1e-12
            )
        else:
            assert m.detections == [], f'frame {k}: offline {r.state}, live published a box'
    return len(offline.results), len(dropped)


def _check_live(ctx, bag, init, n_frames):
    live, counters = _live_vs_offline(ctx, bag, init, n_frames)
    cfg = PipelineConfig(imu_wait_ms=IMU_WAIT_MS)
    plain = replay(bag, init, config=cfg)
    stamps_all = [r.stamp_ns for r in plain.results]
    missing = [t for t in stamps_all if t not in live]
    offline = replay(bag, init, config=cfg, drop_stamps=missing) if missing else plain
    compared, dropped = _compare(live, offline, counters)
    assert dropped <= n_frames // 4, f'the live node dropped {dropped} of {n_frames} frames'
    # every frame had the gyro prior
    assert offline.gyro_used == compared - 1
    print(
        f'live vs offline: {compared} frames agree (box within {BOX_TOL_PX} px), {dropped} '
        'dropped by the node'
        f' (frames {[stamps_all.index(t) for t in missing]})'
    )
    return compared, dropped


def test_live_replay_matches_offline_synthetic(ctx, seq, tmp_path):
    make_bag(seq, tmp_path / 'shaky', imu_margin_s=0.05)
    _check_live(ctx, tmp_path / 'shaky', seq.gt_boxes[0], len(seq.frames))


@pytest.mark.slow
def test_live_replay_matches_offline_desk(ctx, imu_root, tmp_path):
    src = source_from_folder(imu_root / 'cmu_hwangbo_desk')
    write_bag(src, tmp_path / 'desk', 'mcap', count=12, imu_margin_s=0.05)
    _check_live(ctx, tmp_path / 'desk', src.gt_boxes[0], 12)


def test_cli_bad_input(tmp_path, capsys):
    for argv, text in [
        ([str(tmp_path / 'missing')], 'does not exist'),
        ([str(tmp_path), '--rate', '0'], 'must be a finite number > 0'),
        ([str(tmp_path), '--rate', 'inf'], 'must be a finite number > 0'),
        ([str(tmp_path), '--delay', 'inf'], 'must be a finite number >= 0'),
        ([str(tmp_path), '--delay', '-1'], 'must be a finite number >= 0'),
        ([str(tmp_path), '--wait-subscribers', 'nan'], 'must be a finite number >= 0'),
        ([str(tmp_path), '--remap', 'a'], 'FROM:=TO'),
    ]:
        assert text in cli_error(main, argv, capsys, 'iemd-play: error:')
    seq = shaky_sequence(2, render=True)
    make_bag(seq, tmp_path / 'b')
    assert main([str(tmp_path / 'b'), '--topics', '/nope']) == 2
    assert 'not in the bag' in capsys.readouterr().err
    # the library call refuses what the command line refuses, before playing anything
    for rate in (0.0, -1.0, float('inf'), float('nan')):
        with pytest.raises(ValueError, match='--rate must be a finite number > 0'):
            play(tmp_path / 'b', rate=rate)
    for kw in ('delay_s', 'wait_subscribers_s'):
        for seconds in (-1.0, float('inf'), float('nan')):
            with pytest.raises(ValueError, match='must be a finite number >= 0'):
                play(tmp_path / 'b', **{kw: seconds})
