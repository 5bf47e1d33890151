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
Kernel-weighted histograms of sparse codes.

Those of eqs. (sparse target model) and (sparse candidate model).

Bin r carries the pooled code weight ``p_r`` (or ``q_r``) of patch r and the Epanechnikov profile
``k(x) = max(0, 1 - x)`` of its squared normalized distance to the window centre,
``x = ||(c_r - y) / h||^2``.

Section 4's index u of ``p_ru`` is read as: every patch is a bin, with its own appearance and
position in the ground distance (docs/decisions.md#histogram-bins).  Positions are in normalized
window units (the window is [-1, 1]^2); the paper only says "h is template size", and h = 1 is the
ellipse inscribed in the window, where the corner patches of the 8x8/step-4 layout get no weight
(docs/decisions.md#kernel-bandwidth).  The kernel is not scaled with the window: the scale search
resamples the window instead.
"""
from __future__ import annotations

import numba
import numpy as np


def target_weights(code_weights: np.ndarray, pos: np.ndarray, bandwidth: float) -> np.ndarray:
    """
    Target histogram w_T,u = gamma k(||c_u/h||^2) |p_u|.

    It is normalized to sum 1 (eq. sparse target model).

    The candidate weights of the same patches with the kernel at the window centre (y = 0).

    Parameters
    ----------
    code_weights : ndarray
        (N,) pooled code weights p_u.
    pos : ndarray
        (N, 2) patch centres, normalized window units.
    bandwidth : float
        The kernel's h.

    Returns
    -------
    ndarray
        (N,) weights summing to 1.

    Raises
    ------
    ValueError
        When the histogram is empty (no patch with a non-zero code inside the kernel).

    """
    w, _ = candidate_weights(code_weights, pos, np.zeros(2), bandwidth)
    if not w.any():
        raise ValueError(
            'target histogram is empty (no patch with a non-zero code inside the kernel)'
        )
    return w


def candidate_weights(code_weights, pos, y, bandwidth):
    """
    Candidate histogram w_C,v(y) of eq. (sparse candidate model) and its Jacobian dw_C,v/dy.

    The normalization gamma(y) is differentiated too, so sum_v dw_v/dy = 0 and the gradient does
    not depend on the arbitrary constant of the duals.

    Parameters
    ----------
    code_weights : array_like
        (N,) pooled code weights q_v.
    pos : array_like
        (N, 2) fixed patch centres of the sampled candidate grid, normalized window units.
    y : array_like
        (2,) kernel centre, normalized window units.
    bandwidth : float
        The kernel's h.

    Returns
    -------
    w : ndarray
        (N,) weights summing to 1 (all zeros if no patch is inside the kernel).
    dw_dy : ndarray
        (N, 2) their Jacobian.

    """
    return _candidate_weights(
        np.asarray(code_weights, dtype=np.float64),
        np.asarray(pos, dtype=np.float64),
        np.asarray(y, dtype=np.float64),
        float(bandwidth),
    )


@numba.njit(cache=True, nogil=True)
def _candidate_weights(code_weights, pos, y, bandwidth):
    """One pass of :func:`candidate_weights` (it runs on every EMD evaluation)."""
    n = pos.shape[0]
    w = np.zeros(n)
    dw_dy = np.zeros((n, 2))
    total = 0.0
    h2 = bandwidth * bandwidth
    for i in range(n):
        rx, ry = pos[i, 0] - y[0], pos[i, 1] - y[1]
        k = 1.0 - (rx * rx + ry * ry) / h2  # Epanechnikov profile k(||(c - y) / h||^2)
        if k > 0:
            q = abs(code_weights[i])
            w[i] = k * q
            # d k / d y = 2 (c - y) / h^2 inside the support, 0 outside.
            dw_dy[i, 0] = q * 2.0 * rx / h2
            dw_dy[i, 1] = q * 2.0 * ry / h2
            total += w[i]
    if total <= 0:
        return np.zeros(n), np.zeros((n, 2))
    sx, sy = dw_dy[:, 0].sum(), dw_dy[:, 1].sum()
    for i in range(n):
        w[i] /= total
        dw_dy[i, 0] = dw_dy[i, 0] / total - w[i] * sx / total
        dw_dy[i, 1] = dw_dy[i, 1] / total - w[i] * sy / total
    return w, dw_dy
