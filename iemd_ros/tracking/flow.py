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
Median optical flow of the target window: one more start of the search (section 6.1).

The paper meets abrupt motion with extra starting points around the prediction.  The iEMD
descent only converges from a few pixels off the target (docs/decisions.md#capture-range), so a
start placed where the target's own pixels moved is worth more than a blind ring of them: corners
inside the window (Shi-Tomasi) are followed into the new frame by pyramidal Lucas-Kanade, points
whose forward-backward error exceeds ``max_error`` px are dropped (Kalal et al.'s Median Flow),
and the median of the rest moves the window.  The start is only a candidate: the tracker scores it
with the EMD like every other start, so a flow that followed an occluder or the background is
outvoted by the model.
"""
from __future__ import annotations

import cv2
from iemd_ros.common.boxes import map_points
import numpy as np

N_POINTS = 60  # corners followed per frame, at most
MIN_POINTS = 4  # fewer surviving points give no start
# Lucas-Kanade window and pyramid depth: motions up to about 5 * 2**3 = 40 px beyond the prediction
# (docs/decisions.md#flow-start).
_LK = {'winSize': (11, 11), 'maxLevel': 3}


def window_flow(previous: np.ndarray, current: np.ndarray, box, prior: np.ndarray | None = None,
                max_error: float = 2.0) -> np.ndarray | None:
    """
    Median motion of the content of ``box`` from ``previous`` into ``current``, beyond ``prior``.

    The motion is the residual beyond what ``prior`` predicts: the window's predicted centre plus
    the returned residual is the flow's starting point.  Only a region around the window and its
    prediction is processed (one window size of margin), so the cost does not grow with the frame.

    Parameters
    ----------
    previous, current : ndarray
        HxW uint8 grey frames.
    box : array_like
        (x, y, w, h) in ``previous``.
    prior : ndarray, optional
        The 3x3 homography from ``previous`` into ``current`` pixels (the gyro prediction), which
        seeds the Lucas-Kanade search.
    max_error : float, optional
        Forward-backward error, px, above which a point is dropped.

    Returns
    -------
    ndarray or None
        (dx, dy) in px; None when too few points can be followed, when ``prior`` takes the window
        out of the image (or to infinity), or for frames of different sizes.

    """
    if previous.shape != current.shape:
        return None
    x, y, w, h = (float(v) for v in box)
    corners = np.array([[x, y], [x + w, y], [x, y + h], [x + w, y + h]])
    with np.errstate(divide='ignore', invalid='ignore'):
        predicted = corners if prior is None else map_points(prior, corners)
    image = np.array([previous.shape[1], previous.shape[0]], dtype=float)
    # A prior taking the window to infinity or out of the image leaves nothing to follow (and a
    # region of non-finite corners would be cast to INT_MIN, an empty image on which Lucas-Kanade
    # never returns).
    if (
        not np.all(np.isfinite(predicted))
        or np.any(predicted.max(0) < 0)
        or np.any(predicted.min(0) > image)
    ):
        return None
    margin = max(w, h)
    x0, y0 = np.clip(
        np.floor(np.minimum(corners.min(0), predicted.min(0)) - margin), 0, image
    ).astype(int)
    x1, y1 = np.clip(
        np.ceil(np.maximum(corners.max(0), predicted.max(0)) + margin), 0, image
    ).astype(int)
    # Corners are searched in the window only; it lies inside the region, so its size check covers
    # both.
    bx0, by0 = max(int(np.floor(x)), 0), max(int(np.floor(y)), 0)
    window = previous[by0:max(int(np.ceil(y + h)), by0), bx0:max(int(np.ceil(x + w)), bx0)]
    if min(window.shape) < 8:
        return None
    points = cv2.goodFeaturesToTrack(window, N_POINTS, 0.01, 3)
    if points is None or len(points) < MIN_POINTS:
        return None
    points += np.array([bx0 - x0, by0 - y0], dtype=np.float32)
    offset = np.array([x0, y0], dtype=np.float32)
    with np.errstate(divide='ignore', invalid='ignore'):
        guess = (
            points
            if prior is None
            else (map_points(prior, points.reshape(-1, 2) + offset) - offset)
        )
    if not np.all(np.isfinite(guess)):
        return None
    guess = np.ascontiguousarray(guess, dtype=np.float32).reshape(-1, 1, 2)
    prev_roi, cur_roi = previous[y0:y1, x0:x1], current[y0:y1, x0:x1]
    moved, found, _ = cv2.calcOpticalFlowPyrLK(
        prev_roi, cur_roi, points, guess.copy(), flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **_LK
    )
    # The backward pass is seeded where the prior alone takes the points back, not at the points
    # themselves: seeded at the answer, it could hardly miss it, and the check would pass anything.
    back, found_back, _ = cv2.calcOpticalFlowPyrLK(
        cur_roi,
        prev_roi,
        moved,
        moved - (guess - points),
        flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
        **_LK,
    )
    error = np.linalg.norm((back - points).reshape(-1, 2), axis=1)
    good = (found.ravel() == 1) & (found_back.ravel() == 1) & (error < max_error)
    if good.sum() < MIN_POINTS:
        return None
    return np.median((moved - guess).reshape(-1, 2)[good], axis=0).astype(np.float64)
