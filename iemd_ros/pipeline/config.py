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
The pipeline's parameters (:class:`PipelineConfig`).

The tracker's and the gyro's groups and its own.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields

from iemd_ros.common.params import coerce, param
from iemd_ros.gyro import GyroConfig
from iemd_ros.pipeline.parameter_file import NODE_NAME, read_parameter_file, read_yaml
from iemd_ros.tracking import TrackerConfig

__all__ = ['PipelineConfig', 'GROUPS']

# parameter groups: tracker.<name>, gyro.<name>
GROUPS = {'tracker': TrackerConfig, 'gyro': GyroConfig}


@dataclass
class PipelineConfig:
    """
    Tracker + gyro settings and the pipeline's own.

    (``PipelineConfig(tracker=TrackerConfig(...))``).

    ``tracker`` and ``gyro`` are the groups ``tracker.<name>`` and ``gyro.<name>``; every field is
    declared with its meaning, unit and range (:func:`~iemd_ros.common.params.param`).

    Raises
    ------
    ValueError
        When ``tracker`` or ``gyro`` is not of its class, or for an invalid value.

    """

    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    gyro: GyroConfig = field(default_factory=GyroConfig)
    use_gyro: bool = param(True, 'use the gyro prior K R^T K^-1', eq='section 5.2, Algorithm 3')
    imu_wait_ms: float = param(
        15.0,
        'longest wait for IMU samples covering a frame before tracking it without the prior',
        unit='ms',
        range=(0.0, 1000.0),
    )
    clock_reset_ms: float = param(
        1000.0,
        'a stamp this much earlier than the previous one is a clock reset (smaller '
        'steps back reject the frame)',
        unit='ms',
        range=(1.0, 1e7),
    )
    score_emd_scale: float = param(
        0.25, 'detection score = exp(-EMD / score_emd_scale)', range=(1e-6, 100.0)
    )
    watchdog_ms: float = param(
        2000.0,
        'a tracker update still running after this long is abandoned: the frame is '
        'answered without a detection and the tracker rebuilt at its last good window '
        '(the node; an offline replay waits for every update)',
        unit='ms',
        range=(100.0, 600_000.0),
        decision='watchdog',
    )

    def __post_init__(self):
        for name, kind in GROUPS.items():
            if not isinstance(getattr(self, name), kind):
                raise ValueError(f'{name} must be a {kind.__name__}')
        coerce(self)

    @classmethod
    def from_dict(cls, values: dict) -> 'PipelineConfig':
        """
        Configure from ``{"tracker": {...}, "gyro": {...}, "use_gyro": ..., ...}``.

        (missing keys: defaults).

        Parameters
        ----------
        values : dict
            The parameters by name, the groups as mappings.

        Returns
        -------
        PipelineConfig
            The configuration.

        Raises
        ------
        ValueError
            For unknown names, a group that is not a mapping, or invalid values.

        """
        v = dict(values)
        unknown = set(v) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f'unknown pipeline parameters: {", ".join(sorted(unknown))}')
        for name, kind in GROUPS.items():
            group = v.get(name, {})
            if not isinstance(group, dict):
                raise ValueError(f'{name} must be a mapping of its parameters, got {group!r}')
            v[name] = kind.from_dict(group)
        try:
            return cls(**v)
        except TypeError as exc:
            raise ValueError(f'invalid pipeline parameters: {exc}') from None

    @classmethod
    def from_parameters(cls, params: dict) -> 'PipelineConfig':
        """
        Configure from parameters by their dotted names (``tracker.n_iter``, ``use_gyro``).

        Names of no pipeline parameter (the node's own: ``initial_box``, ...) are ignored.

        Parameters
        ----------
        params : dict
            Dotted name -> value.

        Returns
        -------
        PipelineConfig
            The configuration.

        Raises
        ------
        ValueError
            For a group given a single value, a single parameter given as a group, or invalid
            values.

        """
        own = {f.name for f in fields(cls)} - set(GROUPS)
        values: dict = {name: {} for name in GROUPS}
        for key, value in params.items():
            group, dot, name = str(key).partition('.')
            if group in GROUPS:
                if not dot:
                    raise ValueError(
                        f'{group} must be a group of parameters ({group}.<name>), got {value!r}'
                    )
                values[group][name] = value
            elif group in own:
                if dot:
                    raise ValueError(f'{group} is a single parameter, not a group: got {key!r}')
                values[group] = value
        return cls.from_dict(values)

    @classmethod
    def from_yaml(cls, path, node_name: str = NODE_NAME) -> 'PipelineConfig':
        """
        Configure from a YAML file.

        A ROS parameter file (``config/tracker.yaml``) read as the node ``node_name`` reads it
        (:func:`~iemd_ros.pipeline.parameter_file.read_parameter_file`), or a plain
        ``{tracker: {...}, gyro: {...}, use_gyro: ...}`` mapping (:meth:`from_dict`).

        Parameters
        ----------
        path : str or path-like
            The YAML file.
        node_name : str, optional
            The node whose parameters a ROS parameter file gives.

        Returns
        -------
        PipelineConfig
            The configuration.

        Raises
        ------
        ValueError
            Naming the file, for a file that cannot be read or holds invalid values.

        """
        params = read_parameter_file(path, node_name)
        try:
            return (
                cls.from_dict(read_yaml(path)) if params is None else cls.from_parameters(params)
            )
        except ValueError as exc:
            raise ValueError(f'config {path}: {exc}') from None

    def to_dict(self) -> dict:
        """
        Plain values, which round-trip through :meth:`from_dict`.

        Returns
        -------
        dict
            Parameter name -> value, the groups as mappings.

        """
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        for name in GROUPS:
            d[name] = getattr(self, name).to_dict()
        return d
