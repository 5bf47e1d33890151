"""Kernel-weighted histograms of sparse codes: eqs. (sparse target model) and (sparse candidate model).

Bin r carries the pooled code weight ``p_r`` (or ``q_r``) of patch r and the
Epanechnikov profile ``k(x) = max(0, 1 - x)`` of its squared normalized distance
to the window centre, ``x = ||(c_r - y) / (s h)||^2``.

Bandwidth choice (the paper only says "h is template size"): positions are in
normalized window units (the window is [-1, 1]^2), and ``h`` defaults to sqrt(2),
the radius of the circle through the window corners, so every patch of the
window has positive weight (the corner patches of the 8x8/step-4 layout get
0.44) and the kernel reaches zero at the window's circumscribed circle.  ``s`` is the
candidate's relative scale (the scale search enlarges/shrinks the window).
"""
from __future__ import annotations

import numpy as np


def epanechnikov(pos: np.ndarray, bandwidth: float) -> np.ndarray:
    """k(||c / h||^2) for (N, 2) positions."""
    return np.maximum(0.0, 1.0 - (pos**2).sum(1) / bandwidth**2)


def target_weights(code_weights: np.ndarray, pos: np.ndarray, bandwidth: float) -> np.ndarray:
    """w_T,u = gamma k(||c_u/h||^2) |p_u|, normalized to sum 1 (eq. sparse target model)."""
    w = epanechnikov(pos, bandwidth) * np.abs(code_weights)
    total = w.sum()
    if total <= 0:
        raise ValueError("target histogram is empty (no patch has a non-zero code)")
    return w / total


def candidate_weights(code_weights, pos, y, scale, bandwidth):
    """w_C,v(y) of eq. (sparse candidate model) and its Jacobian dw_C,v/dy.

    ``pos`` are the fixed patch centres of the sampled candidate grid, ``y`` the
    window centre (2,), both in normalized units of the sampling window; ``scale``
    the window size relative to the sampling window.  Returns (w, dw_dy) with
    shapes (N,) and (N, 2); w sums to 1 (all zeros if no patch is inside the kernel).
    The normalization gamma(y) is differentiated too, so sum_v dw_v/dy = 0 and
    the gradient does not depend on the arbitrary constant of the duals.
    """
    rel = (pos - y) / scale
    k = np.maximum(0.0, 1.0 - (rel**2).sum(1) / bandwidth**2)
    q = np.abs(code_weights)
    raw = k * q
    total = raw.sum()
    if total <= 0:
        return np.zeros_like(raw), np.zeros((raw.size, 2))
    # d k / d y = 2 (c - y) / (s^2 h^2) inside the support, 0 outside.
    dk_dy = np.where(k[:, None] > 0, 2.0 * rel / (scale * bandwidth**2), 0.0)
    draw_dy = q[:, None] * dk_dy
    w = raw / total
    dw_dy = draw_dy / total - w[:, None] * draw_dy.sum(0)[None, :] / total
    return w, dw_dy
