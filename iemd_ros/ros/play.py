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
              [--wait-subscribers S] [--clock]
              [--ros-args ...]

rosbag2's player is not installable from PyPI, so this is a small one in rclpy: each message is
published when ``(log_time - first_log_time) / rate`` of wall time has passed since the start (log
time = the bag's receive timestamp, which orders the messages), so a running node sees the messages
as on the robot.  Messages are not copied field by field: the CDR bytes of the bag (for a ROS 1
bag: converted to ROS 2 Jazzy CDR by rosbags' own converter) are turned into the rclpy message
class with ``rclpy.serialization.deserialize_message``.  Publishers are reliable / volatile with a
queue of ``--qos-depth`` (a reliable publisher also serves best-effort subscribers, e.g.
``sensor_data``).

``--wait-subscribers S``: wait up to S seconds (wall) until every publisher has a subscriber before
starting (discovery takes a moment); ``--clock``: also publish ``/clock`` (rosgraph_msgs/Clock)
with the log time of each message, for nodes with ``use_sim_time``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import sys
import time

from iemd_ros.bags.io import BagError, iter_messages, open_bag, ros2_typestore
from iemd_ros.common.cli import non_negative_float, positive_float
from iemd_ros.common.progress import Progress
from iemd_ros.messages.conversions import ns_to_stamp
from iemd_ros.ros.messages import message_class


@dataclass
class PlayStats:
    """What :func:`play` did: messages per topic, wall time, and how late messages went out."""

    published: dict = field(default_factory=dict)
    wall_s: float = 0.0
    bag_s: float = 0.0
    max_late_ms: float = 0.0
    mean_late_ms: float = 0.0


def _cdr_converter(reader, msgtype: str, cache: dict, dst_typestore):
    """
    Return the converter of the bag's bytes to ROS 2 CDR bytes.

    The identity for rosbag2, rosbags' converter for ROS 1.  The typestores generate their
    (de)serializers on first use, so they are generated here, before the clock of the timed loop
    starts (docs/decisions.md#play-converter-warmup).
    """
    if reader.is2:
        return bytes
    from rosbags.convert.converter import generate_message_converter

    conv = generate_message_converter(reader.typestore, dst_typestore, msgtype, msgtype, cache,
                                      src_is2=False, dst_is2=True)
    reader.typestore.get_msgdef(msgtype)
    dst_typestore.get_msgdef(msgtype)
    return lambda raw: bytes(conv(raw))


def parse_remaps(remaps) -> dict:
    """``FROM:=TO`` texts -> {FROM: TO}; ValueError for any other text."""
    out = {}
    for r in remaps or []:
        src, sep, dst = r.partition(':=')
        if not sep or not src or not dst:
            raise ValueError(f'--remap must be FROM:=TO, got {r!r}')
        out[src] = dst
    return out


def play(bag, rate: float = 1.0, topics=None, remap: dict | None = None, delay_s: float = 0.0,
         wait_subscribers_s: float = 0.0, clock: bool = False, qos_depth: int = 100, node=None,
         progress: bool | None = False, ros_args: list[str] | None = None) -> PlayStats:
    """
    Publish ``bag`` with its timing scaled by ``1/rate``.

    Parameters
    ----------
    bag : path
        rosbag2 folder or ROS 1 ``.bag``.
    rate : float
        Playback rate factor (finite, > 0).
    topics : list of str, optional
        Only these bag topics (default all).
    remap : dict, optional
        Bag topic -> published topic.
    delay_s, wait_subscribers_s : float
        Sleep before playing; wait up to this long until every topic has a subscriber (s, finite,
        >= 0).
    clock : bool
        Also publish ``/clock`` with the log times.
    qos_depth : int
        Publisher queue depth (reliable, volatile).
    node : rclpy node, optional
        Where to create the publishers (default: a new ``iemd_play`` node; rclpy is initialised if
        needed, with ``ros_args``, and shut down again).
    progress : bool or None, optional
        A progress bar on stderr (None: only when stderr is a terminal).
    ros_args : list of str, optional
        The ROS arguments rclpy is initialised with, when this function initialises it.

    Returns
    -------
    PlayStats

    Raises
    ------
    ValueError
        (BagError) for a bad rate or depth, topics not in the bag, or nothing to play.

    """
    import rclpy
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    positive_float.check('--rate', rate)
    non_negative_float.check('--delay', delay_s)
    non_negative_float.check('--wait-subscribers', wait_subscribers_s)
    if qos_depth < 1:
        raise ValueError(f'--qos-depth must be >= 1, got {qos_depth}')
    remap = dict(remap or {})
    reader = open_bag(bag, warn=lambda text: print(f'iemd-play: warning: {text}', file=sys.stderr))
    own_init = own_node = False
    pubs: dict = {}
    try:
        conns, total = _connections(reader, topics, remap, bag)
        classes = {c.msgtype: message_class(c.msgtype) for c in conns}
        if node is None:
            if not rclpy.ok():
                rclpy.init(args=['iemd-play', *(ros_args or [])])
                own_init = True
            node = rclpy.create_node('iemd_play')
            own_node = True
        qos = QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=int(qos_depth),
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        for c in conns:
            if c.topic not in pubs:
                pubs[c.topic] = node.create_publisher(
                    classes[c.msgtype], remap.get(c.topic, c.topic), qos
                )
        if clock:
            from rosgraph_msgs.msg import Clock

            pubs[_CLOCK] = node.create_publisher(Clock, '/clock', qos)
        if wait_subscribers_s > 0:
            deadline = time.monotonic() + wait_subscribers_s
            while time.monotonic() < deadline and any(
                p.get_subscription_count() == 0 for p in pubs.values()
            ):
                time.sleep(0.01)
        if delay_s > 0:
            time.sleep(delay_s)
        return _publish_timed(
            reader, conns, classes, pubs, rate, Progress(total, 'iemd-play', progress), bag
        )
    finally:
        reader.close()
        if own_node and node is not None:
            node.destroy_node()
        elif node is not None:  # a caller's node: remove what was added to it
            for pub in pubs.values():
                node.destroy_publisher(pub)
        if own_init:
            rclpy.try_shutdown()


_CLOCK = '/clock'  # the publishers' key of the clock


def _connections(reader, topics, remap: dict, bag):
    """
    (connect to play, their message count) of the ``topics`` asked for.

    BagError naming what is missing.
    """
    available = reader.topics
    wanted = list(available) if not topics else list(topics)
    missing = [t for t in wanted if t not in available]
    if missing:
        raise BagError(
            f'topic(s) {", ".join(missing)} not in the bag (topics: '
            f'{", ".join(sorted(available))})'
        )
    unknown = [t for t in remap if t not in wanted]
    if unknown:
        raise BagError(f'--remap of topic(s) not played: {", ".join(unknown)}')
    conns = [c for c in reader.connections if c.topic in wanted]
    total = sum(available[t].msgcount for t in wanted)
    if not conns or total == 0:
        raise BagError(f'bag {bag} has no message to play')
    return conns, total


def _publish_timed(
    reader, conns, classes: dict, pubs: dict, rate: float, bar: Progress, bag
) -> PlayStats:
    """
    Publish every message at its log time.

    (relative to the first, scaled by ``1/rate``) and say how late.
    """
    from rclpy.serialization import deserialize_message

    dst = ros2_typestore() if not reader.is2 else None
    cache: dict = {}
    convert = {c.msgtype: _cdr_converter(reader, c.msgtype, cache, dst) for c in conns}
    clock_pub = pubs.get(_CLOCK)
    stats = PlayStats()
    t0_log = t0_wall = None
    late_sum, n = 0.0, 0
    for conn, log_t, raw in iter_messages(reader, conns, bag):
        msg = deserialize_message(convert[conn.msgtype](raw), classes[conn.msgtype])
        if t0_log is None:
            t0_log, t0_wall = log_t, time.monotonic()
        target = t0_wall + (log_t - t0_log) * 1e-9 / rate
        while (wait := target - time.monotonic()) > 0:
            time.sleep(min(wait, 0.05))
        late = (time.monotonic() - target) * 1e3
        if clock_pub is not None:
            from rosgraph_msgs.msg import Clock

            cm = Clock()
            cm.clock.sec, cm.clock.nanosec = ns_to_stamp(log_t)
            clock_pub.publish(cm)
        pubs[conn.topic].publish(msg)
        stats.published[conn.topic] = stats.published.get(conn.topic, 0) + 1
        stats.max_late_ms = max(stats.max_late_ms, late)
        late_sum += late
        n += 1
        stats.bag_s = (log_t - t0_log) * 1e-9
        bar.update(1)
    bar.close()
    stats.wall_s = 0.0 if t0_wall is None else time.monotonic() - t0_wall
    stats.mean_late_ms = late_sum / n if n else 0.0
    return stats
