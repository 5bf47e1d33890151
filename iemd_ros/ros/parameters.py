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
The node's ROS parameters, all made from the declarations of the configurations.

The declarations are those of :mod:`iemd_ros.common.params`.

Every parameter is declared once: the pipeline's (``use_gyro``, ...), its groups' (``tracker.*``,
``gyro.*``) and the node's own (:class:`NodeConfig`).  From those come the node's parameter
descriptors (:func:`descriptor`), the shipped parameter files and the parameter table of the docs::

    python -m iemd_ros.ros.parameters --yaml > config/tracker.yaml
    python -m iemd_ros.ros.parameters --yaml --preset paper > config/paper.yaml
    python -m iemd_ros.ros.parameters --markdown > docs/parameters.md
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass
import sys
import typing

from iemd_ros.common.limits import IMAGE_SIDE, LIMITS
from iemd_ros.common.params import Choice, coerce, number_text, param, Spec, specs
from iemd_ros.messages.conversions import CLASS_ID, DETECTION_ID
from iemd_ros.pipeline.config import PipelineConfig
from iemd_ros.pipeline.parameter_file import NODE_NAME
from iemd_ros.tracking import TrackerConfig
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

__all__ = [
    'ImageTransport',
    'NodeConfig',
    'Parameter',
    'parameters',
    'descriptor',
    'parameter_file',
    'parameter_table',
    'NODE_NAME',
]


class ImageTransport(Choice):
    """How the node receives images (image_transport's names)."""

    RAW = 'raw'  # sensor_msgs/Image on ``image``
    COMPRESSED = 'compressed'  # sensor_msgs/CompressedImage (jpeg/png) on ``<image>/compressed``


@dataclass
class NodeConfig:
    """The node's own parameters (the pipeline's: :class:`~iemd_ros.pipeline.PipelineConfig`)."""

    initial_box: tuple[float, ...] = param(
        (),
        '[x, y, w, h] of the target, applied to the next frame (0-based '
        'top-left + size); [] for none',
        unit='px',
        range=(-IMAGE_SIDE.high, IMAGE_SIDE.high),
    )
    reliable_qos: bool = param(
        False,
        'reliable QoS for image, imu and camera_info instead of sensor-data (best effort)',
        read_only=True,
    )
    image_transport: ImageTransport = param(
        ImageTransport.RAW,
        'raw: sensor_msgs/Image on image; compressed: '
        'sensor_msgs/CompressedImage (jpeg/png) on <image>/compressed',
        read_only=True,
    )
    frame_buffer_size: int = param(
        30, 'recent frames kept for ~/init', range=(1, 1000), read_only=True
    )
    init_tolerance_ms: float = param(
        20.0,
        'largest stamp difference between ~/init and a buffered frame',
        unit='ms',
        range=(0.0, 10_000.0),
    )
    diagnostics_period_s: float = param(
        1.0, 'period of /diagnostics', unit='s', range=(0.01, 60.0), read_only=True
    )
    input_timeout_s: float = param(
        2.0,
        'warn when no image or IMU message arrived for this long',
        unit='s',
        range=(0.01, 3600.0),
    )
    class_id: str = param(CLASS_ID, 'class_id of the published hypotheses')
    detection_id: str = param(
        DETECTION_ID, 'id of the target of initial_box and of an ~/init without an id'
    )
    min_rate_hz: float = param(
        1.0,
        'detections slower than this (less the tolerance) are a WARN in /diagnostics '
        "(diagnostic_updater's FrequencyStatus)",
        unit='Hz',
        range=(0.0, 10_000.0),
    )
    max_rate_hz: float = param(
        0.0,
        'detections faster than this (plus the tolerance) are a WARN; 0 for no upper bound',
        unit='Hz',
        range=(0.0, 10_000.0),
    )
    rate_tolerance: float = param(
        0.1, 'relative tolerance of min_rate_hz and max_rate_hz', range=(0.0, 1.0)
    )
    rate_window: int = param(
        5, "diagnostics periods the detections' rate is measured over", range=(1, 1000)
    )
    stamp_age_min_s: float = param(
        -1.0,
        'a detection stamped more than this in the future at publication is an '
        "ERROR (diagnostic_updater's TimeStampStatus; negative: in the future)",
        unit='s',
        range=(-3600.0, 3600.0),
    )
    stamp_age_max_s: float = param(
        5.0,
        'a detection whose stamp is older than this at publication is an ERROR',
        unit='s',
        range=(-3600.0, 1e9),
    )

    def __post_init__(self):
        coerce(self)

    @classmethod
    def from_parameters(cls, params: dict) -> 'NodeConfig':
        """From parameters by name (others are ignored)."""
        return cls(**{f.name: params[f.name] for f, _ in specs(cls) if f.name in params})


@dataclass(frozen=True)
class Parameter:
    """One ROS parameter of the node: its name, declaration and default (as a ROS value)."""

    name: str
    spec: Spec
    default: typing.Any
    kind: typing.Any  # the annotated type (int, float, bool, str, a Choice, tuple[...])
    node_only: bool  # one of NodeConfig's (the rest make the PipelineConfig)


def parameters(tracker: TrackerConfig | None = None) -> list[Parameter]:
    """
    Every parameter of the node, in the order of the parameter file.

    The node's, the pipeline's, ``gyro.*`` and ``tracker.*`` (defaults from ``tracker`` when given,
    e.g. a preset).
    """
    pipeline = PipelineConfig() if tracker is None else PipelineConfig(tracker=tracker)
    out = _of(NodeConfig(), '', True) + _of(pipeline, '', False)
    for group in ('gyro', 'tracker'):
        out += _of(getattr(pipeline, group), f'{group}.', False)
    return out


def _of(config, prefix: str, node_only: bool) -> list[Parameter]:
    hints = typing.get_type_hints(type(config))
    return [
        Parameter(
            prefix + f.name, spec, _ros_value(getattr(config, f.name)), hints[f.name], node_only
        )
        for f, spec in specs(type(config))
    ]


def _ros_value(value):
    """
    Return a configuration value as a ROS parameter value.

    (tuples as lists, choices as their strings).
    """
    if isinstance(value, tuple):
        return list(value)
    if isinstance(value, Choice):
        return value.value
    return value


def descriptor(p: Parameter) -> ParameterDescriptor:
    """
    Return the parameter's descriptor.

    Its meaning with unit, paper reference and range, its range for a GUI, its choices, and whether
    it is read-only.
    """
    d = ParameterDescriptor(
        name=p.name, description=_description(p.spec), read_only=p.spec.read_only
    )
    low_high = p.spec.range
    if low_high is not None and p.kind is int:
        d.integer_range = [
            IntegerRange(from_value=int(low_high[0]), to_value=int(low_high[1]), step=0)
        ]
    elif low_high is not None and p.kind is float:
        d.floating_point_range = [
            FloatingPointRange(
                from_value=float(low_high[0]), to_value=float(low_high[1]), step=0.0
            )
        ]
    choices = _choices(p.kind)
    if choices:
        d.additional_constraints = f'one of: {", ".join(choices)}'
    elif low_high is not None and typing.get_origin(p.kind) is tuple:
        d.additional_constraints = (
            f'each value in [{number_text(low_high[0])}, {number_text(low_high[1])}]'
        )
    if p.default == []:
        d.dynamic_typing = True  # an empty list has no ROS type: the first value given sets it
    return d


def _description(spec: Spec) -> str:
    parts = [spec.doc + (f' [{spec.unit}]' if spec.unit else '')]
    if spec.eq:
        parts.append(f'paper: {spec.eq}')
    if spec.decision:
        parts.append(f'docs/decisions.md#{spec.decision}')
    return '; '.join(parts)


def _choices(kind) -> list[str]:
    return [c.value for c in kind] if isinstance(kind, type) and issubclass(kind, Choice) else []


def _range_text(p: Parameter) -> str:
    choices = _choices(p.kind)
    if choices:
        return ' / '.join(choices)
    if p.spec.range is None:
        return ''
    low, high = p.spec.range
    return f'[{number_text(low)}, {number_text(high)}]' + (
        ' each' if typing.get_origin(p.kind) is tuple else ''
    )


def _yaml_value(value) -> str:
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return '[' + ', '.join(_yaml_value(v) for v in value) + ']'
    if isinstance(value, float):
        return repr(value)
    return str(value)


def parameter_file(preset: str = 'default') -> str:
    """
    Return the node's parameter file.

    (YAML with a comment on every parameter) with the tracker preset's values.
    """
    command = 'python -m iemd_ros.ros.parameters --yaml' + (
        '' if preset == 'default' else f' --preset {preset}'
    )
    lines = [
        f"# Parameters of the iemd_ros tracker node ({NODE_NAME}), tracker preset '{preset}'.",
        f"# Generated from the parameters' declarations by `{command}`: do not edit by hand.",
        '#   ros2 run iemd_ros tracker --ros-args --params-file config/tracker.yaml -r '
        'image:=/camera/image_raw',
        f"# `ros2 param describe /{NODE_NAME} <name>` shows a parameter's meaning, unit and range;"
        ' docs/parameters.md lists them all.',
        f'{NODE_NAME}:',
        '  ros__parameters:',
    ]
    group = None
    for p in parameters(TrackerConfig.preset(preset)):
        head, dot, name = p.name.partition('.')
        indent = '    '
        if dot:
            if head != group:
                lines.append(f'    {head}:')
                group = head
            indent = '      '
        else:
            name = head
        comment = p.spec.doc + (f' [{p.spec.unit}]' if p.spec.unit else '')
        rng = _range_text(p)
        lines.append(f'{indent}# {comment}' + (f'; {rng}' if rng else ''))
        line = f'{name}: {_yaml_value(p.default)}'
        lines.append(f'{indent}{"# " if p.default == [] else ""}{line}')
    return '\n'.join(lines) + '\n'


def parameter_table() -> str:
    """
    Return the docs' table of every parameter and of the limits of message fields.

    (``docs/parameters.md``).
    """
    lines = [
        '# Parameters of the tracker node',
        '',
        "Generated from the parameters' declarations by `python -m iemd_ros.ros.parameters "
        '--markdown`: do not '
        'edit by hand.  The node declares each one with this meaning and range (`ros2 param '
        'describe`); '
        "`config/tracker.yaml` holds the defaults and `config/paper.yaml` the paper's tracker "
        '(`TrackerConfig.preset("paper")`).  Read-only parameters take effect at start-up only.',
        '',
        '| parameter | default | unit | range | meaning | paper | decision |',
        '|---|---|---|---|---|---|---|',
    ]
    for p in parameters():
        name = f'`{p.name}`' + (' (read-only)' if p.spec.read_only else '')
        decision = (
            f'[{p.spec.decision}](decisions.md#{p.spec.decision})' if p.spec.decision else ''
        )
        lines.append(
            f'| {name} | `{_yaml_value(p.default)}` | {p.spec.unit} | {_range_text(p)} | '
            f'{p.spec.doc} | '
            f'{p.spec.eq} | {decision} |'
        )
    lines += [
        '',
        '## Limits of message fields',
        '',
        'Declared in `iemd_ros/common/limits.py` and checked where a message becomes numbers: a '
        'message out of '
        "them is rejected, and `/diagnostics` names the field and its value.  The gyro rate's "
        'limit is the '
        'parameter `gyro.saturation`.',
        '',
        '| field | range | meaning |',
        '|---|---|---|',
    ]
    lines += [f'| {name} | {limit.text} | {limit.doc} |' for name, limit in LIMITS.items()]
    return '\n'.join(lines) + '\n'


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog='python -m iemd_ros.ros.parameters', description=__doc__.split('\n\n')[0]
    )
    out = parser.add_mutually_exclusive_group(required=True)
    out.add_argument('--yaml', action='store_true', help="the node's parameter file")
    out.add_argument('--markdown', action='store_true', help='the parameter table of the docs')
    parser.add_argument('--preset', default='default', help='tracker preset of the parameter file')
    a = parser.parse_args(argv)
    sys.stdout.write(parameter_file(a.preset) if a.yaml else parameter_table())
    return 0


if __name__ == '__main__':
    sys.exit(main())
