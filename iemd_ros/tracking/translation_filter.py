"""Discriminative evidence of the window's position: a correlation filter over a search region (DSST/MOSSE).

The iEMD histograms are a generative model with no notion of background: where the target turns or is partly
hidden, a window on background or on a similar object can score an EMD as low as the target's, so the EMD alone
cannot choose between the starting points Algorithm 1 descends from.  A correlation filter trained on the target
against its own surroundings is the complementary view (docs/decisions.md#translation-filter).

The filter is DSST's translation filter (Danelljan et al., BMVC 2014; MOSSE with several channels): the window
padded by ``padding`` on each axis is resampled to about ``model_area`` pixels and described by the
gradient-orientation histograms of :func:`iemd_ros.tracking.correlation_filter.orientation_histograms` (cells of 4
model pixels), tapered by a Hann window; the desired response is a Gaussian of ``sigma_factor`` times the target's
size (in cells) at the window centre.  ``estimate`` gives the displacement where the response peaks and keeps the
response map, which ``response_at`` reads at any window centre.
"""
from __future__ import annotations

import numpy as np

from iemd_ros.tracking.appearance import ImagePyramid, window_axes
from iemd_ros.tracking.correlation_filter import CELL, FilterModel, hann, model_size, orientation_histograms, parabola_peak


class TranslationFilter:
    """DSST's translation filter (see the module docstring).

    ``init`` at the target's window, per frame ``estimate`` at the predicted window (then ``response_at`` for candidate
    centres) and, when the frame is tracked, ``update`` at the tracked window.  Windows are (centre, size (w, h), angle)
    as in :meth:`ImagePyramid.sample`.

    Parameters
    ----------
    padding : float, optional
        The search region is the window's size times 1 + ``padding`` on each axis; >= 0.
    learning_rate : float, optional
        Rate of the filter's running average, in (0, 1].
    regularization : float, optional
        Added to the filter's denominator.
    sigma_factor : float, optional
        Width of the desired Gaussian response, times the target's size in cells.
    model_area : int, optional
        About how many pixels the search region is resampled to.

    Raises
    ------
    ValueError
        For a negative ``padding`` or a ``learning_rate`` outside (0, 1].
    """

    def __init__(self, padding: float = 1.5, learning_rate: float = 0.025, regularization: float = 0.01,
                 sigma_factor: float = 0.1, model_area: int = 4096):
        if padding < 0:
            raise ValueError(f"padding must be >= 0, got {padding}")
        self.padding = padding
        self.sigma_factor = sigma_factor
        self.model_area = model_area
        self.model_size = None  # (w, h) of the resampled search region, multiples of CELL
        self._filter = FilterModel(learning_rate, regularization, channel_axis=-1)  # spectra (rows, cols, d)
        self._response = None  # (response map, centre, cell size in image px, angle) of the last estimate

    def init(self, pyramid: ImagePyramid, center, size, angle: float = 0.0) -> None:
        """Learn the filter from the window (``center``, ``size``) of the first frame.

        Parameters
        ----------
        pyramid : ImagePyramid
            The frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.
        """
        self.model_size = model_size(self._region(size), self.model_area, min_cells=4)
        cols, rows = self.model_size[0] // CELL, self.model_size[1] // CELL
        self._taper = np.outer(hann(rows), hann(cols))[..., None]
        sigma = self.sigma_factor * np.sqrt(cols * rows) / (1.0 + self.padding)
        ys, xs = np.arange(rows) - rows // 2, np.arange(cols) - cols // 2
        peak = np.exp(-0.5 * (ys[:, None] ** 2 + xs[None, :] ** 2) / sigma**2)
        self._desired = np.fft.fft2(np.fft.ifftshift(peak))[..., None]  # peak at cell (0, 0)
        self._filter.reset()
        self._filter.learn(self._desired, self._spectrum(pyramid, center, size, angle))
        self._response = None

    def estimate(self, pyramid: ImagePyramid, center, size, angle: float = 0.0) -> np.ndarray:
        """Displacement to where the response peaks in the region around the window (``center``, ``size``).

        The peak is refined between cells by a parabola through it; the response map is kept for :meth:`response_at`.

        Parameters
        ----------
        pyramid : ImagePyramid
            The frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.

        Returns
        -------
        ndarray
            (dx, dy), image pixels, from ``center``.

        Raises
        ------
        RuntimeError
            Before :meth:`init`.
        """
        if not self._filter.trained:
            raise RuntimeError("TranslationFilter.estimate() called before init()")
        response = np.fft.ifft2(self._filter.response(self._spectrum(pyramid, center, size, angle))).real
        rows, cols = response.shape
        cell_px = self._region(size) / [cols, rows]
        self._response = (response, np.asarray(center, dtype=np.float64), cell_px, angle)
        r, c = np.unravel_index(int(np.argmax(response)), response.shape)
        peak = response[r, c]
        dy = parabola_peak(response[(r - 1) % rows, c], peak, response[(r + 1) % rows, c])
        dx = parabola_peak(response[r, (c - 1) % cols], peak, response[r, (c + 1) % cols])
        cells = np.array([(c + cols // 2) % cols - cols // 2 + dx, (r + rows // 2) % rows - rows // 2 + dy])
        return window_axes(angle) @ (cells * cell_px)

    def response_at(self, point) -> float:
        """The last estimate's response at an image point.

        Parameters
        ----------
        point : array_like
            (x, y) image point.

        Returns
        -------
        float
            The response, bilinear between cells; 0 outside the region.

        Raises
        ------
        RuntimeError
            Before an :meth:`estimate`.
        """
        if self._response is None:
            raise RuntimeError("TranslationFilter.response_at() needs an estimate() first")
        response, center, cell_px, angle = self._response
        rows, cols = response.shape
        c, r = window_axes(angle).T @ (np.asarray(point, dtype=np.float64) - center) / cell_px
        c0, r0 = int(np.floor(c)), int(np.floor(r))
        value = 0.0
        for rr, wr in ((r0, r0 + 1 - r), (r0 + 1, r - r0)):
            for cc, wc in ((c0, c0 + 1 - c), (c0 + 1, c - c0)):
                if abs(rr) <= rows // 2 and abs(cc) <= cols // 2:  # cyclic map: no wrap-around
                    value += wr * wc * response[rr % rows, cc % cols]
        return float(value)

    def update(self, pyramid: ImagePyramid, center, size, angle: float = 0.0) -> None:
        """Blend in a sample at the tracked window (the running average of DSST eq. 5).

        Parameters
        ----------
        pyramid : ImagePyramid
            The frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.
        """
        self._filter.learn(self._desired, self._spectrum(pyramid, center, size, angle))

    def _region(self, size) -> np.ndarray:
        """(w, h) in image pixels of the search region around a window of ``size``: its size times 1 + ``padding``."""
        return np.asarray(size, dtype=np.float64) * (1.0 + self.padding)

    def _spectrum(self, pyramid: ImagePyramid, center, size, angle: float) -> np.ndarray:
        """2-D FFT of the tapered (rows, cols, d) features of the search region around the window."""
        sample = pyramid.sample(center, self._region(size), self.model_size, angle=angle)
        cols, rows = self.model_size[0] // CELL, self.model_size[1] // CELL
        features = orientation_histograms(sample[None]).reshape(rows, cols, -1)
        return np.fft.fft2(features * self._taper, axes=(0, 1))
