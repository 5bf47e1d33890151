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
Box ``(x, y, w, h)`` <-> centre and size, and points mapped by a homography.

In pixel-index coordinates (ROS-free).

A box covers pixels ``x .. x+w-1`` (0-based), i.e. the region ``[x-0.5, x+w-0.5]``; its centre is
``x + (w-1)/2`` (pixel centres at integers, as ``K``, OpenCV and the tracker).
"""
from __future__ import annotations

import numpy as np

__all__ = ['box_centre', 'centre_box', 'check_box', 'map_points']


def box_centre(box) -> np.ndarray:
    """
    Centre ``(x + (w-1)/2, y + (h-1)/2)`` of boxes.

    Parameters
    ----------
    box : array_like
        (..., 4) boxes (x, y, w, h).

    Returns
    -------
    ndarray
        (..., 2) centres, pixel-index coordinates.

    """
    b = np.asarray(box, dtype=float)
    return b[..., :2] + (b[..., 2:] - 1.0) / 2.0


def centre_box(centre, size) -> np.ndarray:
    """
    Inverse of :func:`box_centre`: boxes of the given centres and sizes.

    Parameters
    ----------
    centre : array_like
        (..., 2) centres, pixel-index coordinates.
    size : array_like
        (..., 2) sizes ``(w, h)``.

    Returns
    -------
    ndarray
        (..., 4) boxes (x, y, w, h).

    """
    c, s = np.asarray(centre, dtype=float), np.asarray(size, dtype=float)
    return np.concatenate([c - (s - 1.0) / 2.0, s], axis=-1)


def check_box(box, what: str = 'box', shown=None) -> tuple[float, float, float, float]:
    """
    ``box`` as 4 floats ``(x, y, w, h)``, finite with ``w, h > 0``.

    Parameters
    ----------
    box : array_like
        The values to check.
    what : str, optional
        What the error message names.
    shown : optional
        What the error message quotes (default: ``box``), e.g. the text the values were parsed
        from.

    Returns
    -------
    tuple of float
        (x, y, w, h).

    Raises
    ------
    ValueError
        Naming ``what`` and quoting ``shown``, for anything else.

    """
    shown = box if shown is None else shown
    try:
        b = np.asarray(box, dtype=float).ravel()
    except (TypeError, ValueError):
        b = np.empty(0)
    if b.shape != (4,):
        raise ValueError(f'{what} must be 4 numbers (x, y, w, h), got {shown!r}')
    if not np.all(np.isfinite(b)):
        raise ValueError(f'{what} has non-finite values: {shown!r}')
    if b[2] <= 0 or b[3] <= 0:
        raise ValueError(f'{what} must have a positive size (w, h > 0), got {shown!r}')
    return tuple(float(v) for v in b)


def map_points(H, points) -> np.ndarray:
    """
    Pixel points mapped by a homography.

    Parameters
    ----------
    H : ndarray
        3x3 homography.
    points : array_like
        (..., 2) pixel points.

    Returns
    -------
    ndarray
        (..., 2) mapped points.

    """
    ph = np.asarray(points, dtype=float) @ H[:, :2].T + H[:, 2]
    return ph[..., :2] / ph[..., 2:3]
