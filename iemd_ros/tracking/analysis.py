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
Probes into a running tracker for the benchmarks.

The EMD of any window against its target model, and Algorithm 1 alone from a window.  Neither
changes the tracker's state.
"""
from __future__ import annotations

from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.tracking.candidate import CandidateModel, SearchContext
from iemd_ros.tracking.config import TrackerConfig
from iemd_ros.tracking.tracker import (
    _box,
    _check_box,
    _check_frame,
    _not_optimal,
    IemdTracker,
    TrackResult,
)
import numpy as np

__all__ = ['search_context', 'descend', 'descent_tracker']


def descent_tracker() -> IemdTracker:
    """
    Return a tracker that descends as the paper's system does, the shipped tracker otherwise.

    The shipped tracker does not descend (``n_iter`` 0); this one has the ``paper`` preset's
    ``n_iter``, for :func:`descend`.

    Returns
    -------
    IemdTracker
        Not initialized.

    """
    return IemdTracker(TrackerConfig(n_iter=TrackerConfig.preset('paper').n_iter))


def search_context(
    tracker: IemdTracker, pyramid: ImagePyramid, angle: float = 0.0
) -> SearchContext:
    """
    Return the context the tracker's search samples windows in on a frame.

    The context is the tracker's current target model and dictionary.

    ``CandidateModel(search_context(tracker, pyramid), centre, size).emd()`` scores any window.

    Parameters
    ----------
    tracker : IemdTracker
        An initialized tracker; it is not changed.
    pyramid : ImagePyramid
        The frame's pyramid.
    angle : float, optional
        Orientation of the windows in the image, radians.

    Returns
    -------
    SearchContext
        The context of the tracker's search on ``pyramid``'s frame.

    Raises
    ------
    RuntimeError
        When the tracker is not initialized.

    """
    if tracker._center is None:
        raise RuntimeError('search_context() needs an initialized tracker')
    return tracker._context(pyramid, angle)


def descend(tracker: IemdTracker, frame: np.ndarray, box) -> TrackResult:
    """
    Algorithm 1 alone on ``frame`` from an axis-aligned window, at that size.

    Against the tracker's current target model: no other starts, no filter, no scale search; the
    tracker is unchanged.

    Parameters
    ----------
    tracker : IemdTracker
        An initialized tracker.
    frame : ndarray
        HxW or HxWx3 (BGR) uint8 image.
    box : sequence of 4 float
        The starting window (x, y, w, h), 0-based top-left corner and size in pixels.

    Returns
    -------
    TrackResult
        The window the descent converged to, its EMD and cost, and whether it counts as lost.

    Raises
    ------
    RuntimeError
        When the tracker is not initialized.
    ValueError
        For a bad frame or box, or a tracker that does not descend (``n_iter`` 0: see
        :func:`descent_tracker`).

    """
    if tracker._center is None:
        raise RuntimeError('descend() needs an initialized tracker')
    if tracker.config.n_iter == 0:
        raise ValueError('descend() needs a tracker that descends (n_iter > 0): descent_tracker()')
    _check_frame(frame)
    x, y, w, h = _check_box(box, frame.shape)
    size = np.array([w, h], dtype=np.float64)
    start = CandidateModel(
        search_context(tracker, ImagePyramid(to_gray(frame))), box_centre((x, y, w, h)), size
    )
    end = tracker._descend(start)
    cause, reason = tracker._lost_reason(end.emd, end.center, size, 0.0, frame.shape)
    return TrackResult(
        box=_box(end.center, size),
        emd=end.emd,
        iterations=end.iterations,
        lost=cause is not None,
        codings=1 + end.codings,
        solver_warnings=_not_optimal(start.emd()[1]) + end.warnings,
        reason=reason,
        cause=cause,
    )
