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
Colour evidence of the window's position: foreground and background colour histograms (Staple).

The iEMD patches and the correlation filters see grey levels only, and a target often differs from
its surroundings more in colour than in texture.  Staple (Bertinetto et al., "Staple: Complementary
Learners for Real-Time Tracking", CVPR 2016, eqs. 20-22) scores a window by the share of its pixels
whose colour is more frequent on the target than around it: per colour bin b, with rho_O(b) and
rho_B(b) the fractions of the target's and of the surrounding pixels in b, a pixel of bin b scores
beta(b) = rho_O / (rho_O + rho_B) (0 where neither has it; a table kept with the histograms) and a
window the mean of beta over its pixels, for every window position at once from an integral image.

The search region, the window's size plus ``padding`` times sqrt(w h) on every side (and the window
itself once more, so every window centred up to that far is inside it), is resampled in the
window's axes to at most ``model_area`` pixels (nearest neighbour: colours are not blended), so the
cost does not grow with the target and a window turned by the gyro prior is handled like any other.
The histograms count RGB in ``bins`` levels per channel over the window (the target) and over the
window grown by half its mean side less the window (the surroundings, Staple's areas), as running
averages at ``learning_rate``; parts outside the image replicate its border.  The tracker takes the
position of highest mean as one more start and the mean at each window as evidence in its score, on
colour frames only (docs/decisions.md#colour-model); a tracked window then moves by a share of its
mean-shift step on beta, toward the beta-weighted mean of its pixels
(docs/decisions.md#colour-mean-shift).
"""
from __future__ import annotations

from typing import Callable

import cv2
from iemd_ros.tracking.appearance import warp_window, window_axes
from iemd_ros.tracking.memory import rate_over
import numba
import numpy as np


class ColourModel:
    """
    Staple's colour model of the target against its surroundings (see the module docstring).

    ``init`` at the target's window, per frame ``estimate`` around the predicted window (then
    ``score_at`` for candidate centres) and, when the frame is tracked, ``update`` at the tracked
    window.  Frames are HxWx3 uint8 (BGR); windows are (centre, size (w, h), angle) as in
    :meth:`iemd_ros.tracking.appearance.ImagePyramid.sample`.

    Parameters
    ----------
    padding : float, optional
        Margin of the search region on every side, times sqrt(w h) of the window; >= 0.
    learning_rate : float, optional
        Rate of the histograms' running averages, in (0, 1].
    bins : int, optional
        Levels per colour channel, a power of 2 up to 64 (bins**3 histogram entries).
    model_area : int, optional
        Most pixels the search region is resampled to.

    Raises
    ------
    ValueError
        For a negative ``padding``, a ``learning_rate`` outside (0, 1] or ``bins`` not a power of 2
        up to 64.

    """

    def __init__(self, padding: float = 1.0, learning_rate: float = 0.04, bins: int = 32,
                 model_area: int = 16384):
        if padding < 0:
            raise ValueError(f'padding must be >= 0, got {padding}')
        if not 0.0 < learning_rate <= 1.0:
            raise ValueError(f'learning_rate must be in (0, 1], got {learning_rate}')
        if bins not in (2, 4, 8, 16, 32, 64):  # bins**3 histogram entries: 64 -> 262144
            raise ValueError(f'bins must be a power of 2 up to 64, got {bins}')
        self.padding = padding
        self.learning_rate = learning_rate
        self.bins = bins
        self.model_area = model_area
        self._shift = 8 - int(np.log2(bins))
        self._beta = None  # beta per colour bin, (bins**3,): from rho_O and rho_B
        self._target = self._surroundings = None  # rho_O and rho_B, (bins**3,)
        # (mean beta per window position, origin, region centre, model px per image px, angle)
        self._means = None
        self._scores = None  # pixel_scores() of the current beta, made on first use

    @property
    def trained(self) -> bool:
        """Whether :meth:`init` has learnt the histograms."""
        return self._target is not None

    def init(self, frame: np.ndarray, center, size, angle: float = 0.0) -> None:
        """
        Learn the histograms from the window of the first frame, and estimate there.

        So :meth:`score_at` answers from the first frame on, also before a later frame's estimate.

        Parameters
        ----------
        frame : ndarray
            HxWx3 uint8 (BGR) frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.

        """
        target, surroundings = self._histograms(frame, center, size, angle)
        # blended in at rate 1: the first window's fractions themselves, and their beta
        self._target, self._surroundings, self._beta = _blend(
            target, surroundings, target, surroundings, 1.0
        )
        self._scores = None
        self.estimate(frame, center, size, angle)

    def update(
        self, frame: np.ndarray, center, size, angle: float = 0.0, frames: float = 1.0
    ) -> None:
        """
        Blend in the histograms at the tracked window.

        Parameters
        ----------
        frame : ndarray
            HxWx3 uint8 (BGR) frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.
        frames : float, optional
            The reference frames the frame stands for: the blend is at
            :func:`~iemd_ros.tracking.memory.rate_over` of ``learning_rate``.

        """
        target, surroundings = self._histograms(frame, center, size, angle)
        self._target, self._surroundings, self._beta = _blend(
            self._target,
            self._surroundings,
            target,
            surroundings,
            rate_over(self.learning_rate, frames),
        )
        self._scores = None

    def estimate(self, frame: np.ndarray, center, size, angle: float = 0.0) -> np.ndarray:
        """
        Return the displacement to the window of highest mean beta in the search region.

        The region is the one around the predicted window; the map of mean beta is kept for
        :meth:`score_at`.

        Parameters
        ----------
        frame : ndarray
            HxWx3 uint8 (BGR) frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.

        Returns
        -------
        ndarray
            (dx, dy), image pixels, from ``center`` to the window of ``size`` of highest mean beta.

        Raises
        ------
        RuntimeError
            Before :meth:`init`.

        """
        self._require_trained('estimate')
        size = np.asarray(size, dtype=np.float64)
        region = 2.0 * size + 2.0 * self.padding * np.sqrt(size[0] * size[1])
        bins, scale = self._bin_indices(frame, center, region, angle)
        beta = self._beta[bins]
        integral = cv2.integral(beta, sdepth=cv2.CV_64F)
        ww, wh = (max(1, int(round(v))) for v in size * scale)
        sums = (
            integral[wh:, ww:] - integral[:-wh, ww:] - integral[wh:, :-ww] + integral[:-wh, :-ww]
        )
        means = sums / (ww * wh)
        # Window position (row r, column c) is centred at model pixel (c + (ww-1)/2, r + (wh-1)/2);
        # its offset from the region's centre ((W-1)/2, (H-1)/2) is origin + (c, r).
        origin = np.array([(ww - beta.shape[1]) / 2.0, (wh - beta.shape[0]) / 2.0])
        self._means = (means, origin, np.asarray(center, dtype=np.float64), scale, angle)
        r, c = np.unravel_index(int(np.argmax(means)), means.shape)
        return window_axes(angle) @ ((origin + [c, r]) / scale)

    def score_at(self, point) -> float:
        """
        Return the last estimate's mean beta of the window centred at an image point.

        Parameters
        ----------
        point : array_like
            (x, y) image point.

        Returns
        -------
        float
            The mean beta, bilinear between window positions; 0 outside the search region.

        Raises
        ------
        RuntimeError
            Before an :meth:`estimate`.

        """
        if self._means is None:
            raise RuntimeError('ColourModel.score_at() needs an estimate() first')
        means, origin, center, scale, angle = self._means
        c, r = (
            window_axes(angle).T @ (np.asarray(point, dtype=np.float64) - center) * scale - origin
        )
        rows, cols = means.shape
        if not (0.0 <= c <= cols - 1 and 0.0 <= r <= rows - 1):
            return 0.0
        c0, r0 = int(c), int(r)
        c1, r1 = min(c0 + 1, cols - 1), min(r0 + 1, rows - 1)
        fc, fr = c - c0, r - r0
        top = (1.0 - fc) * means[r0, c0] + fc * means[r0, c1]
        bottom = (1.0 - fc) * means[r1, c0] + fc * means[r1, c1]
        return float((1.0 - fr) * top + fr * bottom)

    def mean_shift(self, frame: np.ndarray, center, size, angle: float = 0.0) -> np.ndarray:
        """
        Return the mean-shift step of the window on the target's colours.

        The beta-weighted mean of the window's pixel positions less its centre: one step of the
        mean-shift tracker (Comaniciu, Ramesh, Meer, "Kernel-Based Object Tracking", TPAMI 2003:
        the new location is the weighted mean of the pixels under the kernel, here flat over the
        window) with Staple's per-pixel score beta as the weights.

        Parameters
        ----------
        frame, center, size, angle
            The frame and the window, as for :meth:`estimate`.

        Returns
        -------
        ndarray
            (dx, dy), image pixels; (0, 0) where no pixel of the window has a target colour.

        Raises
        ------
        RuntimeError
            Before :meth:`init`.

        """
        self._require_trained('mean_shift')
        bins, scale = self._bin_indices(frame, center, np.asarray(size, dtype=np.float64), angle)
        beta = self._beta[bins]
        total = float(beta.sum())
        if total <= 0.0:
            return np.zeros(2)
        rows, cols = beta.shape
        mean = np.array([
            beta.sum(axis=0) @ (np.arange(cols) - (cols - 1) / 2.0),
            beta.sum(axis=1) @ (np.arange(rows) - (rows - 1) / 2.0),
        ]) / total
        return window_axes(angle) @ (mean / scale)

    def pixel_scores(self) -> Callable[[np.ndarray], np.ndarray]:
        """
        Return Staple's per-pixel score beta as the histograms are now, as a function of a patch.

        The function maps an (H, W, 3) uint8 BGR patch to its (H, W) float32 beta, each pixel's
        from its colour bin; a grey patch, (H, W) or (H, W, 1) (a grey frame in a colour stream),
        reads as the colours of three equal levels.  It keeps the table it was made
        with, so a later :meth:`update` does not change it: a model learning on another thread
        cannot change a sample half-way.  Until then every call returns the same function.

        Returns
        -------
        callable
            ``scores(patch) -> beta``.

        Raises
        ------
        RuntimeError
            Before :meth:`init`.

        """
        self._require_trained('pixel_scores')
        if self._scores is None:
            table, shift, bins = self._beta.astype(np.float32), self._shift, self.bins

            def scores(patch: np.ndarray) -> np.ndarray:
                patch = patch[:, :, None] if patch.ndim == 2 else patch
                return table[_bin_index(np.ascontiguousarray(patch), shift, bins)]

            self._scores = scores
        return self._scores

    def _require_trained(self, method: str) -> None:
        """Raise RuntimeError naming ``method`` when :meth:`init` has not learnt the histograms."""
        if not self.trained:
            raise RuntimeError(f'ColourModel.{method}() called before init()')

    def _histograms(self, frame, center, size, angle):
        """
        rho_O and rho_B: the colour-bin fractions of the window and of its surroundings.

        The surroundings are the window grown by half its mean side, less the window.
        """
        size = np.asarray(size, dtype=np.float64)
        bins, scale = self._bin_indices(frame, center, size + 0.5 * (size[0] + size[1]), angle)
        half = size * scale / 2.0
        return _fractions(bins, float(half[0]), float(half[1]), self.bins**3)

    def _bin_indices(self, frame, center, region, angle) -> tuple[np.ndarray, float]:
        """
        Return the colour-bin indices of the region (w, h) around ``center``, and the scale.

        The region is taken in the axes of a window turned by ``angle`` and resampled (nearest
        neighbour) to at most ``model_area`` pixels; the scale is model px per image px.
        """
        scale = min(1.0, np.sqrt(self.model_area / (region[0] * region[1])))
        out_size = [max(1, int(round(v * scale))) for v in region]
        sample = warp_window(
            frame, center, window_axes(angle) / scale, out_size, cv2.INTER_NEAREST
        )
        return _bin_index(sample, self._shift, self.bins), scale


@numba.njit(cache=True, nogil=True)
def _bin_index(sample, shift, bins):
    """
    Histogram bin of every pixel of an (h, w, 3) uint8 sample: its levels >> ``shift``.

    An (h, w, 1) sample's level counts for all three channels, as in the features' Colour Names.
    """
    h, w, c = sample.shape
    out = np.empty((h, w), np.intp)
    for y in range(h):
        for x in range(w):
            b0 = np.intp(sample[y, x, 0]) >> shift
            b1 = np.intp(sample[y, x, 1 if c == 3 else 0]) >> shift
            b2 = np.intp(sample[y, x, 2 if c == 3 else 0]) >> shift
            out[y, x] = (b0 * bins + b1) * bins + b2
    return out


@numba.njit(cache=True, nogil=True)
def _fractions(bins, half_w, half_h, n):
    """
    (rho_O, rho_B): the fractions of the pixels in each of ``n`` bins, in and around the window.

    ``bins`` is the (h, w) bin map of the region centred on the window; a pixel is in the window
    when it is at most ``half_w`` and ``half_h`` px from the region's centre.
    """
    h, w = bins.shape
    target, surroundings = np.zeros(n), np.zeros(n)
    inside = 0
    for y in range(h):
        in_rows = abs(y - (h - 1) / 2.0) <= half_h
        for x in range(w):
            if in_rows and abs(x - (w - 1) / 2.0) <= half_w:
                target[bins[y, x]] += 1.0
                inside += 1
            else:
                surroundings[bins[y, x]] += 1.0
    target /= max(float(inside), 1.0)
    surroundings /= max(float(h * w - inside), 1.0)
    return target, surroundings


@numba.njit(cache=True, nogil=True)
def _blend(target, surroundings, new_target, new_surroundings, eta):
    """
    (rho_O, rho_B, beta) after blending the new fractions in at rate ``eta``.

    Staple's running averages and its per-bin score beta = rho_O / (rho_O + rho_B) (0 where
    neither histogram has the bin), in one pass over the bins.
    """
    n = target.size
    t_out, s_out, beta = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        t = (1.0 - eta) * target[i] + eta * new_target[i]
        s = (1.0 - eta) * surroundings[i] + eta * new_surroundings[i]
        t_out[i], s_out[i] = t, s
        beta[i] = t / (t + s) if t + s > 0 else 0.0
    return t_out, s_out, beta
