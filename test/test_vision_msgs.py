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
vision_msgs in the venv (vendored 4.x interface from scripts/build_vision_msgs.sh, or ROS).

Checks the message layout, CDR round trips with rclpy, the RIHS01 type hashes against an upstream
build, publish/subscribe of Detection2DArray between two processes, and rosbags registration of
the same definitions (iemd_ros.bags.types) with byte-identical CDR.

This file is also the publisher of the two-process test:
``python test_vision_msgs.py --publish TOPIC``.
"""
from __future__ import annotations

import importlib
import importlib.util
import json
import os
from pathlib import Path
import subprocess
import sys
import time
import uuid

from iemd_ros.bags.types import vision_msgs_types
import numpy as np
import pytest

# The repository's sources (iemd_ros itself may be installed in the venv, away from the tree).
REPO_MSG_DIR = Path(__file__).resolve().parents[1] / 'interfaces' / 'vision_msgs' / 'msg'
TYPES = sorted(p.stem for p in REPO_MSG_DIR.glob('*.msg'))

# RIHS01 hashes of upstream vision_msgs 4.x (ROS 2 Jazzy era rosidl), as recorded in generated code
# of a public colcon build of ros-perception/vision_msgs: repository borednuna/ipm-ws, commit
# 1d768272c24114f1004e19d0ef8118b73b9a2b68, build/vision_msgs/rosidl_generator_type_description/
# vision_msgs/msg/*.json and build/vision_msgs/rosidl_generator_c/vision_msgs/msg/detail/
# *__description.c (the *_EXPECTED_HASH tables there give the referenced vision_msgs types too).
# BoundingBox2D and ObjectHypothesis are also in dkrygsman/pi_ws, build/depthai_ros_msgs/
# rosidl_generator_c/depthai_ros_msgs/msg/detail/spatial_detection__description.c (a package built
# against the installed vision_msgs). No public record of BoundingBox3DArray's hash was found: it
# is checked against rosidl's own hash function of the .msg text only.
UPSTREAM_RIHS01 = {
    'BoundingBox2D': '008eacbb0cf8f26e83795547bed013eec3675485ef386ec056d80eaaf1c1ce2f',
    'BoundingBox2DArray': '2464e82838009386d371b523211c21c91d74d313fcdd6788223c531d621cf691',
    'BoundingBox3D': 'bbb73a65c163d7f9bb29009c7bde9f7faa576bd2d23299c4511d19230dab4698',
    'Classification': 'f74db28d0eaef3afb78f48bf2161cd709a1383a0309d3454383b25be11345143',
    'Detection2D': '0d12b69df5c593b3455b7346fac8205437a7d4bcb09b9e0e0b2dde787ded38ea',
    'Detection2DArray': '214274120007f4a683866481336b70310268cfa107aebe9d594a6acf75bda968',
    'Detection3D': 'ddd703be132ab0b69d33121f1bb034132bfbb3b0ac5f9fb1516005ba1c8a265b',
    'Detection3DArray': '793f5eab9595ac1c0da07873cc859db42eae51f0ee76056db8562515d830e018',
    'LabelInfo': '3d37df4015cdf660cc851c51897f2acd957e1ca6205ba0a99aebffb9406b0783',
    'ObjectHypothesis': '51da43cec11c01957a64d1e05a24acd18aae7745ec30b74348ad5f6d634f7f90',
    'ObjectHypothesisWithPose': '41c12344c0396c48b81df12467c192d99b2a0eb1463c5c37194e4223251c80bc',
    'Point2D': 'eab0e83f44ab4de92ceaf76dd7d0e7638f2bdd1d16ffbe16c7a136c48e407247',
    'Pose2D': 'b0b5d1d7b4c20dd4fcde3ed1d4b289a919290572007d67a97043814db25d3648',
    'VisionClass': '1e4a11f0fed50b5623cb8ff26ca0e37952a48a9c074d16f804b44e9164c2037a',
    'VisionInfo': '95d3116a17484ad91c9a2686e1d54890bbfc3ff6c6a2de137738c4950d45d284',
}

# Pose covariance of the sample detection: distinct values so that a misplaced element shows.
COVARIANCE = np.arange(36, dtype=np.float64) * 0.25


def build_detection_array(cls):
    """
    Return the sample Detection2DArray from ``cls('pkg/msg/Name')`` classes.

    (rclpy or rosbags).
    """
    header = cls('std_msgs/msg/Header')(
        stamp=cls('builtin_interfaces/msg/Time')(sec=1_700_000_123, nanosec=456_789_000),
        frame_id='camera_optical')
    pose = cls('geometry_msgs/msg/Pose')(
        position=cls('geometry_msgs/msg/Point')(x=1.5, y=-2.25, z=3.0),
        orientation=cls('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.6, w=0.8))
    hypothesis = cls('vision_msgs/msg/ObjectHypothesisWithPose')(
        hypothesis=cls('vision_msgs/msg/ObjectHypothesis')(class_id='person', score=0.875),
        pose=cls('geometry_msgs/msg/PoseWithCovariance')(pose=pose, covariance=COVARIANCE.copy()))
    bbox = cls('vision_msgs/msg/BoundingBox2D')(
        center=cls('vision_msgs/msg/Pose2D')(
            position=cls('vision_msgs/msg/Point2D')(x=320.5, y=240.25), theta=0.125),
        size_x=64.0, size_y=128.5)
    detection = cls('vision_msgs/msg/Detection2D')(
        header=header, results=[hypothesis], bbox=bbox, id='track-7')
    return cls('vision_msgs/msg/Detection2DArray')(header=header, detections=[detection])


def rclpy_class(type_name):
    package, _, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


@pytest.fixture(scope='module')
def vm():
    """vision_msgs.msg of this interpreter, with its C type support loaded."""
    try:
        module = importlib.import_module('vision_msgs.msg')
        module.Detection2DArray.__class__.__import_type_support__()
    except Exception as exc:  # noqa: BLE001 - report any failure the same way
        pytest.fail(f'vision_msgs is not usable in {sys.prefix} ({exc!r}); '
                    f'run scripts/build_vision_msgs.sh {sys.prefix}')
    return module


def prefix_share(package: str) -> Path:
    """share/<package> of the install prefix of a generated message package (venv or /opt/ros)."""
    origin = Path(importlib.util.find_spec(package).origin)
    # <prefix>/lib/pythonX.Y/site-packages/<package>/__init__.py
    return origin.parents[4] / 'share' / package


def installed_hashes(package: str) -> dict[str, str]:
    share = prefix_share(package) / 'msg'
    return {p.stem: json.loads(p.read_text())['type_hashes'][0]['hash_string']
            for p in share.glob('*.json')}


def test_interface_is_the_vision_msgs_4_list(vm):
    assert TYPES == sorted(list(UPSTREAM_RIHS01) + ['BoundingBox3DArray'])
    for name in TYPES:
        assert hasattr(vm, name), name


def test_detection_field_layout(vm):
    fields = {name: list(getattr(vm, name).get_fields_and_field_types().items())
              for name in ('Detection2DArray', 'Detection2D', 'BoundingBox2D', 'Pose2D',
                           'Point2D', 'ObjectHypothesisWithPose', 'ObjectHypothesis')}
    assert fields == {
        'Detection2DArray': [('header', 'std_msgs/Header'),
                             ('detections', 'sequence<vision_msgs/Detection2D>')],
        'Detection2D': [('header', 'std_msgs/Header'),
                        ('results', 'sequence<vision_msgs/ObjectHypothesisWithPose>'),
                        ('bbox', 'vision_msgs/BoundingBox2D'), ('id', 'string')],
        'BoundingBox2D': [('center', 'vision_msgs/Pose2D'), ('size_x', 'double'),
                          ('size_y', 'double')],
        'Pose2D': [('position', 'vision_msgs/Point2D'), ('theta', 'double')],
        'Point2D': [('x', 'double'), ('y', 'double')],
        'ObjectHypothesisWithPose': [('hypothesis', 'vision_msgs/ObjectHypothesis'),
                                     ('pose', 'geometry_msgs/PoseWithCovariance')],
        'ObjectHypothesis': [('class_id', 'string'), ('score', 'double')],
    }


def test_detection2d_array_cdr_round_trip(vm):
    from rclpy.serialization import deserialize_message, serialize_message

    msg = build_detection_array(rclpy_class)
    data = serialize_message(msg)
    assert b'person\x00' in data and b'track-7\x00' in data and b'camera_optical\x00' in data
    back = deserialize_message(data, vm.Detection2DArray)
    assert back == msg
    det = back.detections[0]
    assert (back.header.stamp.sec, back.header.stamp.nanosec) == (1_700_000_123, 456_789_000)
    assert back.header.frame_id == det.header.frame_id == 'camera_optical'
    assert (det.bbox.center.position.x, det.bbox.center.position.y) == (320.5, 240.25)
    assert (det.bbox.center.theta, det.bbox.size_x, det.bbox.size_y) == (0.125, 64.0, 128.5)
    assert det.results[0].hypothesis.class_id == 'person'
    assert det.results[0].hypothesis.score == 0.875
    np.testing.assert_array_equal(det.results[0].pose.covariance, COVARIANCE)
    assert det.id == 'track-7'
    # Changing one field changes the bytes (the round trip is not trivially equal).
    det.results[0].hypothesis.score = 0.5
    assert serialize_message(back) != data


def test_installed_type_hashes_match_upstream(vm):
    hashes = installed_hashes('vision_msgs')
    assert sorted(hashes) == TYPES
    for name, value in UPSTREAM_RIHS01.items():
        assert hashes[name] == 'RIHS01_' + value, name


def test_type_hashes_from_msg_text_with_rosidl(vm, tmp_path):
    """Run rosidl's pipeline (.msg -> .idl -> type description hash) on the repo's .msg text."""
    from rosidl_adapter.msg import convert_msg_to_idl
    from rosidl_generator_type_description import generate_type_hash

    idl_dir = tmp_path / 'idl' / 'msg'
    idl_dir.mkdir(parents=True)
    for name in TYPES:
        convert_msg_to_idl(
            REPO_MSG_DIR.parent, 'vision_msgs', Path('msg') / f'{name}.msg', idl_dir
        )
    out = tmp_path / 'out'
    args = tmp_path / 'args.json'
    args.write_text(
        json.dumps(
            {
                'package_name': 'vision_msgs',
                'output_dir': str(out),
                'idl_tuples': [f'{tmp_path / "idl"}:msg/{name}.idl' for name in TYPES],
                'include_paths': [
                    f'{pkg}:{prefix_share(pkg)}' for pkg in ('std_msgs', 'geometry_msgs')
                ],
            }
        )
    )
    generate_type_hash(str(args))
    computed = {
        p.stem: json.loads(p.read_text())['type_hashes'][0]['hash_string']
        for p in (out / 'msg').glob('*.json')
    }
    assert computed == installed_hashes('vision_msgs')
    for name, value in UPSTREAM_RIHS01.items():
        assert computed[name] == 'RIHS01_' + value, name


# ---------------------------------------------------------------- two processes


def _publisher_main(topic: str) -> int:
    """Publish the sample Detection2DArray on ``topic`` at 20 Hz until SIGINT (or 60 s)."""
    from iemd_ros.ros.spin import spin_until_shutdown
    import rclpy
    from vision_msgs.msg import Detection2DArray

    rclpy.init()
    node = rclpy.create_node('vision_msgs_test_publisher')
    publisher = node.create_publisher(Detection2DArray, topic, 10)
    msg = build_detection_array(rclpy_class)
    count = 0
    deadline = time.monotonic() + 60.0

    def tick():
        nonlocal count
        publisher.publish(msg)
        count += 1
        if time.monotonic() > deadline:
            raise SystemExit(3)

    node.create_timer(0.05, tick)
    spin_until_shutdown(node)
    print(f'published {count}', flush=True)
    return 0


def _child_env() -> dict:
    from ros_harness import child_env

    env = child_env(os.environ)
    if importlib.util.find_spec('ros_wheels_bootstrapper') is not None:
        # pip-only venv: the child must work with no ROS environment variables at all.
        for name in ('LD_LIBRARY_PATH', 'AMENT_PREFIX_PATH', '_ROS_WHEELS_BOOTSTRAP_COMPLETE'):
            env.pop(name, None)
    return env


def test_detection2d_array_between_processes(vm, stop_process):
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from ros_harness import ros_context

    topic = f'/iemd_test_{uuid.uuid4().hex[:12]}/detections'
    with ros_context() as context:  # isolated domain, localhost-only discovery
        publisher = subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), '--publish', topic],
            env=_child_env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            node = rclpy.create_node('vision_msgs_test_subscriber', context=context)
            received = []
            node.create_subscription(vm.Detection2DArray, topic, received.append, 10)
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(node)
            deadline = time.monotonic() + 30.0
            while not received and time.monotonic() < deadline and publisher.poll() is None:
                executor.spin_once(timeout_sec=0.1)
            # Endpoints seen in discovery (the topic name is unique: the only publisher is the
            # child).
            remote = node.get_publishers_info_by_topic(topic)
            executor.shutdown()
            node.destroy_node()
        finally:
            out, err, _ = stop_process(publisher)
    assert received, f'no Detection2DArray within 30 s; publisher stderr:\n{err[-2000:]}'
    assert received[0] == build_detection_array(rclpy_class)
    assert received[0].detections[0].bbox.size_y == 128.5
    assert publisher.returncode == 0, err[-2000:]
    assert out.startswith('published ') and int(out.split()[1]) >= 1
    # The hash the publisher's type support announced in discovery is the upstream one.
    assert len(remote) == 1 and remote[0].topic_type == 'vision_msgs/msg/Detection2DArray'
    assert str(remote[0].topic_type_hash) == 'RIHS01_' + UPSTREAM_RIHS01['Detection2DArray']


# ---------------------------------------------------------------- rosbags


@pytest.fixture(scope='module')
def typestore():
    from rosbags.typesys import get_typestore, Stores

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(vision_msgs_types())
    return store


def test_rosbags_definitions_hash_like_upstream(typestore, vm):
    installed = installed_hashes('vision_msgs')
    for name in TYPES:
        assert typestore.hash_rihs01(f'vision_msgs/msg/{name}') == installed[name], name
    for name, value in UPSTREAM_RIHS01.items():
        assert typestore.hash_rihs01(f'vision_msgs/msg/{name}') == 'RIHS01_' + value, name


def test_rosbags_installed_and_repo_definitions_agree(vm):
    assert vision_msgs_types(prefix_share('vision_msgs') / 'msg') == vision_msgs_types(
        REPO_MSG_DIR
    )
    assert len(vision_msgs_types(REPO_MSG_DIR)) == len(TYPES)


def test_rosbags_cdr_is_rclpy_cdr(typestore, vm):
    from rclpy.serialization import deserialize_message, serialize_message

    name = 'vision_msgs/msg/Detection2DArray'
    expected = build_detection_array(rclpy_class)
    bag_msg = build_detection_array(lambda type_name: typestore.types[type_name])
    bag_bytes = bytes(typestore.serialize_cdr(bag_msg, name))
    assert deserialize_message(bag_bytes, vm.Detection2DArray) == expected
    # Same layout, byte for byte except alignment padding: rosbags writes zeros there, Fast CDR
    # leaves whatever was in its buffer (seen: the 4 bytes between "person\0" and the float64
    # score). So compare through rosbags, which rewrites the padding as zeros.
    rclpy_bytes = serialize_message(expected)
    assert len(rclpy_bytes) == len(bag_bytes)
    back = typestore.deserialize_cdr(rclpy_bytes, name)
    assert bytes(typestore.serialize_cdr(back, name)) == bag_bytes
    det = back.detections[0]
    assert det.results[0].hypothesis.class_id == 'person' and det.id == 'track-7'
    assert (det.bbox.center.position.x, det.bbox.size_x) == (320.5, 64.0)
    np.testing.assert_array_equal(det.results[0].pose.covariance, COVARIANCE)


def test_vision_msgs_types_rejects_bad_folder(tmp_path):
    with pytest.raises(ValueError, match='not a directory'):
        vision_msgs_types(tmp_path / 'missing')
    with pytest.raises(ValueError, match='holds no .msg file'):
        vision_msgs_types(tmp_path)


if __name__ == '__main__':
    if len(sys.argv) == 3 and sys.argv[1] == '--publish':
        sys.exit(_publisher_main(sys.argv[2]))
    print('usage: test_vision_msgs.py --publish TOPIC', file=sys.stderr)
    sys.exit(2)
