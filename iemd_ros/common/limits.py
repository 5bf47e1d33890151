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
Limits of the numbers that messages carry and no parameter sets.

Each declared once with its meaning and range.

The parameters' ranges are in their declarations (:func:`iemd_ros.common.params.param`; the gyro
rate's limit is the parameter ``gyro.saturation``); these are the ranges of message fields: image
sizes, the camera matrix, target boxes. They are checked where a message becomes numbers
(:mod:`iemd_ros.messages.conversions`, :mod:`iemd_ros.gyro.camera`, the tracker's init), so that no
absurd or non-finite value reaches OpenCV or numba; docs/parameters.md lists them (generated,
:func:`iemd_ros.ros.parameters.parameter_table`), docs/decisions.md#input-limits says why::

    # ValueError: image width = 100000 px is out of [2, ...
    IMAGE_SIDE.check("image width", 100_000)
    # the range scaled by the image's larger side
    FOCAL_LENGTH.check("camera_info k[0] (fx)", 1e8, 640)
"""
from __future__ import annotations

from dataclasses import dataclass
import math

from iemd_ros.common.params import number_text

__all__ = ['Limit', 'LIMITS', 'IMAGE_SIDE', 'FOCAL_LENGTH', 'PRINCIPAL_POINT', 'TARGET_SIDE']


@dataclass(frozen=True)
class Limit:
    """
    The closed range ``[low, high]`` px of a message field.

    Absolute or in multiples of an image size.

    Parameters
    ----------
    doc : str
        What is limited and why, one line.
    low, high : float
        The bounds: pixels, or multiples of ``per``.
    per : str, optional
        The image size the bounds are multiples of ("" when they are pixels).

    """

    doc: str
    low: float
    high: float
    per: str = ''

    def check(self, field: str, value, size: float | None = None) -> float:
        """
        ``value`` as a float, if it is finite and within the limit.

        Parameters
        ----------
        field : str
            The field's name, as the error names it.
        value : float
            Its value, px.
        size : float, optional
            The image size (px) the bounds are multiples of, for a limit with ``per``.

        Returns
        -------
        float
            ``value``.

        Raises
        ------
        ValueError
            Naming the field, its value and the range in px.

        """
        low, high = self.bounds(size)
        v = float(value)
        if not (math.isfinite(v) and low <= v <= high):
            basis = (
                f'; {number_text(self.low)} to {number_text(self.high)} x the {self.per}, '
                f'{size:g} px'
                if self.per
                else ''
            )
            raise ValueError(
                f'{field} = {v:g} px is out of [{number_text(low)}, {number_text(high)}] px '
                f'({self.doc}{basis})'
            )
        return v

    def bounds(self, size: float | None = None) -> tuple[float, float]:
        """
        Return the range in px (for a limit with ``per``: at the image size ``size``).

        Parameters
        ----------
        size : float, optional
            The image size (px), required for a limit with ``per``.

        Returns
        -------
        tuple of float
            ``(low, high)``, px.

        """
        if not self.per:
            return self.low, self.high
        if size is None:
            raise ValueError(f'the limit of {self.doc} needs the {self.per}')
        return self.low * size, self.high * size

    @property
    def text(self) -> str:
        """Return the range as the docs' table writes it."""
        unit = f' x the {self.per}' if self.per else ' px'
        return f'[{number_text(self.low)}, {number_text(self.high)}]{unit}'


IMAGE_SIDE = Limit(
    "width and height of an image: the tracker's smallest frame up to 16K", 2, 16384
)
FOCAL_LENGTH = Limit(
    'fx and fy of camera_info k: a horizontal field of view from about 0.6 to 160 degrees',
    0.1,
    100.0,
    per="image's larger side",
)
PRINCIPAL_POINT = Limit(
    'cx and cy of camera_info k: inside the image or at most half its size beyond an edge',
    -0.5,
    1.5,
    per="image's width (cx) or height (cy)",
)
TARGET_SIDE = Limit(
    "w and h of a target box given to start tracking: at most the image's",
    0.0,
    1.0,
    per="image's width (w) or height (h)",
)

#: every limit by its name in the docs' table
LIMITS = {
    'image width, height': IMAGE_SIDE,
    'camera_info fx, fy': FOCAL_LENGTH,
    'camera_info cx, cy': PRINCIPAL_POINT,
    'target box w, h': TARGET_SIDE,
}
