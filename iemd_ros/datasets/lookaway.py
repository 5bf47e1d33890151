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
"Look away and back" sequences cut from real footage.

A virtual camera follows the target, pans off it until the target is out of view, holds there, and
pans back.

The virtual camera is a window of ``crop`` times the frame's size moving over the frames of an
OTB-layout sequence; its images are the window's pixels, so the footage stays real (its blur, noise
and the target's own motion) while the camera's motion is known.  It follows the target's centre
(clipped so the window stays inside the frame), then moves at ``pan_px`` pixels per frame in the
direction with the most room until the target is entirely outside it, holds ``away_frames`` frames,
and returns the same way to following.  The annotation is the target's box in the window's
coordinates, clipped to it; frames where no part of the target is inside are ``NaN`` (absent).
"""
from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import cv2
from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import GT_NAME, read_frame, Sequence
import numpy as np

__all__ = ['LookAway', 'look_away_windows', 'write_look_away']


@dataclass(frozen=True)
class LookAway:
    """
    How the virtual camera looks away and back.

    Attributes
    ----------
    crop : float
        The window's size as a fraction of the frame's (per axis).
    follow_frames : int
        Frames the window follows the target before it pans off.
    away_frames : int
        Frames the target stays out of view.
    pan_px : float
        The window's speed while panning, pixels per frame of the source.

    """

    crop: float = 0.5
    follow_frames: int = 15
    away_frames: int = 30
    pan_px: float = 40.0

    def __post_init__(self):
        if (
            not 0.1 <= self.crop < 1.0
            or self.follow_frames < 1
            or self.away_frames < 1
            or not self.pan_px > 0
        ):
            raise ValueError(f'invalid look-away settings {self}')


def look_away_windows(seq: Sequence, frame_size: tuple[int, int], cfg: LookAway = LookAway()):
    """
    Return the virtual camera's window origin (x, y) on every frame and the window's size (w, h).

    Parameters
    ----------
    seq : Sequence
        The source; its GT box gives the target on every frame.
    frame_size : tuple of int
        (W, H) of the source's frames.
    cfg : LookAway
        The motion.

    Returns
    -------
    origins : ndarray
        (N, 2) top-left corners of the window, float pixels.
    size : tuple of int
        (w, h) of the window.

    Raises
    ------
    ValueError
        When the target cannot leave the window inside the frame (too large for it) or the sequence
        is too short for the motion.

    """
    W, H = frame_size
    w, h = int(round(W * cfg.crop)), int(round(H * cfg.crop))
    boxes = np.asarray(seq.gt_boxes, dtype=float)
    if not np.isfinite(boxes).all():
        raise ValueError(f'{seq.name}: the source must have the target in every frame')
    centres = box_centre(boxes)
    follow = np.column_stack(
        [
            np.clip(centres[:, 0] - (w - 1) / 2, 0, W - w),
            np.clip(centres[:, 1] - (h - 1) / 2, 0, H - h),
        ]
    )
    k0 = cfg.follow_frames
    if k0 >= len(seq):
        raise ValueError(
            f'{seq.name}: {len(seq)} frames, fewer than the {k0} followed before looking away'
        )
    start, n_pan, away = follow[k0], 1, None
    # the pan's length sets which frames the window must avoid the target on, and back
    for _ in range(3):
        stop = min(k0 + 2 * n_pan + cfg.away_frames, len(seq))
        away = _away_origin(boxes[k0:stop], start, (w, h), (W, H))
        if away is None:
            raise ValueError(
                f'{seq.name}: the target ({boxes[k0, 2]:.0f}x{boxes[k0, 3]:.0f} px, moving) '
                'cannot stay '
                f'out of a {w}x{h} window inside the {W}x{H} frame for {cfg.away_frames} frames'
            )
        n_pan = max(1, math.ceil(np.linalg.norm(away - start) / cfg.pan_px))
    k_back = k0 + n_pan + cfg.away_frames  # the frame the window starts back
    if k_back + n_pan >= len(seq):
        raise ValueError(
            f'{seq.name}: {len(seq)} frames are too few to follow, pan off ({n_pan} frames), stay '
            'away '
            f'{cfg.away_frames} and come back'
        )
    origins = follow.copy()
    for i in range(n_pan):
        origins[k0 + i] = start + (away - start) * (i + 1) / n_pan
    origins[k0 + n_pan: k_back] = away
    for i in range(n_pan):  # back towards where following would be by then
        end = follow[k_back + n_pan]
        origins[k_back + i] = away + (end - away) * (i + 1) / n_pan
    return origins, (w, h)


def _away_origin(boxes: np.ndarray, start, size, frame) -> np.ndarray | None:
    """
    Return the window origin nearest to ``start``, moved along one axis only.

    That keeps the window clear of every box of ``boxes`` (the target while the camera looks away)
    and inside the frame; None when no axis has the room.
    """
    (w, h), (W, H) = size, frame
    x0, y0 = boxes[:, 0].min(), boxes[:, 1].min()
    x1, y1 = (boxes[:, 0] + boxes[:, 2]).max(), (boxes[:, 1] + boxes[:, 3]).max()
    candidates = [
        np.array([x0 - w - 1, start[1]]),
        np.array([x1 + 1, start[1]]),
        np.array([start[0], y0 - h - 1]),
        np.array([start[0], y1 + 1]),
    ]
    inside = [c for c in candidates if 0 <= c[0] <= W - w and 0 <= c[1] <= H - h]
    return min(inside, key=lambda c: float(np.linalg.norm(c - start))) if inside else None


def write_look_away(
    seq: Sequence, out_dir, cfg: LookAway = LookAway(), name: str | None = None
) -> Path:
    """
    Write the look-away sequence of ``seq`` in OTB layout.

    (``img/00001.jpg`` ..., ``groundtruth_rect.txt`` with ``NaN`` where the target is out of view)
    into ``out_dir / <name>`` (default: the source's name); returns that folder.
    """
    first = read_frame(seq.frame_paths[0])
    origins, (w, h) = look_away_windows(seq, (first.shape[1], first.shape[0]), cfg)
    folder = Path(out_dir) / (name or seq.name)
    (folder / 'img').mkdir(parents=True, exist_ok=True)
    lines = []
    for k, (path, box, (ox, oy)) in enumerate(zip(seq.frame_paths, seq.gt_boxes, origins)):
        frame = first if k == 0 else read_frame(path)
        warp = np.array([[1.0, 0.0, -ox], [0.0, 1.0, -oy]])
        crop = cv2.warpAffine(
            frame, warp, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        cv2.imwrite(str(folder / 'img' / f'{k + 1:05d}.jpg'), crop, [cv2.IMWRITE_JPEG_QUALITY, 95])
        lines.append(_visible_line(box, ox, oy, w, h))
    (folder / GT_NAME).write_text('\n'.join(lines) + '\n')
    return folder


def _visible_line(box, ox: float, oy: float, w: int, h: int) -> str:
    """
    Return the GT line (1-based x,y,w,h) of the part of ``box`` inside the window at (ox, oy).

    NaN when none is.
    """
    x, y, bw, bh = box
    x0, y0 = max(x - ox, 0.0), max(y - oy, 0.0)
    x1, y1 = min(x + bw - ox, float(w)), min(y + bh - oy, float(h))
    if x1 - x0 < 1.0 or y1 - y0 < 1.0:
        return 'NaN,NaN,NaN,NaN'
    return ','.join(f'{v:.2f}' for v in (x0 + 1, y0 + 1, x1 - x0, y1 - y0))
