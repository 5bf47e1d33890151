"""A tracking result drawn on its frame (ROS-free): the node's ``~/debug_image`` and the replay's video."""
from __future__ import annotations

import cv2
import numpy as np

from iemd_ros.pipeline.results import FrameResult

__all__ = ["draw_result", "draw_results", "box_colour"]

# BGR
TRACKING, LOST, INIT, GYRO = (0, 200, 0), (0, 0, 255), (255, 200, 0), (0, 220, 255)


def draw_result(frame: np.ndarray, r: FrameResult) -> np.ndarray:
    """A tracking result drawn on a BGR copy of its frame (:func:`draw_results` of one result).

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
    """The BGR colour of a result's box: light blue on the init frame, green tracking, red lost or rejected.

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
    """The results of one frame (one per target) drawn on a BGR copy of it.

    Each box (:func:`box_colour`), the gyro's predicted box (thin, yellow) and a line per result with the stamp and
    state (and the target's id when there are several).

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
        label = f"[{r.target_id}] " if len(results) > 1 else ""
        text = f"{label}{r.stamp_ns / 1e9:.3f}s {_status(r)}"
        for colour, thickness in (((0, 0, 0), 3), ((255, 255, 255), 1)):
            cv2.putText(img, text, (5, 18 + 18 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, thickness, cv2.LINE_AA)
    return img


def _status(r: FrameResult) -> str:
    if r.is_init:
        return "initialized"
    if r.rejection is not None or r.box is None:
        return r.reason or r.state.value
    return (f"{r.state.value}{' (held)' if r.held else ''} EMD {r.emd:.4f} it {r.iterations} {'gyro' if r.gyro_used else 'no gyro'} "
            f"{r.processing_ms:.0f} ms")


def _rect(img: np.ndarray, box, colour, thickness: int) -> None:
    """Box ``(x, y, w, h)`` covering pixels ``x .. x+w-1`` (0-based)."""
    x, y, w, h = box
    cv2.rectangle(img, (int(round(x)), int(round(y))), (int(round(x + w - 1)), int(round(y + h - 1))),
                  colour, thickness)
