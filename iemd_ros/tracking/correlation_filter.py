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
What the translation filter (STRCF) and the scale filter (fDSST) share.

Region sampling, windows, labels, the response's confidence and its sub-cell peak, and the fused
spectral kernels.

Coordinates: a centre is ``(cx, cy)`` in pixels with pixel centres at integers (``x + (w - 1) / 2``
of a 0-based box ``(x, y, w, h)``, :mod:`iemd_ros.common.boxes`); a size is ``(w, h)``.
"""
from __future__ import annotations

import cv2
from iemd_ros.tracking.appearance import warp_window, window_axes
import numba
import numpy as np

__all__ = ['sample_region', 'hann_inner', 'gaussian_label', 'apce', 'SubCellPeak']


# -------------------------------------------------------------------------------- sampling
def sample_region(img: np.ndarray, centre, region_wh, out_wh, angle: float = 0.0) -> np.ndarray:
    """
    Return the region of ``region_wh`` (w, h) pixels centred on ``centre`` and turned by ``angle``.

    It is resampled to ``out_wh`` pixels; parts outside the image replicate its border.

    Unturned (the usual case), the region is ``[round(cx) - w//2, round(cx) - w//2 + w)`` (STRCF's
    ``get_pixels`` with its rounded sample position); shrinking by ``f >= 2`` first averages
    ``k x k`` blocks, ``k = floor(f)`` (OpenCV's integer INTER_AREA; the region rounded to a
    multiple of k), then resamples bilinearly by the remaining factor below 2, as the MATLAB
    trackers' ``mexResize(..., 'auto')`` averages over areas.  A turned region (the gyro prior's
    camera roll) is warped bilinearly from the image shrunk by ``pyrDown`` until the remaining
    factor is below 2, so that it is not aliased either.

    Parameters
    ----------
    img : ndarray
        (H, W) or (H, W, 3) uint8 image.
    centre : array_like
        (cx, cy) of the region.
    region_wh : array_like
        (w, h) of the region in image pixels.
    out_wh : array_like
        (w, h) of the sample.
    angle : float
        Turn of the region's axes (radians; its x axis along (cos, sin)).

    Returns
    -------
    ndarray
        The sample, (out_h, out_w[, 3]) uint8.

    """
    ow, oh = int(out_wh[0]), int(out_wh[1])
    if angle == 0.0:
        return _axis_aligned(img, centre, region_wh, ow, oh)
    sx, sy = float(region_wh[0]) / ow, float(region_wh[1]) / oh
    level = max(int(np.floor(np.log2(max(min(sx, sy), 1.0)))), 0)
    src, f = img, 1.0
    for _ in range(level):
        if min(src.shape[:2]) < 4:
            break
        src, f = cv2.pyrDown(src), f * 2.0
    centre_at_level = (np.asarray(centre, dtype=np.float64) + 0.5) / f - 0.5
    return warp_window(src, centre_at_level, window_axes(angle) * [sx / f, sy / f], (ow, oh))


def _axis_aligned(img, centre, region_wh, ow: int, oh: int) -> np.ndarray:
    sw = max(int(round(float(region_wh[0]))), 2)
    sh = max(int(round(float(region_wh[1]))), 2)
    k = int(min(sw / ow, sh / oh))
    if k >= 2:
        sw, sh = k * max(int(round(sw / k)), 1), k * max(int(round(sh / k)), 1)
    x0 = int(round(float(centre[0]))) - sw // 2
    y0 = int(round(float(centre[1]))) - sh // 2
    crop = _crop(img, x0, y0, sw, sh)
    if sw == ow and sh == oh:
        return np.ascontiguousarray(crop)
    if k >= 2:
        crop = cv2.resize(crop, (sw // k, sh // k), interpolation=cv2.INTER_AREA)
        if crop.shape[1] == ow and crop.shape[0] == oh:
            return crop
    return cv2.resize(crop, (ow, oh), interpolation=cv2.INTER_LINEAR)


def _crop(img, x0: int, y0: int, sw: int, sh: int) -> np.ndarray:
    """
    Integer crop ``[x0, x0 + sw) x [y0, y0 + sh)`` of ``img``.

    Outside the image its border pixels are replicated.
    """
    H, W = img.shape[:2]
    x1, y1 = x0 + sw, y0 + sh
    if x0 >= 0 and y0 >= 0 and x1 <= W and y1 <= H:
        return img[y0:y1, x0:x1]
    xa, xb, ya, yb = max(x0, 0), min(x1, W), max(y0, 0), min(y1, H)
    if xa < xb and ya < yb:
        return cv2.copyMakeBorder(
            img[ya:yb, xa:xb], ya - y0, y1 - yb, xa - x0, x1 - xb, cv2.BORDER_REPLICATE
        )
    ix = np.clip(np.arange(x0, x1), 0, W - 1)  # entirely outside: the nearest border pixels
    iy = np.clip(np.arange(y0, y1), 0, H - 1)
    return img[iy[:, None], ix[None, :]]


# -------------------------------------------------------------------------------- windows, labels
def hann_inner(n: int) -> np.ndarray:
    """
    Hann window of length ``n`` without its zero end points.

    It is ``hann(n + 2)(2:end-1)`` of BACF/AutoTrack.
    """
    k = np.arange(1, n + 1)
    return (0.5 - 0.5 * np.cos(2 * np.pi * k / (n + 1))).astype(np.float32)


def gaussian_label(rows: int, cols: int, sigma: float) -> np.ndarray:
    """
    Gaussian of std ``sigma`` (cells) with its peak at index (0, 0), wrapped circularly.

    As in KCF/STRCF.
    """
    ry = np.roll(np.arange(rows) - (rows - 1) // 2, -((rows - 1) // 2))
    rx = np.roll(np.arange(cols) - (cols - 1) // 2, -((cols - 1) // 2))
    return np.exp(-0.5 * (ry[:, None] ** 2 + rx[None, :] ** 2) / sigma**2).astype(np.float32)


# -------------------------------------------------------------------------------- confidence
def apce(resp: np.ndarray) -> float:
    """
    Average peak-to-correlation energy ``|F_max - F_min|^2 / mean((F - F_min)^2)``.

    From LMCF (CVPR 2017), eq. 11.
    """
    mx, mn = float(resp.max()), float(resp.min())
    den = float(np.mean((resp - mn) ** 2))
    return (mx - mn) ** 2 / den if den > 0 else 0.0


class SubCellPeak:
    """
    The response's maximum refined by Newton's method on its Fourier interpolant.

    As SRDCF does (Danelljan et al., ICCV 2015, sec. 4.2), from the rfft2 half spectrum ``R``.

    ``r(Y, X) = 1/T Re sum c_kx R(ky, kx) exp(i (ky Y + kx X))`` with ``Y = 2 pi y / rows``,
    ``X = 2 pi x / cols`` and ``c_kx = 2`` for the frequencies whose conjugate is not stored.

    Parameters
    ----------
    rows, cols : int
        The response's shape.
    iterations : int
        Newton iterations (stopped early where the Hessian is not negative definite).

    """

    def __init__(self, rows: int, cols: int, iterations: int = 5):
        self.rows, self.cols, self.iterations = rows, cols, iterations
        self.ky = (np.fft.fftfreq(rows) * rows).astype(np.float64)
        half = cols // 2 + 1
        self.kx = np.arange(half, dtype=np.float64)
        self.c = np.full(half, 2.0)
        self.c[0] = 1.0
        if cols % 2 == 0:
            self.c[-1] = 1.0
        self.T = rows * cols

    def __call__(self, resp: np.ndarray, rf: np.ndarray) -> tuple[float, float, float]:
        """
        ``(dy, dx, value)``: the peak's displacement in cells from the origin, and its value.

        The displacement is signed and circular; the value is the interpolated response there.
        """
        rows, cols = self.rows, self.cols
        idx = int(np.argmax(resp))
        r0, c0 = divmod(idx, cols)
        v0 = float(resp.flat[idx])
        ty = (r0 + (rows - 1) // 2) % rows - (rows - 1) // 2
        tx = (c0 + (cols - 1) // 2) % cols - (cols - 1) // 2
        Y0, X0 = 2 * np.pi * ty / rows, 2 * np.pi * tx / cols
        Y, X, v = _newton(rf, self.ky, self.kx, self.c, Y0, X0, self.iterations)
        v /= self.T
        # no ascent (a saddle at the integer peak): a parabola per axis instead
        if not np.isfinite(v) or v <= v0:
            return (
                ty + _vertex(resp[(r0 - 1) % rows, c0], v0, resp[(r0 + 1) % rows, c0]),
                tx + _vertex(resp[r0, (c0 - 1) % cols], v0, resp[r0, (c0 + 1) % cols]),
                v0,
            )
        dy = (np.mod(Y + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * rows
        dx = (np.mod(X + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * cols
        return float(dy), float(dx), float(v)


def _vertex(left: float, centre: float, right: float) -> float:
    """
    Offset in (-0.5, 0.5) of the vertex of the parabola through three samples.

    The samples lie around their maximum.
    """
    den = left - 2.0 * centre + right
    return float(np.clip(0.5 * (left - right) / den, -0.5, 0.5)) if den < 0 else 0.0


@numba.njit(cache=True, nogil=True)
def _newton(R, ky, kx, c, Y, X, iterations):
    """
    Newton iterations on ``F(Y, X) = Re sum_ab R_ab c_b exp(i (ky_a Y + kx_b X))``.

    Returns (Y, X, F(Y, X)).
    """
    H, Wh = R.shape
    ex = np.empty(Wh, np.complex128)
    v = 0.0
    for it in range(iterations + 1):
        for b in range(Wh):
            ex[b] = c[b] * np.exp(1j * kx[b] * X)
        v = gy = gx = hyy = hxx = hxy = 0.0
        for a in range(H):
            s0 = s1 = s2 = 0j
            for b in range(Wh):
                t = ex[b] * R[a, b]
                s0 += t
                s1 += kx[b] * t
                s2 += kx[b] * kx[b] * t
            ey = np.exp(1j * ky[a] * Y)
            t0, t1, t2 = ey * s0, ey * s1, ey * s2
            v += t0.real
            gy -= ky[a] * t0.imag
            gx -= t1.imag
            hyy -= ky[a] * ky[a] * t0.real
            hxx -= t2.real
            hxy -= ky[a] * t1.real
        if it == iterations:
            break
        det = hyy * hxx - hxy * hxy
        if not (det > 0 and hyy < 0):
            break
        Y = Y - (hxx * gy - hxy * gx) / det
        X = X - (hyy * gx - hxy * gy) / det
    return Y, X, v


# -------------------------------------------------------------------------------- spectral kernels
@numba.njit(cache=True, fastmath=True, nogil=True)
def energy(xf, out):
    """``out[i, j] = sum_d |xf[d, i, j]|^2``."""
    C, H, W = xf.shape
    out[:, :] = 0.0
    for d in range(C):
        for i in range(H):
            for j in range(W):
                v = xf[d, i, j]
                out[i, j] += v.real * v.real + v.imag * v.imag


@numba.njit(cache=True, fastmath=True, nogil=True)
def correlate(f, z, out):
    """
    ``out[i, j] = sum_d conj(f[d, i, j]) z[d, i, j]``.

    The response spectrum of filter ``f`` on sample ``z``.
    """
    C, H, W = f.shape
    out[:, :] = 0.0
    for d in range(C):
        for i in range(H):
            for j in range(W):
                out[i, j] += np.conj(f[d, i, j]) * z[d, i, j]
