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
One source per parameter.

The declarations, and everything made from them (descriptors, parameter files, docs).
"""
from dataclasses import dataclass
import re

from helpers import REPO
from iemd_ros import TrackerConfig
from iemd_ros.common.params import Choice, coerce, param, specs
from iemd_ros.gyro import GyroConfig
from iemd_ros.pipeline import PipelineConfig
from iemd_ros.ros.parameters import (
    descriptor,
    NodeConfig,
    parameter_file,
    parameter_table,
    parameters,
)
from iemd_ros.tracking.config import Gradient, PRESETS, ScaleEstimator
import numpy as np
import pytest

DECISIONS = set(re.findall(r'<a id="([a-z0-9-]+)">', (REPO / 'docs' / 'decisions.md').read_text()))


@pytest.mark.parametrize(
    'preset, path', [('default', 'config/tracker.yaml'), ('paper', 'config/paper.yaml')]
)
def test_shipped_parameter_files_are_the_generated_ones(preset, path):
    assert (REPO / path).read_text() == parameter_file(preset), (
        'regenerate: python -m iemd_ros.ros.parameters '
        f'--yaml{"" if preset == "default" else " --preset " + preset}'
    )


def test_the_docs_parameter_table_is_the_generated_one():
    assert (REPO / 'docs' / 'parameters.md').read_text() == parameter_table(), (
        'regenerate: python -m iemd_ros.ros.parameters --markdown > docs/parameters.md'
    )


@pytest.mark.parametrize(
    'preset, path', [('default', 'config/tracker.yaml'), ('paper', 'config/paper.yaml')]
)
def test_a_parameter_file_reads_back_as_its_preset(preset, path):
    cfg = PipelineConfig.from_yaml(REPO / path)
    assert cfg.tracker == TrackerConfig.preset(preset) and cfg.gyro == GyroConfig()
    assert cfg == PipelineConfig(tracker=TrackerConfig.preset(preset))


def test_every_parameter_is_declared_with_meaning_and_a_default_inside_its_range():
    ps = parameters()
    assert len(ps) == len({p.name for p in ps}) > 50
    for p in ps:
        assert p.spec.doc.strip(), p.name
        if p.spec.decision:
            assert p.spec.decision in DECISIONS, (p.name, p.spec.decision)
        values = p.default if isinstance(p.default, list) else [p.default]
        if p.spec.range is not None:
            assert all(p.spec.range[0] <= v <= p.spec.range[1] for v in values), p.name


def test_descriptors_carry_the_declaration():
    by_name = {p.name: p for p in parameters()}
    alpha = descriptor(by_name['tracker.alpha'])
    assert (
        alpha.floating_point_range[0].from_value == 0.001
        and alpha.floating_point_range[0].to_value == 0.999
    )
    assert 'eq. (ground distance)' in alpha.description and not alpha.read_only
    n_iter = descriptor(by_name['tracker.n_iter'])
    assert (n_iter.integer_range[0].from_value, n_iter.integer_range[0].to_value) == (0, 500)
    assert (
        descriptor(by_name['tracker.gradient']).additional_constraints
        == 'one of: appearance, paper'
    )
    assert (
        descriptor(by_name['tracker.template_size']).additional_constraints
        == 'each value in [8, 96]'
    )
    assert (
        descriptor(by_name['reliable_qos']).read_only
        and descriptor(by_name['initial_box']).dynamic_typing
    )
    assert '[ms]' in descriptor(by_name['imu_wait_ms']).description


def test_presets_are_selectable_and_the_paper_one_is_the_papers_system():
    assert PRESETS == ('default', 'paper') and TrackerConfig.preset('default') == TrackerConfig()
    paper = TrackerConfig.preset('paper')
    assert (paper.gradient, paper.scale_estimator, paper.n_particles) == (
        Gradient.PAPER,
        ScaleEstimator.EMD,
        4,
    )
    assert (
        paper.translation_weight,
        paper.colour_weight,
        paper.flow_start,
        paper.update_confidence,
    ) == (0, 0, False, 0)
    with pytest.raises(ValueError, match="unknown tracker preset 'fast'"):
        TrackerConfig.preset('fast')


class _Mode(Choice):
    A = 'a'
    B = 'b'


@dataclass
class _Toy:
    count: int = param(3, 'a count', range=(0, 10))
    rate: float = param(0.5, 'a rate', unit='Hz', range=(0.0, 1.0))
    flag: bool = param(True, 'a flag')
    mode: _Mode = param(_Mode.A, 'a mode')
    size: tuple[int, int] = param((4, 4), 'a size', range=(1, 8), length=2)
    name: str = param('x', 'a name')

    def __post_init__(self):
        coerce(self, 'toy.')


@pytest.mark.parametrize(
    'kwargs, message',
    [
        ({'count': 11}, r'toy.count must be in \[0, 10\], got 11'),
        ({'count': 2.5}, 'toy.count must be an integer'),
        ({'count': '3'}, 'toy.count must be a number'),
        ({'count': True}, 'toy.count must be a number'),
        ({'rate': float('nan')}, 'toy.rate must be finite'),
        ({'rate': 1.5}, r'toy.rate must be in \[0, 1\] Hz'),
        ({'flag': 1}, 'toy.flag must be true or false'),
        ({'mode': 'c'}, "toy.mode must be one of a, b, got 'c'"),
        ({'size': (4, 4, 4)}, 'toy.size must have 2 values'),
        ({'size': (4, 9)}, r'toy.size\[1\] must be in \[1, 8\]'),
        ({'size': 5}, 'toy.size must be a list'),
        ({'name': 3}, 'toy.name must be text'),
    ],
)
def test_coerce_refuses_values_outside_the_declaration(kwargs, message):
    with pytest.raises(ValueError, match=message):
        _Toy(**kwargs)


def test_coerce_converts_to_the_declared_types():
    toy = _Toy(count=np.int64(4), rate=1, flag=np.bool_(False), mode='b', size=[2.0, 3], name='y')
    assert (toy.count, toy.rate, toy.flag, toy.mode, toy.size) == (4, 1.0, False, _Mode.B, (2, 3))
    assert type(toy.count) is int and type(toy.rate) is float and type(toy.size[0]) is int
    assert [f.name for f, _ in specs(_Toy)] == ['count', 'rate', 'flag', 'mode', 'size', 'name']


def test_node_config_is_declared_the_same_way():
    with pytest.raises(ValueError, match='image_transport must be one of raw, compressed'):
        NodeConfig(image_transport='theora')
    with pytest.raises(ValueError, match=r'frame_buffer_size must be in \[1, 1000\]'):
        NodeConfig.from_parameters({'frame_buffer_size': 0, 'unrelated': 1})
