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
Discriminative scale estimation: fDSST's one-dimensional correlation filter over scales.

The EMD of the iEMD histograms hardly changes with the window's scale: its patch positions are in
normalized window units and its patches are normalized, so a window somewhat too large or too small
scores almost the same EMD (docs/decisions.md#scale-estimator).  This is the scale filter of fDSST
(Danelljan, Hager, Shahbaz Khan, Felsberg, "Discriminative Scale Space Tracking", TPAMI 2017,
sec. 4-5): ``N_SCALES`` samples of the window at sizes ``step^e_k`` (``e_k`` spaced by
``N_INTERP / N_SCALES`` interpolated steps) resampled to one model size of area ``MODEL_AREA`` and
described by fHOG, one column per scale times a Hann window over the scales; a 1-D filter over the
scales (eqs. 5-6; the template a running average at ``LEARNING_RATE``, eq. 21), its response
zero-padded to ``N_INTERP`` scales (sec. 5.3) and the peak refined by a parabola (ECO-HC).  fDSST's
QR compression to ``N_SCALES`` dimensions (eqs. 22-23) leaves the response unchanged; it is
computed exactly from a Gram matrix instead.
"""
from __future__ import annotations

import cv2
from iemd_ros.tracking import features
from iemd_ros.tracking.correlation_filter import sample_region
from iemd_ros.tracking.memory import running_average
import numpy as np

__all__ = ['ScaleFilter']

N_SCALES = 17
N_INTERP = 33
SIGMA_FACTOR = 1.0 / 16
REGULARIZATION = 1e-2
LEARNING_RATE = 0.025
MODEL_AREA = 32.0 * 16.0  # px^2 of the model size the scale samples are resampled to


class ScaleFilter:
    """
    fDSST's scale filter (see the module docstring).

    Parameters
    ----------
    scale_step : float
        Ratio between neighbouring interpolated scales (``1 + TrackerConfig.scale_step``).

    """

    def __init__(self, scale_step: float = 1.02):
        if not scale_step > 1.0:
            raise ValueError(f'scale_step must be > 1, got {scale_step}')
        exps = (np.arange(N_SCALES) - (N_SCALES - 1) // 2) * N_INTERP / N_SCALES
        exps_shifted = np.roll(exps, -((N_SCALES - 1) // 2))
        interp = np.roll(np.arange(N_INTERP) - (N_INTERP - 1) // 2, -((N_INTERP - 1) // 2))
        self.size_factors = scale_step ** exps
        self.interp_factors = scale_step ** interp
        sigma = N_INTERP * SIGMA_FACTOR
        self.label_f = np.fft.fft(np.exp(-0.5 * exps_shifted ** 2 / sigma ** 2))
        # MATLAB's hann(n)
        self.window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(N_SCALES) / (N_SCALES - 1))
        k = np.arange(N_SCALES)
        self._diagonals = (
            np.broadcast_to(k[None, :], (N_SCALES, N_SCALES)),
            (k[None, :] + k[:, None]) % N_SCALES,
        )
        self.template = self.denominator = None
        self._last = None

    def init(self, frame: np.ndarray, center, size, angle: float = 0.0) -> None:
        """
        Fix the model size and learn on the first window.

        The model size is the first window's, scaled to ``MODEL_AREA``.
        """
        w, h = float(size[0]), float(size[1])
        f = np.sqrt(MODEL_AREA / (w * h))
        self.model_wh = (max(int(np.floor(w * f)), 8), max(int(np.floor(h * f)), 8))
        self.template = self.denominator = None
        self.update(frame, center, size, angle)

    def estimate(
        self, frame: np.ndarray, center, size, angle: float = 0.0, bounds=(0.0, np.inf)
    ) -> float:
        """
        Return the relative scale of the target at the window (``center``, ``size``, ``angle``).

        The scale is kept within ``bounds`` (lowest, highest).
        """
        if self.template is None:
            raise RuntimeError('ScaleFilter.estimate() needs init() first')
        z = self._sample(frame, center, size, angle)
        rf = (
            self.label_f
            * self._correlation_f(self.template, z)
            / (self.denominator + REGULARIZATION)
        )
        # fDSST's resizeDFT: the spectrum zero-padded to N_INTERP samples
        pad = np.zeros(N_INTERP, complex)
        npos = (N_SCALES + 1) // 2
        pad[:npos] = rf[:npos]
        pad[N_INTERP - (N_SCALES - npos):] = rf[npos:]
        resp = np.real(np.fft.ifft(pad)) * N_INTERP / N_SCALES
        i = int(np.argmax(resp))
        scale = _parabola_peak(
            self.interp_factors[[(i - 1) % N_INTERP, i, (i + 1) % N_INTERP]],
            resp[[(i - 1) % N_INTERP, i, (i + 1) % N_INTERP]],
        )
        return float(np.clip(scale, bounds[0], bounds[1]))

    def update(
        self, frame: np.ndarray, center, size, angle: float = 0.0, frames: float = 1.0
    ) -> None:
        """
        Learn on the scale samples of the window (``center``, ``size``, ``angle``) of ``frame``.

        See eqs. 5-6, 21; the frame stands for ``frames`` reference frames
        (:func:`~iemd_ros.tracking.memory.running_average`).
        """
        x = self._sample(frame, center, size, angle)
        denominator = np.real(self._correlation_f(x, x))
        if self.template is None:
            self.template, self.denominator = x, denominator
        else:
            self.template = running_average(self.template, x, LEARNING_RATE, frames)
            self.denominator = running_average(
                self.denominator, denominator, LEARNING_RATE, frames
            )

    def _correlation_f(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """
        DFT over the scales of ``c(m) = sum_k sum_d a~_d(k) b~_d(k + m)``.

        ``~`` is times the scale window.  Computed from the Gram matrix ``a~^T b~``: the
        QR-compressed correlation of fDSST, which it equals.
        """
        G = (a.T @ b) * (self.window[:, None] * self.window[None, :])
        return np.fft.fft(G[self._diagonals].sum(axis=1))

    def _sample(self, frame: np.ndarray, center, size, angle: float) -> np.ndarray:
        """
        (D, N_SCALES) fHOG columns of the scale samples.

        One region covering the largest scale is sampled once at the resolution the smallest needs,
        then each scale is a bilinear warp of it to the model size.
        """
        mw, mh = self.model_wh
        tw, th = float(size[0]), float(size[1])
        smin, smax = float(self.size_factors.min()), float(self.size_factors.max())
        sw, sh = int(round(tw * smax)) + 4, int(round(th * smax)) + 4
        ow = max(int(np.ceil(sw * min(1.0, mw / (tw * smin)))), 2)
        oh = max(int(np.ceil(sh * min(1.0, mh / (th * smin)))), 2)
        pos = (
            np.round(np.asarray(center, dtype=np.float64))
            if angle == 0.0
            else np.asarray(center, float)
        )
        region = sample_region(frame, pos, (sw, sh), (ow, oh), angle)
        ax, ay = ow / sw, oh / sh
        # the region's corner (a turned region is centred exactly on pos, in its own axes)
        x0, y0 = (
            (pos[0] - sw // 2, pos[1] - sh // 2)
            if angle == 0.0
            else (pos[0] - sw / 2, pos[1] - sh / 2)
        )
        # each scale's box (pw, ph) at its corner (x0k, y0k), and the warp of the region onto it
        pw = np.maximum(np.floor(tw * self.size_factors), 1.0)
        ph = np.maximum(np.floor(th * self.size_factors), 1.0)
        if angle == 0.0:
            x0k, y0k = pos[0] - pw.astype(int) // 2, pos[1] - ph.astype(int) // 2
        else:
            x0k, y0k = pos[0] - pw / 2, pos[1] - ph / 2
        warps = np.zeros((N_SCALES, 2, 3))
        warps[:, 0, 0], warps[:, 0, 2] = pw / mw * ax, ((x0k - x0) + 0.5 * pw / mw) * ax - 0.5
        warps[:, 1, 1], warps[:, 1, 2] = ph / mh * ay, ((y0k - y0) + 0.5 * ph / mh) * ay - 0.5
        patches = np.empty((N_SCALES, mh, mw) + region.shape[2:], region.dtype)
        for k in range(N_SCALES):
            cv2.warpAffine(
                region,
                warps[k],
                (mw, mh),
                dst=patches[k],
                flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                borderMode=cv2.BORDER_REPLICATE,
            )
        return features.fhog_batch(patches).reshape(N_SCALES, -1).T.astype(np.float64)


def _parabola_peak(xs: np.ndarray, ys: np.ndarray) -> float:
    """
    Return the maximum of the parabola through three (scale, response) points, within their range.

    It is the middle scale when the parabola opens upward or the system is singular.
    """
    A = np.stack([xs**2, xs, np.ones(3)], axis=1)
    try:
        p = np.linalg.solve(A, ys)
    except np.linalg.LinAlgError:
        return float(xs[1])
    if p[0] >= 0:
        return float(xs[1])
    return float(np.clip(-p[1] / (2 * p[0]), xs.min(), xs.max()))
