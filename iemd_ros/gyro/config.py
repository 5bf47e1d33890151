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

"""The gyro prior's parameters (:class:`GyroConfig`): extrinsic, bias, time offset, IMU buffer."""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from iemd_ros.common.params import coerce, param
from iemd_ros.gyro.imu import ImuBuffer
from iemd_ros.gyro.rotation import GyroCalibration, StillBiasEstimator
import numpy as np

__all__ = ['GyroConfig']

IDENTITY = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


@dataclass
class GyroConfig:
    """
    Parameters of :class:`~iemd_ros.gyro.predictor.GyroPredictor`.

    ``w_cam = R_cam_imu (w_imu - bias)`` and ``t_imu = t_cam + time_offset_ns``.  Each field is
    declared with its meaning, unit and range (:func:`~iemd_ros.common.params.param`).

    Raises
    ------
    ValueError
        For a value of the wrong kind or out of its range, an ``R_cam_imu`` that is not a proper
        rotation, or settings the IMU buffer or the still-bias estimator refuse.

    """

    time_offset_ns: int = param(
        0,
        "camera-IMU time offset, t_imu = t_cam + offset (Kalibr's timeshift_cam_imu)",
        unit='ns',
        range=(-1e9, 1e9),
        decision='gyro-time-offset',
    )
    R_cam_imu: tuple[float, ...] = param(
        IDENTITY,
        'IMU -> camera rotation, 9 values row-major',
        length=9,
        range=(-1.0, 1.0),
        eq='eq. (22)',
    )
    bias: tuple[float, ...] = param(
        (0.0, 0.0, 0.0),
        'gyro bias [x, y, z] in the IMU frame',
        unit='rad/s',
        length=3,
        range=(-10.0, 10.0),
    )
    still_bias_samples: int = param(
        0,
        'estimate the bias from the first N samples if the camera is still (0: off)',
        range=(0, 100_000),
    )
    still_bias_max_std: float = param(
        0.02,
        'largest per-axis standard deviation of a still start',
        unit='rad/s',
        range=(1e-6, 1.0),
    )
    saturation: float = param(
        35.0,
        "reject samples with |w_i| >= this: a MEMS gyro's full scale (2000 deg/s = "
        '34.9 rad/s is the largest common one)',
        unit='rad/s',
        range=(1.0, 1000.0),
        decision='gyro-saturation',
    )
    max_gap_ns: int = param(
        50_000_000, 'IMU sample spacing reported as a gap', unit='ns', range=(1e6, 1e10)
    )
    buffer_ns: int = param(10_000_000_000, 'IMU history kept', unit='ns', range=(1e8, 1e14))
    buffer_samples: int = param(20_000, 'IMU samples kept at most', range=(2, 1e8))
    allow_gaps: bool = param(False, 'use a rotation integrated across a gap (else no prior)')
    coning: bool = param(
        True, 'coning correction of the rotation integration', decision='imu-integration'
    )

    def __post_init__(self):
        if self.R_cam_imu is None:
            self.R_cam_imu = IDENTITY
        if self.bias is None:
            self.bias = (0.0, 0.0, 0.0)
        if isinstance(self.R_cam_imu, np.ndarray):
            self.R_cam_imu = self.R_cam_imu.ravel()
        coerce(self, 'gyro.')
        try:
            GyroCalibration.checked(self.rotation, self.bias)
            ImuBuffer.check_settings(
                self.buffer_ns, self.buffer_samples, self.saturation, self.max_gap_ns
            )
            StillBiasEstimator.check_settings(self.still_bias_samples, self.still_bias_max_std)
        except ValueError as exc:
            raise ValueError(f'gyro: {exc}') from None

    @property
    def rotation(self) -> np.ndarray:
        """R_cam_imu as a 3x3 array."""
        return np.asarray(self.R_cam_imu, dtype=float).reshape(3, 3)

    @classmethod
    def from_dict(cls, values: dict) -> 'GyroConfig':
        """
        Configure from plain values by field name (missing: defaults).

        Parameters
        ----------
        values : dict
            Field name -> value.

        Returns
        -------
        GyroConfig
            The configuration.

        Raises
        ------
        ValueError
            For unknown names or bad values.

        """
        unknown = set(values) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f'unknown gyro parameters: {", ".join(sorted(unknown))}')
        return cls(**values)

    def to_dict(self) -> dict:
        """
        Plain values by field name, which round-trip through :meth:`from_dict`.

        Returns
        -------
        dict
            Field name -> value, sequences as lists.

        """
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}
