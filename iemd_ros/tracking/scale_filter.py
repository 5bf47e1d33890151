"""Discriminative scale estimation: a one-dimensional correlation filter over scales (DSST).

The EMD of the iEMD histograms hardly changes with the window's scale: its patch positions are in normalized window
units and its patches are normalized, so a window somewhat too large or too small scores almost the same EMD
(docs/decisions.md#scale-estimator).  This is Danelljan et al.'s scale filter ("Accurate Scale Estimation for Robust
Visual Tracking", BMVC 2014): the window at ``n_scales`` scales ``scale_step**k`` around the current size is
resampled to one small model size and described by gradient-orientation histograms; the features of the scales,
tapered by a Hann window over the scale axis, form a d x S sample whose desired response is a Gaussian peaked at the
current scale.  The filter (eq. 5 of DSST, solved in the Fourier domain along the scale axis) and its running
average (learning rate eta) give, on the next frame, the scale whose response peaks.  All scales are sampled from
one pyramid level, so their smoothing differs by the scale only, and the filter learns from the estimate's own
sample.
"""
from __future__ import annotations

import numpy as np

from iemd_ros.tracking.appearance import ImagePyramid
from iemd_ros.tracking.correlation_filter import FilterModel, hann, model_size, orientation_histograms, parabola_peak


class ScaleFilter:
    """DSST scale filter (see the module docstring).

    ``init`` at the target's window, then per frame ``estimate`` and, when the frame is tracked, ``update``.  Windows
    are (centre, size (w, h), angle) as in :meth:`ImagePyramid.sample`.  ``update`` learns from the sample ``estimate``
    took, its desired response centred on the estimated scale (a shift along the scale axis, a phase in the Fourier
    domain) rather than from a second sample at the new size as DSST does: one sample per frame instead of two.

    Parameters
    ----------
    n_scales : int, optional
        Number of scales S, odd and >= 3.
    scale_step : float, optional
        Ratio of consecutive scales, > 1: the scales are ``scale_step**k`` around the current size.
    learning_rate : float, optional
        Rate eta of the filter's running average, in (0, 1].
    regularization : float, optional
        Added to the filter's denominator.
    sigma : float, optional
        Width of the desired Gaussian response over the scale index, in scale steps (DSST's 33 / sqrt(33) / 4).
    model_area : int, optional
        About how many pixels each scaled window is resampled to.

    Raises
    ------
    ValueError
        For an even ``n_scales`` or one below 3, a ``scale_step`` not above 1, or a ``learning_rate`` outside (0, 1].
    """

    def __init__(self, n_scales: int = 33, scale_step: float = 1.02, learning_rate: float = 0.025,
                 regularization: float = 0.01, sigma: float = 1.4375, model_area: int = 512):
        if n_scales < 3 or n_scales % 2 == 0:
            raise ValueError(f"n_scales must be odd and >= 3, got {n_scales}")
        if not scale_step > 1.0:
            raise ValueError(f"scale_step must be > 1, got {scale_step}")
        offsets = np.arange(n_scales) - n_scales // 2
        self.step = scale_step
        self.factors = scale_step ** offsets  # relative scales, ascending; the middle one is 1
        # Desired response: a Gaussian over the scale index (sigma in scale steps: DSST's 33 / sqrt(33) / 4)
        # peaked at the middle, and the frequencies that shift it.
        self._desired = np.fft.fft(np.exp(-0.5 * (offsets / sigma) ** 2))
        self._frequencies = 2.0 * np.pi * np.fft.fftfreq(n_scales)
        self._taper = hann(n_scales)  # over the scales
        self.model_area = model_area
        self.model_size = None  # (w, h) of the resampled windows, multiples of CELL
        self._filter = FilterModel(learning_rate, regularization, channel_axis=0)  # spectra (d, S)
        self._last = None  # (spectrum, estimated shift in scale steps) of the last estimate

    def init(self, pyramid: ImagePyramid, center, size, angle: float = 0.0) -> None:
        """Learn the filter from the window (``center``, ``size``) of the first frame.

        Parameters
        ----------
        pyramid : ImagePyramid
            The first frame.
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        angle : float, optional
            The window's turn, radians.
        """
        self.model_size = model_size(size, self.model_area, min_cells=2)
        self._filter.reset()
        self._learn(self._spectrum(pyramid, center, size, angle), 0.0)
        self._last = None

    def estimate(self, pyramid: ImagePyramid, center, size, angle: float = 0.0, bounds=None) -> float:
        """Relative scale of the target in ``pyramid``'s frame against the window ``size`` at ``center``.

        The factor where the filter response peaks, refined between scales by a parabola through the peak.  ``update``
        learns at the scale returned.

        Parameters
        ----------
        pyramid : ImagePyramid
            The frame.
        center, size : array_like
            The window, as in :meth:`init`.
        angle : float, optional
            The window's turn, radians.
        bounds : tuple of float, optional
            (lowest, highest) factor the estimate is limited to.

        Returns
        -------
        float
            The relative scale factor.

        Raises
        ------
        RuntimeError
            Before :meth:`init`.
        """
        if not self._filter.trained:
            raise RuntimeError("ScaleFilter.estimate() called before init()")
        spectrum = self._spectrum(pyramid, center, size, angle)
        response = np.fft.ifft(self._filter.response(spectrum)).real
        peak = int(np.argmax(response))
        shift = peak - len(response) // 2
        if 0 < peak < len(response) - 1:
            shift += parabola_peak(*response[peak - 1:peak + 2])
        if bounds is not None:
            shift = float(np.clip(shift, *(np.log(bounds) / np.log(self.step))))
        self._last = (spectrum, shift)
        return float(self.step**shift)

    def update(self) -> None:
        """Blend the last estimate's sample in (the running average of DSST eq. 5).

        Its desired response is peaked at the scale it estimated.

        Raises
        ------
        RuntimeError
            Without an :meth:`estimate` since :meth:`init` or the last update.
        """
        if self._last is None:
            raise RuntimeError("ScaleFilter.update() needs an estimate() first")
        self._learn(*self._last)
        self._last = None

    # ------------------------------------------------------------ internals
    def _learn(self, spectrum: np.ndarray, shift: float) -> None:
        self._filter.learn(self._desired * np.exp(-1j * self._frequencies * shift), spectrum)

    def _spectrum(self, pyramid: ImagePyramid, center, size, angle: float) -> np.ndarray:
        """FFT along the scales of the (d, S) sample: per scale, the window at that scale resampled to the
        model size and described by :func:`orientation_histograms`, tapered by the Hann window over the scales."""
        size = np.asarray(size, dtype=np.float64)
        windows = pyramid.sample_scales(center, size, self.model_size, self.factors, angle)
        return np.fft.fft(orientation_histograms(windows).T * self._taper, axis=1)
