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
A fuzz campaign against the node (one process, over DDS).

Malformed images of every encoding and size, IMU with extreme and non-finite rates and disordered
stamps, CameraInfo with extreme K, D and sizes, ~/init boxes and parameters out of range, and
bursts.  After each campaign the node must answer valid frames, with a detection once the target is
given again.  ``CASES`` counts the cases of each campaign (printed with ``-s``).
"""
import itertools
import math

import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
pytest.importorskip('vision_msgs.msg')

from iemd_ros.datasets.synthetic import generate  # noqa: E402, I100
from iemd_ros.messages.conversions import ENCODINGS, fill_image_msg, stamp_ns  # noqa: E402
from iemd_ros.ros.parameters import parameters  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from ros_harness import imu_msg, level, stamp_header, values  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402
from test_node import ERROR, tracker_and_driver  # noqa: E402
from vision_msgs.msg import Detection2D  # noqa: E402

CASES: dict[str, int] = {}
EXTREME = [math.nan, math.inf, -math.inf, 1e308, -1e308, 1e30, 35.0, 34.9, -1e-300, 0.0]
FRAME_PERIOD_NS = 33_333_333
# the largest stamp a builtin_interfaces/Time holds (int32 seconds)
LAST_STAMP = (2**31 - 1) * 10**9


@pytest.fixture(scope='module')
def seq():
    return generate(n_frames=6, max_rate_deg_s=30.0, seed=11)


class Campaign:
    """The tracker node and a driver; ``t`` is the next image stamp (they only increase)."""

    def __init__(self, node, drv, seq):
        self.node, self.drv, self.seq = node, drv, seq
        self.t = 10**12
        self.box = [float(v) for v in seq.gt_boxes[0]]

    def stamp(self) -> int:
        self.t += FRAME_PERIOD_NS
        return self.t

    def answered(self, t_ns, tracked=None, timeout=20.0) -> bool:
        return self.drv.wait_for(
            lambda: any(
                stamp_ns(d.header) == t_ns and (tracked is None or bool(d.detections) == tracked)
                for d in self.drv.detections
            ),
            timeout,
        )

    def still_tracks(self) -> None:
        """
        Validate frames are answered.

        After ~/init on one of them the next ones carry a detection.
        """
        t = self.stamp()
        self.drv.publish_camera_info(self.seq)
        self.drv.publish_image(self.seq.frames[0], t)
        assert self.answered(t), 'a valid frame got no answer'
        self.drv.publish_init(self.box, t)
        assert self.drv.wait_for(lambda: self.node.pipeline.counters['inits'] > self.inits, 20.0)
        self.inits = self.node.pipeline.counters['inits']
        for k in (1, 2):
            t = self.stamp()
            self.drv.publish_image(self.seq.frames[k], t)
            assert self.answered(t, tracked=True), f'frame {k} after the campaign was not tracked'
        assert self.node._worker.is_alive() and self.node.context.ok()

    inits = 0


@pytest.fixture(scope='module')
def campaign(ctx, seq):
    with tracker_and_driver(ctx, imu_wait_ms=0.0, watchdog_ms=5000.0) as (node, drv):
        c = Campaign(node, drv, seq)
        c.still_tracks()
        yield c
    print('\nnode fuzz campaign cases: ' + ', '.join(f'{k} {v}' for k, v in CASES.items()))


def _image_cases(frame):
    """
    Image messages: every encoding (and unknown ones) x sizes.

    Steps and data lengths that do and do not fit.
    """
    out = []
    for encoding in [*ENCODINGS, 'yuv422', 'bgr16', '', '8UC3']:
        channels, depth = ENCODINGS.get(encoding, (3, 1))
        for width, height in [
            (0, 0),
            (1, 1),
            (2, 2),
            (1, 100_000),
            (100_000, 1),
            (16_385, 2),
            (37, 23),
            (320, 240),
        ]:
            row = width * channels * depth
            for step, size in [
                (row, row * height),
                (row + 3, (row + 3) * height),
                (max(row - 1, 0), row * height),
                (row, row * height - 1),
                (row, 0),
            ]:
                # never a huge message: the size check comes first
                if size > 3 * 320 * 240 * 2 + 1000:
                    size = 16
                msg = fill_image_msg(Image(), frame)
                msg.encoding, msg.width, msg.height, msg.step = encoding, width, height, step
                msg.is_bigendian = len(out) % 2
                msg.data = bytes(max(size, 0))
                out.append(msg)
    return out


def test_malformed_images_of_every_encoding_and_size(campaign, seq):
    cases = _image_cases(seq.frames[0])
    CASES['images'] = len(cases)
    # one at a time: each must be answered
    for msg in cases:
        t = campaign.stamp()
        stamp_header(msg.header, t)
        campaign.drv.image_pub.publish(msg)
        assert campaign.answered(t), (msg.encoding, msg.width, msg.height, msg.step, len(msg.data))
    campaign.still_tracks()


def test_imu_with_extreme_and_non_finite_rates_and_disordered_stamps(campaign, seq):
    rng = np.random.default_rng(7)
    t0 = campaign.t
    cases = [
        (t0 + i * 5_000_000, w) for i, w in enumerate(itertools.product(EXTREME[:6], repeat=2))
    ]
    cases += [
        (int(t0 + rng.integers(-3 * 10**9, 3 * 10**9)), tuple(rng.choice(EXTREME, 2)) + (0.1,))
        # disordered: back and forth by up to 3 s
        for _ in range(60)
    ]
    # repeats, ends
    cases += [(t0, (0.1, 0.0, 0.0))] * 10 + [(0, (0.0, 0.0, 0.0)), (LAST_STAMP, (0.0, 0.0, 0.0))]
    CASES['imu'] = len(cases)
    received = campaign.node.pipeline.counters['imu_received']
    for t, w in cases:
        msg = imu_msg(max(min(t, LAST_STAMP), 0), (*w, 0.0)[:3])
        campaign.drv.imu_pub.publish(msg)
    assert campaign.drv.wait_for(
        lambda: campaign.node.pipeline.counters['imu_received'] >= received + len(cases), 20.0
    )
    campaign.still_tracks()


def _camera_info(seq, k=None, d=None, size=None, model='plumb_bob'):
    msg = CameraInfo()
    msg.width, msg.height = size if size is not None else (seq.config.width, seq.config.height)
    msg.k = [float(v) for v in (seq.K.ravel() if k is None else k)]
    msg.d = [float(v) for v in (seq.dist if d is None else d)]
    msg.distortion_model = model
    return msg


def test_camera_info_with_extreme_k_d_and_sizes(campaign, seq):
    K = list(seq.K.ravel())
    cases = []
    for i, v in itertools.product((0, 2, 4, 5, 1, 8), EXTREME + [-500.0, 1e8, 1e-8]):
        k = list(K)
        k[i] = v
        cases.append(_camera_info(seq, k=k))
    cases += [_camera_info(seq, k=[0.0] * 9), _camera_info(seq, k=[1.0] * 9)]
    cases += [
        _camera_info(seq, d=d)
        for d in (
            [math.nan] * 5,
            [1e300] * 5,
            [0.1] * 14,
            [],
            [-1e6, 0, 0, 0, 0],
            [0.0, 1e8, 0.0, 0.0, 0.0],
        )
    ]
    cases += [
        _camera_info(seq, size=s)
        for s in [(0, 0), (1, 1), (100_000, 100_000), (640, 480), (4294967295, 1)]
    ]
    cases += [
        _camera_info(seq, model=m) for m in ('equidistant', 'rational_polynomial', '', 'fisheye')
    ]
    CASES['camera_info'] = len(cases)
    t = campaign.stamp()
    campaign.drv.publish_image(seq.frames[0], t)
    for msg in cases:
        campaign.drv.info_pub.publish(msg)
        # frames in between use whatever was taken
        t = campaign.stamp()
        campaign.drv.publish_image(seq.frames[len(cases) % 3], t)
    assert campaign.answered(t)
    campaign.still_tracks()
    st = campaign.drv.wait_status('camera_info', lambda x: True)
    # the valid one of still_tracks is in use
    assert st is not None and level(st) != ERROR, st.message


def test_init_boxes_out_of_range(campaign, seq):
    cases = [
        (x, y, w, h)
        for x, y, w, h in itertools.product(
            [-1e9, -10.0, 50.0, 1e9, math.nan],
            [50.0, math.inf],
            [0.0, -5.0, 30.0, 2e5, math.nan],
            [30.0, 1e-9],
        )
    ]
    CASES['init boxes'] = len(cases)
    t = campaign.stamp()
    campaign.drv.publish_image(seq.frames[0], t)
    assert campaign.answered(t)
    inits = campaign.node.pipeline.counters['inits']
    for box in cases:
        msg = Detection2D()
        stamp_header(msg.header, t)
        c = msg.bbox.center.position
        c.x, c.y, msg.bbox.size_x, msg.bbox.size_y = box
        campaign.drv.init_pub.publish(msg)
    st = campaign.drv.wait_status(
        'tracking', lambda x: '~/init' in values(x).get('note', ''), 10.0
    )
    assert st is not None
    accepted = campaign.node.pipeline.counters['inits'] - inits
    assert accepted <= sum(
        1
        for x, y, w, h in cases
        if all(map(math.isfinite, (x, y, w, h)))
        and 0 < w <= 320
        and 0 < h <= 240
        and -w < x < 320
        and -h < y < 240
    )
    campaign.still_tracks()


def _out_of_range(p):
    """
    Values of parameter ``p`` that must be refused.

    Beyond its range, of another type, of another length.
    """
    low_high = p.spec.range
    scalar = p.default if not isinstance(p.default, list) else (p.default[0] if p.default else 0.0)
    bad = []
    if low_high is not None:
        for v in (
            low_high[0] - max(1.0, abs(low_high[0])),
            low_high[1] + max(1.0, abs(low_high[1])),
        ):
            v = int(v) if isinstance(scalar, int) and not isinstance(scalar, bool) else float(v)
            bad.append([v] * (p.spec.length or 4) if isinstance(p.default, list) else v)
    if isinstance(p.default, bool):
        bad.append('yes')
    elif isinstance(p.default, (int, float)):
        bad += ['text', math.nan if isinstance(p.default, float) else 1.5]
    elif isinstance(p.default, list):
        bad += [[1.0] * ((p.spec.length or 4) + 1), [math.inf] * (p.spec.length or 4)]
    elif isinstance(p.default, str) and p.kind is not str:
        bad.append('no such choice')
    return bad


def test_parameters_out_of_range_are_refused(campaign):
    node = campaign.node
    before = {p.name: node.get_parameter(p.name).value for p in parameters()}
    cases = [(p.name, v) for p in parameters() for v in _out_of_range(p)]
    CASES['parameters'] = len(cases)
    for name, value in cases:
        try:
            param = Parameter(name, value=value)
        except TypeError:
            continue
        (r,) = campaign.drv.set_parameters_raw([param])
        assert not r.successful, (name, value)
    assert {p.name: node.get_parameter(p.name).value for p in parameters()} == before
    campaign.still_tracks()


def test_bursts_of_images_and_imu(campaign, seq):
    n_images, n_imu = 120, 2000
    CASES['burst'] = n_images + n_imu
    t_imu = campaign.t
    for i in range(n_imu):
        campaign.drv.publish_imu(t_imu + i * 1_000_000, (0.01, -0.02, 0.0))
    stamps = []
    for i in range(n_images):
        t = campaign.stamp()
        stamps.append(t)
        campaign.drv.publish_image(seq.frames[i % len(seq.frames)], t)
    assert campaign.answered(stamps[-1])
    st = campaign.drv.wait_status('image input', lambda x: int(values(x)['frames_received']) > 0)
    assert st is not None
    campaign.still_tracks()
    c = campaign.node.pipeline.counters
    assert c['frames_received'] >= c['frames_processed'] + c['frames_dropped']
