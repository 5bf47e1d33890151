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
Model memory in time rather than in frames.

The models' learning rates (fDSST's scale template, Staple's colour histograms, the response's
running mean) and STRCF's temporal regularization are per frame, as their papers set them on OTB's
frames (``TrackerConfig.reference_rate``).  A frame that comes ``frames`` such frame intervals
after the last one (a 10 Hz camera's frames: 3; a frame after one the node dropped: 2) learns as
that many frames in turn would: a running average at rate ``eta`` keeps ``(1 - eta)^frames`` of its
old value, and STRCF's temporal penalty ``mu / 2 ||f - f_{t-1}||^2``, a random-walk prior of
variance ``1 / mu`` per frame on the filter, becomes ``mu / frames``.
"""
from __future__ import annotations

__all__ = ['rate_over', 'running_average', 'penalty_over']


def rate_over(rate: float, frames: float) -> float:
    """
    Return the learning rate of a running average over ``frames`` reference frames.

    Parameters
    ----------
    rate : float
        The rate per reference frame, in (0, 1].
    frames : float
        The frame's interval in reference frame intervals, > 0.

    Returns
    -------
    float
        ``1 - (1 - rate)^frames``; ``rate`` itself for one frame (exactly).

    """
    if frames == 1.0:
        return rate
    return 1.0 - (1.0 - rate) ** frames


def running_average(old, new, rate: float, frames: float):
    """
    Return a running average at ``rate`` per reference frame after ``new`` over ``frames`` of them.

    Parameters
    ----------
    old, new : float or ndarray
        The average so far and the frame's value.
    rate : float
        The rate per reference frame, in (0, 1].
    frames : float
        The frame's interval in reference frame intervals, > 0.

    Returns
    -------
    float or ndarray
        ``(1 - r) old + r new`` with ``r`` = :func:`rate_over` ``(rate, frames)``.

    """
    r = rate_over(rate, frames)
    return (1 - r) * old + r * new


def penalty_over(mu: float, frames: float) -> float:
    """
    Return a random-walk prior's weight ``mu`` per reference frame over ``frames`` of them.

    Parameters
    ----------
    mu : float
        The weight (inverse variance) per reference frame, >= 0.
    frames : float
        The frame's interval in reference frame intervals, > 0.

    Returns
    -------
    float
        ``mu / frames``.

    """
    return mu / frames
