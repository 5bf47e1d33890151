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
launch/tracker.launch.xml agrees with the package it launches.

launch_ros has no PyPI wheel, so ``ros2 launch`` cannot run here; these tests read the file as
launch_ros would (``$(var name)`` from the declared args, ``$(find-pkg-share iemd_ros)`` the
package's share folder, whose config/ is the source tree's config/ installed) and check every name
in it against the package: the executable, the node name its parameter file is keyed by, and the
topics it remaps.  That the file is installed is checked in test_node_process.py, against the
installed prefix.
"""
import ast
import re
import xml.etree.ElementTree as ET

from catkin_pkg import package as catkin_package
from helpers import REPO
from iemd_ros.ros.parameters import NODE_NAME
import pytest
import yaml

LAUNCH = REPO / 'launch' / 'tracker.launch.xml'
SUBSTITUTION = re.compile(r'\$\((\S+)\s+([^)]*)\)')


def _launch():
    root = ET.parse(LAUNCH).getroot()
    args = {a.get('name'): a.get('default') for a in root.iter('arg')}
    return root, args


def _resolve(text: str, args: dict) -> str:
    """``text`` with its substitutions replaced by their defaults; unknown ones fail the test."""
    def one(match):
        kind, value = match.group(1), match.group(2).strip()
        if kind == 'var':
            assert value in args, f'$(var {value}) is not a declared arg'
            return _resolve(args[value], args)
        assert (kind, value) == ('find-pkg-share', 'iemd_ros'), (
            f'unexpected substitution {match.group(0)}'
        )
        return str(REPO)

    return SUBSTITUTION.sub(one, text)


def test_every_substitution_names_a_declared_arg_and_every_arg_is_used_and_described():
    root, args = _launch()
    assert root.tag == 'launch'
    text = LAUNCH.read_text()
    for name in args:
        assert f'$(var {name})' in text, f'arg {name} is declared but never used'
    for arg in root.iter('arg'):
        assert arg.get('description'), f'arg {arg.get("name")} has no description'
    for element in root.iter():
        for value in element.attrib.values():
            _resolve(value, args)


def test_node_is_the_packages_tracker_executable_named_as_its_parameter_file_says():
    root, args = _launch()
    (node,) = root.iter('node')
    assert node.get('pkg') == catkin_package.parse_package(REPO).name
    setup = ast.parse((REPO / 'setup.py').read_text())
    executables = next(
        ast.literal_eval(n.value)
        for n in ast.walk(setup)
        if isinstance(n, ast.Assign) and getattr(n.targets[0], 'id', '') == 'EXECUTABLES'
    )
    assert node.get('exec') in executables and executables[node.get('exec')] == (
        'iemd_ros.ros.node',
        'main',
    )
    assert node.get('name') == NODE_NAME
    (params,) = [p for p in node.iter('param') if p.get('from')]
    params_file = REPO.joinpath(_resolve(params.get('from'), args))
    assert params_file.is_file(), params_file
    assert list(yaml.safe_load(params_file.read_text())) == [node.get('name')], (
        "the parameter file must be keyed by the launched node's name, or the node ignores it"
    )


def test_remaps_rename_topics_the_node_really_has(ctx):
    rclpy_node = pytest.importorskip('iemd_ros.ros.node')
    root, args = _launch()
    (node,) = root.iter('node')
    tracker = rclpy_node.TrackerNode(context=ctx)
    try:
        topics = {e.topic_name for e in (*tracker.subscriptions, *tracker.publishers)}
    finally:
        tracker.destroy_node()
    remapped = [r.get('from') for r in node.iter('remap')]
    assert {'image', 'imu', 'camera_info', 'detections'} <= set(remapped)
    for name in remapped:
        assert not name.startswith(('/', '~')), (
            f"remap {name}: the node's topics are relative names"
        )
        assert f'/{name}' in topics, f'remap {name}: the node has no such topic ({sorted(topics)})'
