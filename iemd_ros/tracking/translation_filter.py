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
Discriminative evidence of the window's position.

A spatial-temporal regularized correlation filter (STRCF).

The iEMD histograms are a generative model with no notion of background: where the target turns or
is partly hidden, a window on background or on a similar object can score an EMD as low as the
target's.  A correlation filter trained on the target against its own surroundings is the
complementary view (docs/decisions.md#strcf).

* Features (:mod:`iemd_ros.tracking.features`): grey + fHOG + Colour Names on 4x4 cells (42
  channels; 32 on grey frames), the feature set of STRCF and AutoTrack; the Colour Names weighted
  by ``CN_WEIGHT`` against fHOG and grey (docs/decisions.md#colour-names-weight).  With a colour
  model (:class:`~iemd_ros.tracking.colour_model.ColourModel`), one more channel: its per-pixel
  score beta (Staple) averaged over each cell, less 1/2 as grey is, weighted as grey
  (docs/decisions.md#colour-score-channel).
* Sample: a square region of side ``SEARCH_AREA_SCALE`` x ``sqrt(w h)`` of the target, turned with
  the window, resampled so that its area lies in ``[150^2, 160^2]`` px (at most 40 x 40 cells); a
  cosine window; a Gaussian label of std ``sqrt(w h) / cell / 16`` cells.
* Filter: STRCF (Li, Tian, Zuo, Zhang, Yang, "Learning Spatial-Temporal Regularized Correlation
  Filters for Visual Tracking", CVPR 2018).  Each learning frame minimizes (STRCF eq. 3)
  ``E(f) = 1/(2T) ||sum_d x_d (*) f_d - y||^2 + 1/2 sum_d ||w . f_d||^2
  + mu/2 sum_d ||f_d - f_{t-1,d}||^2`` with the binary window ``w`` of BACF (Kiani Galoogahi et
  al., ICCV 2017): ``1e-3`` on the target's cells, ``1e5`` elsewhere, so that every circular shift
  of the padded sample is a real background negative.  ADMM on ``f = g`` (STRCF eqs. 5-10), 2
  iterations: the f-step per frequency by Sherman-Morrison (eq. 8), the g-step element-wise in
  space (eq. 9), the multiplier update (eq. 10).  The training sample is the detection sample
  circularly shifted to the new centre in the Fourier domain (AutoTrack's ``shift_sample``).
* Detection: the response ``r = F^-1(sum_d conj(f_d^) z_d^)`` on the cell grid, its peak refined by
  Newton's method on the Fourier interpolant (SRDCF); :meth:`TranslationFilter.response_at` reads
  it at any window centre.
"""
from __future__ import annotations

from typing import NamedTuple

import cv2
from iemd_ros.tracking import features
from iemd_ros.tracking.appearance import window_axes
from iemd_ros.tracking.colour_model import ColourModel
from iemd_ros.tracking.correlation_filter import (
    apce,
    correlate,
    energy,
    gaussian_label,
    hann_inner,
    sample_region,
    SubCellPeak,
)
from iemd_ros.tracking.memory import penalty_over
import numba
import numpy as np
import scipy.fft as sfft

__all__ = ['Region', 'Strip', 'TranslationFilter', 'SEARCH_AREA_SCALE']

SEARCH_AREA_SCALE = 5.0                       # side of the search region / sqrt(w h) (STRCF, BACF)
CN_WEIGHT = 2.0                               # Colour Names channels' weight; fHOG's, grey's 1
SAMPLE_AREA = (150.0 ** 2, 160.0 ** 2)        # resampled px^2 (docs/decisions.md#sample-area)
OUTPUT_SIGMA_FACTOR = 1.0 / 16                # label std / sqrt(w h) in cells (STRCF)
REG_TARGET, REG_BACKGROUND = 1e-3, 1e5        # BACF's binary spatial regularization
MU = 15.0                                     # STRCF's temporal regularization
ADMM_ITERATIONS = 2
GAMMA_INIT, GAMMA_STEP, GAMMA_MAX = 1.0, 10.0, 0.1  # ADMM penalty schedule (STRCF)
FRAME_SEARCH_CELLS = 2048  # feature cells searched per search_frame call (its cost per lost frame)


class Region(NamedTuple):
    """The search region's spectrum and where it was taken (:meth:`TranslationFilter.sample`)."""

    frame_id: int        # id() of the frame sampled
    center: np.ndarray   # the predicted window's centre, image px
    pos: np.ndarray      # the region's centre, image px
    scale: float         # image px per sample px
    angle: float         # the region's turn, radians
    zf: np.ndarray       # (C, n, n // 2 + 1) spectrum of the windowed features
    patch: np.ndarray | None  # the resampled region, kept for the colour channel (else None)


class Strip(NamedTuple):
    """A vertical strip of a frame at a window's scale (:meth:`TranslationFilter.frame_strip`)."""

    patch: np.ndarray    # the strip with its margins, resampled to the filter's scale
    features: np.ndarray  # (C, rows, cols) its feature channels, without the colour channel
    lo: int              # the frame's cell column of the patch's first column
    first: int           # the frame's cell column of the strip's (and its response's) first column
    width: int           # the strip's own columns (the last strip may have fewer in the frame)
    cells: tuple         # the frame's (rows, cols) cells at this scale
    cell_px: np.ndarray  # (x, y) size of a cell in frame pixels
    parts: int           # how many strips the frame has at this scale


class TranslationFilter:
    """
    STRCF over the search region around the window (see the module docstring).

    The filter keeps no position of its own: :meth:`estimate` and :meth:`update` take the window
    from the caller, which fuses the response with its other cues first.
    """

    def __init__(self):
        self.f = None
        self._detection = self._response = None
        # (f, shape, the conjugate spectrum of its crop to the target's cells at that shape) for
        # frame_response
        self._frame_filter = None
        self.response_peak = None  # the last estimate's peak value
        self.colour_model = self._scores = None

    def init(
        self,
        frame: np.ndarray,
        center,
        size,
        colour: bool,
        angle: float = 0.0,
        colour_model: ColourModel | None = None,
    ) -> None:
        """
        Set up the sample geometry from the first window and learn the first filter (``mu = 0``).

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 frame.
        center, size : array_like
            The window's centre (cx, cy) and size (w, h), px.
        colour : bool
            Whether the sequence has colour (Colour Names are used on colour frames only).
        angle : float
            The window's turn (radians).
        colour_model : ColourModel, optional
            A trained colour model whose per-pixel score is one more feature channel; the caller
            keeps it learning.  Without it the features are grey, fHOG and Colour Names only.

        """
        w, h = max(float(size[0]), 1.0), max(float(size[1]), 1.0)
        self.colour = bool(colour)
        self.colour_model = colour_model
        # the colour model's per-pixel score as it was at the last estimate (or at init): one
        # frame's samples read the same beta while the model learns on another thread
        self._scores = None if colour_model is None else colour_model.pixel_scores()
        area = w * h * SEARCH_AREA_SCALE ** 2
        s0 = np.sqrt(area / np.clip(area, *SAMPLE_AREA))
        # the target's size in the resampled sample, px
        self.base_wh = np.array([w, h]) / s0
        n = max(int(round(np.sqrt(np.prod(self.base_wh)) * SEARCH_AREA_SCALE / features.CELL)), 8)
        self.map_hw = (n, n)
        self.support = float(n * features.CELL)            # the resampled sample's side, px
        self.T = n * n
        # each feature channel's weight, and the cosine window times it
        self.channel_weight = np.ones(self.n_channels, np.float32)
        self.channel_weight[features.CN_START:features.n_channels(self.colour)] = CN_WEIGHT
        self.window = (
            self.channel_weight[:, None, None] * (hann_inner(n)[:, None] * hann_inner(n)[None, :])
        ).astype(np.float32)
        cells = np.floor(self.base_wh / features.CELL)
        sigma = max(float(np.sqrt(np.prod(cells))) * OUTPUT_SIGMA_FACTOR, 1e-3)
        self.yf_conj = np.conj(sfft.rfft2(gaussian_label(n, n, sigma))).astype(np.complex64)
        reg = np.full((n, n), REG_BACKGROUND)
        rw, rh = max(int(cells[0]), 1), max(int(cells[1]), 1)
        # the target's cells, where the filter may be nonzero (BACF's crop)
        self.target_cells = tuple(
            slice(max(n // 2 - k // 2, 0), min(n // 2 - k // 2 + k, n)) for k in (rh, rw)
        )
        reg[self.target_cells] = REG_TARGET
        self.reg_sq = (reg ** 2).astype(np.float32)
        self.peak = SubCellPeak(n, n)
        self.ky = (np.fft.fftfreq(n) * n).astype(np.float32)
        self.kx = np.arange(n // 2 + 1, dtype=np.float32)
        self.f = None
        self._detection = self._response = None
        self.update(frame, center, size, angle)

    # ------------------------------------------------------------------ detection
    def sample(self, frame: np.ndarray, center, size, angle: float = 0.0) -> Region:
        """
        Return the spectrum of the search region around a predicted window, for :meth:`estimate`.

        It reads only the geometry fixed by :meth:`init`, not the filter, so it may run while
        :meth:`update` learns.

        Parameters
        ----------
        frame : ndarray
            The frame.
        center, size : array_like
            The predicted window's centre and size (the search region follows the size).
        angle : float
            The window's turn (radians).

        Returns
        -------
        Region
            The region's features' spectrum and where it was taken.

        """
        scale = self._scale(size)
        pos = self._position(center, angle)
        patch = self._patch(frame, pos, scale, angle)
        return Region(
            id(frame),
            np.asarray(center, dtype=np.float64),
            pos,
            scale,
            angle,
            self._windowed_spectrum(features.extract(patch, self.colour)),
            None if self.colour_model is None else patch,
        )

    def estimate(self, region: Region) -> np.ndarray:
        """
        Displacement (dx, dy) px from the region's window centre to where the response peaks.

        The response is kept for :meth:`response_at`, its peak value in :attr:`response_peak`.
        With a colour model, the region's colour channel is added here, from the model as it is
        now: call it when the model is not learning.

        Parameters
        ----------
        region : Region
            :meth:`sample` of the frame around the predicted window.

        Returns
        -------
        ndarray
            (2,) displacement, image px.

        """
        scores, region, self._response, move, value = self._detect(region)
        if scores is not None:
            self._scores = scores
        self._detection = region
        self.response_peak = value
        return move

    def locate(self, region: Region) -> tuple[np.ndarray, float]:
        """
        Return where the response over ``region`` peaks, as :meth:`estimate`, keeping nothing.

        It reads the filter and the colour model, so it may run beside :meth:`estimate` while
        neither learns.

        Parameters
        ----------
        region : Region
            :meth:`sample` of the frame around a window.

        Returns
        -------
        move : ndarray
            (2,) displacement from the region's window centre to the peak, image px.
        value : float
            The response at the peak.

        """
        return self._detect(region)[3:]

    def _detect(self, region: Region):
        """
        (colour scores, region with its colour channel, response, displacement, peak value).

        The colour scores are the colour model's as it is now (None without one); the response is
        kept with its geometry, as :meth:`response_at` reads it: (response, region position, cell
        size px, axes).
        """
        scores = None
        if self.colour_model is not None:
            scores = self.colour_model.pixel_scores()
            colour = self._colour_channel(region.patch, scores)[None]
            region = region._replace(
                zf=np.concatenate([region.zf, self._windowed_spectrum(colour, len(region.zf))]),
                patch=None,
            )
        rf = np.empty(region.zf.shape[1:], np.complex64)
        correlate(self.f, region.zf, rf)
        resp = sfft.irfft2(rf, s=self.map_hw)
        dy, dx, value = self.peak(resp, rf)
        cell_px, axes = features.CELL * region.scale, window_axes(region.angle)
        move = axes @ (np.array([dx, dy]) * cell_px) + region.pos - region.center
        return scores, region, (resp, region.pos, cell_px, axes), move, value

    def response_at(self, point) -> float:
        """
        Return the last :meth:`estimate`'s response at the window centre ``point`` (image px).

        It is interpolated bilinearly between cells (the response is circular over the search
        region).
        """
        if self._response is None:
            raise RuntimeError('TranslationFilter.response_at() needs an estimate() first')
        resp, pos, cell_px, axes = self._response
        d = axes.T @ (np.asarray(point, dtype=np.float64) - pos) / cell_px
        return _bilinear_circular(resp, float(d[1]), float(d[0]))

    def search_frame(self, strip: Strip) -> tuple[np.ndarray, float]:
        """
        Where in one strip of a frame the filter responds most.

        The response is :meth:`frame_response`'s, of the ``strip`` it takes.  A caller scans the
        whole frame by asking for parts 0, 1, ... of :meth:`frame_strip` over several frames.

        Returns
        -------
        centre : ndarray
            (cx, cy) of the strongest response in the strip, image px (pixel centres at integers).
        response : float
            The response there (no cosine window, so not comparable with :attr:`response_peak`:
            check a candidate with :meth:`estimate` or :meth:`locate`).

        """
        resp = self.frame_response(strip)
        k = np.unravel_index(int(np.argmax(resp)), resp.shape)
        centre = (np.array([k[1] + strip.first, k[0]], dtype=np.float64) + 0.5) * strip.cell_px
        return centre - 0.5, float(resp[k])

    def frame_strip(self, frame: np.ndarray, size, part: int = 0) -> Strip:
        """
        Return one vertical strip of ``frame`` at the scale of ``size`` (:meth:`frame_response`).

        The frame is resampled to the filter's scale and cut into vertical strips of at most
        ``FRAME_SEARCH_CELLS`` feature cells; the strip is read with the margins the filter's crop
        to the target's cells needs.  It reads only the geometry fixed by :meth:`init`, not the
        filter, so it may run while the filter estimates elsewhere.

        Parameters
        ----------
        frame : ndarray
            The frame.
        size : array_like
            The window's size (w, h), px: the scale the frame is resampled to.
        part : int
            Which strip (taken modulo the number of strips).

        Returns
        -------
        Strip
            The strip's features and where it lies in the frame.

        """
        rows, cols = frame.shape[:2]
        cell = self.cell_size(size)
        cells = (max(int(rows / cell), 1), max(int(cols / cell), 1))
        parts = max(int(np.ceil(cells[0] * cells[1] / FRAME_SEARCH_CELLS)), 1)
        width = int(np.ceil(cells[1] / parts))
        parts = int(np.ceil(cells[1] / width))  # no empty last strip
        crop, origin = self._frame_crop()
        first = (part % parts) * width
        lo, hi = max(first - origin[1], 0), min(first + width + crop[1] - 1 - origin[1], cells[1])
        cell_px = np.array([cols / cells[1], rows / cells[0]])
        patch = sample_region(
            frame,
            ((lo + hi) / 2 * cell_px[0] - 0.5, rows / 2 - 0.5),
            ((hi - lo) * cell_px[0], rows),
            ((hi - lo) * features.CELL, cells[0] * features.CELL),
        )
        return Strip(
            patch, features.extract(patch, self.colour), lo, first, width, cells, cell_px, parts
        )

    def frame_response(self, strip: Strip) -> np.ndarray:
        """
        Return the filter's response over one strip of a frame.

        The strip's features, with the colour channel from the colour model as it is now, are
        correlated with the spatial filter cropped to the target's cells (:attr:`target_cells`:
        the regularization leaves it all but zero outside them, BACF's crop), zero-padded so that
        the response is linear, not circular, over the strip's own cells: by the crop's size down
        the frame and beyond the strip's own width (overlap-save: the margins wrap only into cells
        not returned).

        Parameters
        ----------
        strip : Strip
            :meth:`frame_strip` of the frame.

        Returns
        -------
        ndarray
            (rows, cols) response at the strip's cells inside the frame; a cell answers for a
            target centred on it: cell (i, j) is centred at ``((j + strip.first, i) + 0.5) *
            strip.cell_px - 0.5`` in the frame.

        """
        scores = None if self.colour_model is None else self.colour_model.pixel_scores()
        z = self._with_colour(strip.features, strip.patch, scores)
        z = z * self.channel_weight[:, None, None]
        crop, origin = self._frame_crop()
        cells, first, lo = strip.cells, strip.first, strip.lo
        # sizes the FFT factors well
        shape = tuple(
            sfft.next_fast_len(k + c - 1, real=True) for k, c in zip((cells[0], strip.width), crop)
        )
        if (
            self._frame_filter is None
            or self._frame_filter[0] is not self.f
            or self._frame_filter[1] != shape
        ):
            h = sfft.irfft2(self.f, s=self.map_hw, axes=(1, 2))[(slice(None),) + self.target_cells]
            self._frame_filter = (self.f, shape, np.conj(sfft.rfft2(h, s=shape, axes=(1, 2))))
        resp_f = np.sum(self._frame_filter[2] * sfft.rfft2(z, s=shape, axes=(1, 2)), axis=0)
        resp = np.roll(sfft.irfft2(resp_f, s=shape), origin, axis=(0, 1))[
            :cells[0], first - lo:min(first + strip.width, cells[1]) - lo
        ]
        return resp

    def _frame_crop(self) -> tuple[tuple[int, int], tuple[int, int]]:
        """
        (rows, cols) of the filter's crop to the target's cells, and where the target's centre is.

        A target at cell k of a strip answers at displacement k - origin.
        """
        ty, tx = self.target_cells
        crop = (ty.stop - ty.start, tx.stop - tx.start)
        return crop, (self.map_hw[0] // 2 - ty.start, self.map_hw[1] // 2 - tx.start)

    @property
    def confidence(self) -> dict:
        """
        Return the last estimate's peak value and APCE (LMCF's average peak-to-correlation energy).

        Computed when asked; {} before any estimate.
        """
        if self._response is None:
            return {}
        return {'peak': self.response_peak, 'apce': apce(self._response[0])}

    # ------------------------------------------------------------------ learning
    def update(
        self, frame: np.ndarray, center, size, angle: float = 0.0, frames: float = 1.0
    ) -> None:
        """
        Learn on the window (``center``, ``size``, ``angle``) of ``frame``.

        The detection sample shifted there when ``frame`` is the one just estimated on at this
        scale and turn, else a new sample (STRCF, eqs. 3-10); the temporal term's weight is
        :func:`~iemd_ros.tracking.memory.penalty_over` ``frames`` reference frames.
        """
        scale = self._scale(size)
        det, self._detection = self._detection, None
        if (
            det is not None
            and det.frame_id == id(frame)
            and abs(det.scale / scale - 1.0) < 0.05
            and det.angle == angle
        ):
            shift = (
                window_axes(angle).T
                @ (np.asarray(center, dtype=np.float64) - det.pos)
                / (features.CELL * det.scale)
            )
            phase_y = np.exp(2j * np.pi * self.ky * shift[1] / self.map_hw[0]).astype(np.complex64)
            phase_x = np.exp(2j * np.pi * self.kx * shift[0] / self.map_hw[1]).astype(np.complex64)
            xf = det.zf * (phase_y[:, None] * phase_x[None, :])[None]
        else:
            xf = self._spectrum(frame, self._position(center, angle), scale, angle)
        self.f = self._admm(xf, self.f, mu=penalty_over(MU, frames))

    def _admm(
        self,
        xf: np.ndarray,
        f_prev,
        iterations: int = ADMM_ITERATIONS,
        gamma: tuple = (GAMMA_INIT, GAMMA_STEP, GAMMA_MAX),
        mu: float = MU,
    ):
        """
        Run STRCF's ADMM (eqs. 5-10) on one sample spectrum ``xf``, from ``g = h = 0``.

        ``xf`` is (C, rows, cols//2+1).  Per iteration with penalty ``gamma``
        (``gamma <- min(step gamma, max)``): the f-step (eq. 8)
        ``f^ = q + x^ (conj(y^) - x^H q) / (T (gamma + mu) + x^H x^)``,
        ``q = (gamma g^ - h^ + mu f^_{t-1}) / (gamma + mu)``; the g-step (eq. 9)
        ``g = (gamma f + h) / (w^2 + gamma)``; the multiplier (eq. 10) ``h^ += gamma (f^ - g^)``.
        The last iteration stops after its f-step, so 2 iterations cost one inverse and one forward
        FFT.  ``mu`` is 0 on the first frame (no previous filter ``f_prev``).
        """
        mu = 0.0 if f_prev is None else mu
        g_now, g_step, g_max = gamma
        shape, cdt = xf.shape, xf.dtype
        rdt = np.float32 if cdt == np.complex64 else np.float64
        S = np.empty(shape[1:], rdt)
        energy(xf, S)
        yfc = self.yf_conj.astype(cdt, copy=False)
        g = h = None
        f = np.empty(shape, cdt)
        xq = np.empty(shape[1:], cdt)
        for it in range(iterations):
            kap = g_now + mu
            dinv = (1.0 / (self.T * kap + S)).astype(rdt)
            # g and h are 0 before the first g-step: their terms drop out of q
            _f_step(
                xf,
                yfc,
                dinv,
                f if g is None else g,
                f if h is None else h,
                f if f_prev is None else f_prev,
                rdt(0.0 if g is None else g_now / kap),
                rdt(0.0 if h is None else 1.0 / kap),
                rdt(mu / kap),
                g is not None,
                mu > 0,
                f,
                xq,
            )
            if it == iterations - 1:
                break
            a = g_now * f if h is None else g_now * f + h
            gs = sfft.irfft2(a, s=self.map_hw) * (1.0 / (self.reg_sq + g_now)).astype(rdt)[None]
            g = sfft.rfft2(gs).astype(cdt, copy=False)
            step = g_now * (f - g)
            h = step if h is None else h + step
            g_now = min(g_step * g_now, g_max)
        return f

    # ------------------------------------------------------------------ sampling
    def cell_size(self, size) -> float:
        """Return the image px of a feature cell for a window of ``size`` (w, h)."""
        return features.CELL * self._scale(size)

    def _scale(self, size) -> float:
        """
        Image px per sample px for a window of ``size``.

        ``sqrt(w h)`` over the first window's, after resampling (the region keeps its square
        shape).
        """
        return float(np.sqrt(float(size[0]) * float(size[1]) / float(np.prod(self.base_wh))))

    @staticmethod
    def _position(center, angle: float) -> np.ndarray:
        """
        Where the region is centred.

        The window centre, rounded to a pixel when the region is not turned (STRCF's integer sample
        position, then the crop is exact).
        """
        c = np.asarray(center, dtype=np.float64)
        return np.round(c) if angle == 0.0 else c

    @property
    def n_channels(self) -> int:
        """Return how many feature channels: :func:`features.n_channels`, and the colour's."""
        return features.n_channels(self.colour) + (self.colour_model is not None)

    def _patch(self, frame: np.ndarray, pos, scale: float, angle: float) -> np.ndarray:
        """Return the search region at ``pos``, resampled to the filter's sample."""
        side = self.support * scale
        return sample_region(frame, pos, (side, side), (self.support, self.support), angle)

    def _colour_channel(self, patch: np.ndarray, scores) -> np.ndarray:
        """
        Return the colour model's score of ``patch``'s pixels averaged over each cell, less 1/2.

        ``scores`` is :meth:`ColourModel.pixel_scores`; pixels beyond the last full cell are
        ignored, as :func:`features.extract` ignores them.
        """
        rows, cols = patch.shape[0] // features.CELL, patch.shape[1] // features.CELL
        beta = scores(patch)[:rows * features.CELL, :cols * features.CELL]
        # an integer shrink by area is the mean over each cell
        return cv2.resize(beta, (cols, rows), interpolation=cv2.INTER_AREA) - np.float32(0.5)

    def _features(self, patch: np.ndarray) -> np.ndarray:
        """
        Return every feature channel of ``patch`` (:func:`features.extract`, the colour's).

        The colour channel reads the colour scores of the last estimate (``_scores``).
        """
        return self._with_colour(features.extract(patch, self.colour), patch, self._scores)

    def _with_colour(self, x: np.ndarray, patch: np.ndarray, scores) -> np.ndarray:
        """Return the channels ``x`` of ``patch`` and, with a colour model, its colour channel."""
        if self.colour_model is None:
            return x
        return np.concatenate([x, self._colour_channel(patch, scores)[None]])

    def _windowed_spectrum(self, x: np.ndarray, first: int = 0) -> np.ndarray:
        """Return the spectrum of feature channels ``x``, the filter's ``first`` on, windowed."""
        return sfft.rfft2(x * self.window[first:first + len(x)]).astype(np.complex64, copy=False)

    def _spectrum(self, frame: np.ndarray, pos, scale: float, angle: float) -> np.ndarray:
        """Return the spectrum of every windowed feature channel of the region at ``pos``."""
        return self._windowed_spectrum(self._features(self._patch(frame, pos, scale, angle)))


def _bilinear_circular(resp: np.ndarray, y: float, x: float) -> float:
    rows, cols = resp.shape
    y0, x0 = int(np.floor(y)), int(np.floor(x))
    fy, fx = y - y0, x - x0
    y0, x0 = y0 % rows, x0 % cols
    y1, x1 = (y0 + 1) % rows, (x0 + 1) % cols
    return float(
        (1 - fy) * ((1 - fx) * resp[y0, x0] + fx * resp[y0, x1])
        + fy * ((1 - fx) * resp[y1, x0] + fx * resp[y1, x1])
    )


@numba.njit(cache=True, fastmath=True, nogil=True)
def _f_step(xf, yfc, dinv, g, h, fp, cg, ch, cp, use_gh, use_fp, out, xq):
    """
    Compute STRCF's f-step (eq. 8) per frequency.

    ``q = cg g - ch h + cp fp`` (the g and h terms only with ``use_gh``, the fp term only with
    ``use_fp``), ``f = q + x (conj(y) - x^H q) dinv``.  ``out`` may be passed as an unused ``g``,
    ``h`` or ``fp``: those are not read.
    """
    C, H, W = xf.shape
    if not use_gh and not use_fp:
        for d in range(C):
            for i in range(H):
                for j in range(W):
                    out[d, i, j] = xf[d, i, j] * (yfc[i, j] * dinv[i, j])
        return
    xq[:, :] = 0.0
    for d in range(C):
        for i in range(H):
            for j in range(W):
                if use_gh and use_fp:
                    q = cg * g[d, i, j] - ch * h[d, i, j] + cp * fp[d, i, j]
                elif use_gh:
                    q = cg * g[d, i, j] - ch * h[d, i, j]
                else:
                    q = cp * fp[d, i, j]
                out[d, i, j] = q
                xq[i, j] += np.conj(xf[d, i, j]) * q
    for i in range(H):
        for j in range(W):
            xq[i, j] = (yfc[i, j] - xq[i, j]) * dinv[i, j]
    for d in range(C):
        for i in range(H):
            for j in range(W):
                out[d, i, j] += xf[d, i, j] * xq[i, j]
