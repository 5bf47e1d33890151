"""What the scale and the translation filter share: DSST's correlation filter and its features.

* :class:`FilterModel`: a multi-channel correlation filter in the Fourier domain (DSST eq. 5) learnt as a
  running average;
* :func:`orientation_histograms`: the features, gradient-orientation histograms on CELL x CELL cells;
* :func:`parabola_peak`: a response's peak refined between samples;
* :func:`model_size` and :func:`hann`: the resampled window and the taper of the features.
"""
from __future__ import annotations

import numba
import numpy as np

N_ORIENTATIONS = 9  # unsigned gradient orientation bins of the features
CELL = 4  # feature cell size, model pixels
FLOOR = 0.05  # added to a cell histogram's norm (gradient magnitudes in grey levels per pixel, [0, 1] scale)


class FilterModel:
    """Multi-channel correlation filter in the Fourier domain (DSST eq. 5).

    Shared by the scale and the translation filter: numerator G conj(F_l) and denominator sum_l |F_l|^2 of the samples
    learnt, as running averages at ``learning_rate`` (the first sample replaces them).

    Parameters
    ----------
    learning_rate : float
        Rate of the running averages, in (0, 1].
    regularization : float
        Added to the denominator when the filter responds.
    channel_axis : int
        Axis of the feature channels in the spectra.

    Raises
    ------
    ValueError
        For a ``learning_rate`` outside (0, 1].
    """

    def __init__(self, learning_rate: float, regularization: float, channel_axis: int):
        if not 0.0 < learning_rate <= 1.0:
            raise ValueError(f"learning_rate must be in (0, 1], got {learning_rate}")
        self.learning_rate = learning_rate
        self.regularization = regularization
        self.channel_axis = channel_axis
        self.reset()

    @property
    def trained(self) -> bool:
        """Whether a sample has been learnt since the last :meth:`reset`."""
        return self._numerator is not None

    def reset(self) -> None:
        """Forget the samples learnt."""
        self._numerator = self._denominator = None

    def learn(self, desired: np.ndarray, spectrum: np.ndarray) -> None:
        """Blend in a sample with its desired response.

        Parameters
        ----------
        desired : ndarray
            Spectrum G of the desired response.
        spectrum : ndarray
            Spectra F_l of the sample's channels.
        """
        numerator = desired * np.conj(spectrum)
        denominator = (spectrum * np.conj(spectrum)).real.sum(self.channel_axis)
        if self._numerator is None:
            self._numerator, self._denominator = numerator, denominator
            return
        eta = self.learning_rate
        self._numerator = (1.0 - eta) * self._numerator + eta * numerator
        self._denominator = (1.0 - eta) * self._denominator + eta * denominator

    def response(self, spectrum: np.ndarray) -> np.ndarray:
        """Spectrum of the filter's response to a sample, channels summed.

        Parameters
        ----------
        spectrum : ndarray
            Spectra of the sample's channels.

        Returns
        -------
        ndarray
            The response's spectrum.
        """
        return (self._numerator * spectrum).sum(self.channel_axis) / (self._denominator + self.regularization)


def model_size(size, area: float, min_cells: int) -> tuple[int, int]:
    """Size in model pixels of a window resampled to about ``area`` pixels with its aspect ratio.

    Parameters
    ----------
    size : array_like
        (w, h) of the window.
    area : float
        Number of model pixels aimed at.
    min_cells : int
        Least number of CELLs per axis.

    Returns
    -------
    tuple of int
        (w, h) in model pixels: whole CELLs, at least ``min_cells`` of them per axis.
    """
    w, h = (float(v) for v in size)
    f = np.sqrt(area / (w * h))
    return tuple(int(max(min_cells, round(v * f / CELL))) * CELL for v in (w, h))


def hann(n: int) -> np.ndarray:
    """Hann window of ``n`` samples without its zero ends (every sample keeps some weight).

    Parameters
    ----------
    n : int
        Number of samples.

    Returns
    -------
    ndarray
        (n,) weights.
    """
    return np.hanning(n + 2)[1:-1]


def parabola_peak(left: float, centre: float, right: float) -> float:
    """Sub-sample offset of a maximum: the vertex of the parabola through three samples around it.

    Parameters
    ----------
    left, centre, right : float
        Three consecutive samples, ``centre`` the maximum.

    Returns
    -------
    float
        Offset of the vertex from ``centre``, in samples, within +-0.5; 0 when the samples are not concave.
    """
    curvature = left - 2.0 * centre + right
    return 0.5 * (left - right) / curvature if curvature < 0 else 0.0


def orientation_histograms(windows: np.ndarray) -> np.ndarray:
    """Gradient-orientation histograms of each window, as one vector per window.

    Central-difference gradients (one-sided at the border); unsigned orientations in ``N_ORIENTATIONS`` bins, weighted
    by the gradient magnitude, summed over CELL x CELL cells; each cell's histogram divided by its L2 norm plus a floor
    (flat cells stay short): a HOG without blocks, invariant to brightness and contrast.

    Parameters
    ----------
    windows : ndarray
        (S, H, W) windows; H and W are multiples of CELL.

    Returns
    -------
    ndarray
        (S, d) features.

    Raises
    ------
    ValueError
        When H or W is not a multiple of CELL.
    """
    windows = np.ascontiguousarray(windows, dtype=np.float32)
    n, h, w = windows.shape
    if h % CELL or w % CELL:
        raise ValueError(f"window size {w}x{h} is not a multiple of the {CELL} px cell")
    return _orientation_histograms(windows).reshape(n, -1)


_BOUNDARY_COS = np.cos(np.arange(N_ORIENTATIONS) * np.pi / N_ORIENTATIONS)
_BOUNDARY_SIN = np.sin(np.arange(N_ORIENTATIONS) * np.pi / N_ORIENTATIONS)


@numba.njit(cache=True)
def _orientation_histograms(windows):
    n, h, w = windows.shape
    n_rows, n_cols = h // CELL, w // CELL
    hist = np.zeros((n, n_rows, n_cols, N_ORIENTATIONS))
    for k in range(n):
        for y in range(h):
            y0, y1 = max(y - 1, 0), min(y + 1, h - 1)
            for x in range(w):
                x0, x1 = max(x - 1, 0), min(x + 1, w - 1)
                gx = (windows[k, y, x1] - windows[k, y, x0]) / (x1 - x0)
                gy = (windows[k, y1, x] - windows[k, y0, x]) / (y1 - y0)
                if gy < 0.0 or (gy == 0.0 and gx < 0.0):  # unsigned: fold onto [0, pi)
                    gx, gy = -gx, -gy
                # The bin: the last boundary at or below the orientation, i.e. the number of boundaries 1..8 it is
                # at or above (on [0, pi) "at or above boundary b" holds for b up to the bin and fails after it),
                # counted without branches.
                b = 0
                for boundary in range(1, N_ORIENTATIONS):
                    b += gy * _BOUNDARY_COS[boundary] >= gx * _BOUNDARY_SIN[boundary]
                hist[k, y // CELL, x // CELL, b] += np.sqrt(gx * gx + gy * gy)
    for k in range(n):
        for r in range(n_rows):
            for c in range(n_cols):
                norm = 0.0
                for b in range(N_ORIENTATIONS):
                    norm += hist[k, r, c, b] ** 2
                scale = 1.0 / (np.sqrt(norm) + FLOOR)
                for b in range(N_ORIENTATIONS):
                    hist[k, r, c, b] *= scale
    return hist
