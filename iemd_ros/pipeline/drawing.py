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
A tracking result drawn on its frame (ROS-free).

The node's ``~/debug_image`` and the replay's video.
"""
from __future__ import annotations

import cv2
from iemd_ros.pipeline.results import FrameResult
import numpy as np

__all__ = ['draw_result', 'draw_results', 'box_colour']

# BGR
TRACKING, LOST, INIT, GYRO = (0, 200, 0), (0, 0, 255), (255, 200, 0), (0, 220, 255)


def draw_result(frame: np.ndarray, r: FrameResult) -> np.ndarray:
    """
    Return a tracking result drawn on a BGR copy of its frame (:func:`draw_results` of one result).

    Parameters
    ----------
    frame : ndarray
        HxW grey or HxWx3 BGR uint8 frame.
    r : FrameResult
        The frame's result.

    Returns
    -------
    ndarray
        The HxWx3 BGR drawing.

    """
    return draw_results(frame, [r])


def box_colour(r: FrameResult) -> tuple[int, int, int]:
    """
    Return the BGR colour of a result's box.

    Light blue on the init frame, green tracking, red lost or rejected.

    Parameters
    ----------
    r : FrameResult
        The result.

    Returns
    -------
    tuple of int
        B, G, R.

    """
    return INIT if r.is_init else TRACKING if r.tracking else LOST


def draw_results(frame: np.ndarray, results) -> np.ndarray:
    """
    Return the results of one frame (one per target) drawn on a BGR copy of it.

    Each box (:func:`box_colour`), the gyro's predicted box (thin, yellow) and a line per result
    with the stamp and state (and the target's id when there are several).

    Parameters
    ----------
    frame : ndarray
        HxW grey or HxWx3 BGR uint8 frame.
    results : sequence of FrameResult
        The frame's results.

    Returns
    -------
    ndarray
        The HxWx3 BGR drawing.

    """
    img = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR) if frame.ndim == 2 else frame.copy()
    for i, r in enumerate(results):
        if r.gyro_box is not None:
            _rect(img, r.gyro_box, GYRO, 1)
        if r.box is not None:
            _rect(img, r.box, box_colour(r), 2)
        label = f'[{r.target_id}] ' if len(results) > 1 else ''
        text = f'{label}{r.stamp_ns / 1e9:.3f}s {_status(r)}'
        for colour, thickness in (((0, 0, 0), 3), ((255, 255, 255), 1)):
            cv2.putText(
                img,
                text,
                (5, 18 + 18 * i),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.5,
                colour,
                thickness,
                cv2.LINE_AA,
            )
    return img


def _status(r: FrameResult) -> str:
    if r.is_init:
        return 'initialized'
    if r.rejection is not None or r.box is None:
        return r.reason or r.state.value
    return (
        f'{r.state.value}{" (held)" if r.held else ""} EMD {r.emd:.4f} it {r.iterations} '
        f'{"gyro" if r.gyro_used else "no gyro"} '
        f'{r.processing_ms:.0f} ms'
    )


def _rect(img: np.ndarray, box, colour, thickness: int) -> None:
    """Box ``(x, y, w, h)`` covering pixels ``x .. x+w-1`` (0-based)."""
    x, y, w, h = box
    cv2.rectangle(
        img,
        (int(round(x)), int(round(y))),
        (int(round(x + w - 1)), int(round(y + h - 1))),
        colour,
        thickness,
    )
