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
Hand-crafted features of the correlation filters: fHOG, Colour Names and grey, on 4x4 cells.

Maps are channel-first, ``(C, rows, cols)`` float32, one value per ``cell x cell`` block of pixels
(``rows = H // cell``; pixels beyond the last full cell are ignored).

* fHOG: Felzenszwalb et al.'s 31-channel HOG ("Object Detection with Discriminatively Trained
  Part-Based Models", TPAMI 2010, sec. 6) as Piotr Dollar's ``fhog`` computes it, the feature of
  DSST, SRDCF, BACF, STRCF, ECO-HC, ARCF and AutoTrack: the gradient by centred differences per
  colour channel, keeping the channel of largest magnitude; its signed orientation to the nearest
  of 18 bins, the vote (magnitude / cell^2) split bilinearly between the 4 nearest cells; the 9
  contrast-insensitive histograms; four 2x2-block normalizations per cell; 18 signed + 9 unsigned
  channels of the normalized values clipped at 0.2, and 4 texture channels.
* Colour Names: the 10-channel normalized CN of van de Weijer et al. (TIP 2009) in the form of
  Danelljan et al. (CVPR 2014), from the table ``data/colour_names.npy`` (row of an 8-bit pixel:
  ``R//8 + 32 G//8 + 1024 B//8``), averaged over the cell; and grey ``gray / 255 - 0.5`` averaged
  over the cell.

:func:`extract` stacks grey (1) + fHOG (31) + CN (10) = 42 channels on colour frames and grey +
fHOG = 32 on grey frames (CN carries nothing on a grey pixel): the feature set of STRCF and
AutoTrack.
"""
from __future__ import annotations

from functools import cache
import math
from pathlib import Path

import numba
import numpy as np

__all__ = [
    'N_HOG', 'N_CN', 'CN_START', 'CELL',
    'colour_names', 'fhog', 'fhog_batch', 'n_channels', 'extract',
]

N_HOG = 31
N_CN = 10
CN_START = 1 + N_HOG  # the first Colour Names channel of extract()'s map (grey, fHOG, CN)
CELL = 4  # pixels per cell side


@cache
def colour_names() -> np.ndarray:
    """
    Return the (32768, 10) float32 Colour Names table.

    It is loaded from ``data/colour_names.npy`` (see ``data/README.md``).
    """
    return np.ascontiguousarray(
        np.load(Path(__file__).with_name('data') / 'colour_names.npy'), dtype=np.float32
    )


@numba.njit(inline='always', fastmath=True, nogil=True)
def _atan2_pos(y, x):
    """
    ``atan2(y, x)`` mapped to [0, 2 pi).

    Octant reduction + a degree-7 odd polynomial for atan on [0, 1] (max error 2e-4 rad = 0.01 deg,
    far below the 20 deg bin width; Piotr's toolbox also uses a table).  Written with selects, not
    branches, so that a loop over pixels vectorizes.
    """
    ax = abs(x)
    ay = abs(y)
    mx = max(ax, ay)
    mn = min(ax, ay)
    a = mn / mx if mx != 0.0 else 0.0
    s = a * a
    r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a
    r = 1.57079637 - r if ay > ax else r
    r = 3.14159274 - r if x < 0.0 else r
    r = 6.28318548 - r if y < 0.0 else r
    return r if mx != 0.0 else 0.0


@numba.njit(cache=True, fastmath=True, nogil=True)
def _grad_bins(img, cell, O0, M0):
    """
    Per pixel: the nearest of 18 orientation bins ``O0`` and the vote ``M0`` (magnitude / cell^2).

    Both are those of the colour channel of largest gradient (centred differences, one-sided at
    the border; the first channel on a tie).  ``img`` is (H, W, C) uint8 or float32.  A row at a
    time: the channels' gradients into row buffers, then the orientations of the row.
    """
    H, W, C = img.shape
    norm = 1.0 / (cell * cell)
    omult = 18.0 / (2.0 * math.pi)
    gx = np.empty(W)
    gy = np.empty(W)
    gxb = np.empty(W)
    gyb = np.empty(W)
    best = np.empty(W)
    for y in range(H):
        ym = y - 1 if y > 0 else 0
        yp = y + 1 if y < H - 1 else H - 1
        fy = 0.5 if (y > 0 and y < H - 1) else 1.0
        for c in range(C):
            # the interior's centred differences without branches, so that the loops vectorize
            for x in range(1, W - 1):
                gx[x] = 0.5 * (np.float32(img[y, x + 1, c]) - np.float32(img[y, x - 1, c]))
            if W > 1:
                gx[0] = 1.0 * (np.float32(img[y, 1, c]) - np.float32(img[y, 0, c]))
                gx[W - 1] = 1.0 * (np.float32(img[y, W - 1, c]) - np.float32(img[y, W - 2, c]))
            else:
                gx[0] = 0.0
            for x in range(W):
                gy[x] = fy * (np.float32(img[yp, x, c]) - np.float32(img[ym, x, c]))
            for x in range(W):
                m2 = gx[x] * gx[x] + gy[x] * gy[x]
                take = c == 0 or m2 > best[x]
                best[x] = m2 if take else best[x]
                gxb[x] = gx[x] if take else gxb[x]
                gyb[x] = gy[x] if take else gyb[x]
        for x in range(W):
            o0 = int(_atan2_pos(gyb[x], gxb[x]) * omult + 0.5)
            O0[y, x] = o0 - 18 if o0 >= 18 else o0
            M0[y, x] = math.sqrt(best[x]) * norm


@numba.njit(cache=True, fastmath=True, nogil=True)
def _accumulate(O0, M0, cell, R):
    """
    Spatially bilinear votes into the 4 nearest cells.

    ``R`` is (hb + 2, wb + 2, 18), one cell of padding each side catching the votes that fall
    outside the map.  (Direct 3-D indexing: keeping row views in variables costs numba reference
    counting.)
    """
    H, W = O0.shape
    hb = H // cell
    wb = W // cell
    inv = 1.0 / cell
    nx = wb * cell
    # the column's cell and weight are the same on every row
    xb0s = np.empty(nx, np.int64)
    xds = np.empty(nx)
    for x in range(nx):
        xb = (x + 0.5) * inv - 0.5
        xb0s[x] = int(math.floor(xb))
        xds[x] = xb - xb0s[x]
    for y in range(hb * cell):
        yb = (y + 0.5) * inv - 0.5
        yb0 = int(math.floor(yb))
        yd = yb - yb0
        for x in range(nx):
            xb0 = xb0s[x]
            xd = xds[x]
            o0 = O0[y, x]
            m0 = M0[y, x]
            R[yb0 + 1, xb0 + 1, o0] += (1.0 - yd) * (1.0 - xd) * m0
            R[yb0 + 1, xb0 + 2, o0] += (1.0 - yd) * xd * m0
            R[yb0 + 2, xb0 + 1, o0] += yd * (1.0 - xd) * m0
            R[yb0 + 2, xb0 + 2, o0] += yd * xd * m0


@numba.njit(cache=True, fastmath=True, nogil=True)
def _fhog_into(img, cell, clip, out, off):
    """
    Write the 31 fHOG channels of ``img`` (H, W, C) uint8 or float32 into ``out[off:off+31]``.

    See the module docstring.
    """
    H, W, C = img.shape
    hb = H // cell
    wb = W // cell
    O0 = np.empty((H, W), np.int32)
    M0 = np.empty((H, W), np.float32)
    _grad_bins(img, cell, O0, M0)
    R = np.zeros((hb + 2, wb + 2, 18), np.float32)
    _accumulate(O0, M0, cell, R)
    # cell energies of the contrast-insensitive histograms (cell (i, j) is R[i + 1, j + 1])
    E = np.empty((hb, wb), np.float32)
    for i in range(hb):
        for j in range(wb):
            e = np.float32(0.0)
            for o in range(9):
                v = R[i + 1, j + 1, o] + R[i + 1, j + 1, o + 9]
                e += v * v
            E[i, j] = e
    # block normalization factors: block (i, j) = cells (i..i+1, j..j+1); index (i+1, j+1) of N;
    # edges replicated
    eps = 1e-4 / 4.0 / cell / cell / cell / cell
    N = np.zeros((hb + 1, wb + 1), np.float32)
    for i in range(hb - 1):
        for j in range(wb - 1):
            N[i + 1, j + 1] = 1.0 / math.sqrt(
                E[i, j] + E[i + 1, j] + E[i, j + 1] + E[i + 1, j + 1] + eps
            )
    for i in range(hb + 1):
        for j in range(wb + 1):
            ii = min(max(i, 1), hb - 1)
            jj = min(max(j, 1), wb - 1)
            if (ii != i or jj != j) and hb > 1 and wb > 1:
                N[i, j] = N[ii, jj]
    r = 0.2357
    for i in range(hb):
        for j in range(wb):
            n0 = N[i + 1, j + 1]
            n1 = N[i, j + 1]
            n2 = N[i + 1, j]
            n3 = N[i, j]
            t0 = 0.0
            t1 = 0.0
            t2 = 0.0
            t3 = 0.0
            for o in range(18):
                v = R[i + 1, j + 1, o]
                a0 = min(v * n0, clip)
                a1 = min(v * n1, clip)
                a2 = min(v * n2, clip)
                a3 = min(v * n3, clip)
                out[off + o, i, j] = 0.5 * (a0 + a1 + a2 + a3)
                t0 += a0
                t1 += a1
                t2 += a2
                t3 += a3
            for o in range(9):
                v = R[i + 1, j + 1, o] + R[i + 1, j + 1, o + 9]
                out[off + 18 + o, i, j] = 0.5 * (
                    min(v * n0, clip) + min(v * n1, clip) + min(v * n2, clip) + min(v * n3, clip)
                )
            out[off + 27, i, j] = r * t0
            out[off + 28, i, j] = r * t1
            out[off + 29, i, j] = r * t2
            out[off + 30, i, j] = r * t3


def _kernel_input(img) -> np.ndarray:
    """Return ``img`` for the fHOG kernel: uint8 as it is (exact differences), else float32."""
    a = np.asarray(img)
    return a if a.dtype == np.uint8 else a.astype(np.float32)


def fhog(img: np.ndarray, cell: int = CELL, clip: float = 0.2) -> np.ndarray:
    """
    Felzenszwalb's 31-channel HOG of an image.

    Parameters
    ----------
    img : ndarray
        (H, W) or (H, W, C) image, any numeric type (uint8 images on their 0-255 scale), at least
        2x2.
    cell : int
        Cell side, px.
    clip : float
        Truncation of the normalized histogram values.

    Returns
    -------
    ndarray
        (31, H // cell, W // cell) float32.

    """
    a = _kernel_input(img)
    if a.ndim == 2:
        a = a[:, :, None]
    a = np.ascontiguousarray(a)
    if a.shape[0] < 2 or a.shape[1] < 2:
        raise ValueError(f'fhog needs an image of at least 2x2 pixels, got {a.shape[:2]}')
    out = np.zeros((N_HOG, a.shape[0] // cell, a.shape[1] // cell), np.float32)
    _fhog_into(a, cell, np.float32(clip), out, 0)
    return out


@numba.njit(cache=True, fastmath=True, nogil=True)
def _colour_into(bgr, cell, table, use_cn, out, grey_ch, cn_off):
    """
    Write the per-cell means of grey and of the CN table rows into ``out``.

    The mean of grey/255 - 0.5 goes into ``out[grey_ch]``, that of the CN table rows into
    ``out[cn_off:+10]``.
    """
    H, W, C = bgr.shape
    hb = H // cell
    wb = W // cell
    inv = 1.0 / (cell * cell)
    acc = np.zeros(10, np.float32)
    for i in range(hb):
        for j in range(wb):
            g = 0.0
            for k in range(10):
                acc[k] = 0.0
            for y in range(i * cell, i * cell + cell):
                for x in range(j * cell, j * cell + cell):
                    b = bgr[y, x, 0]
                    if C == 3:
                        gg = bgr[y, x, 1]
                        rr = bgr[y, x, 2]
                    else:
                        gg = b
                        rr = b
                    g += 0.299 * rr + 0.587 * gg + 0.114 * b
                    if use_cn:
                        idx = (rr >> 3) + 32 * (gg >> 3) + 1024 * (b >> 3)
                        for k in range(10):
                            acc[k] += table[idx, k]
            if grey_ch >= 0:
                out[grey_ch, i, j] = g * inv / 255.0 - 0.5
            if use_cn:
                for k in range(10):
                    out[cn_off + k, i, j] = acc[k] * inv


def n_channels(colour: bool) -> int:
    """Return how many channels :func:`extract` returns: 42 on colour frames, 32 on grey ones."""
    return CN_START + (N_CN if colour else 0)


def extract(
    patch_bgr: np.ndarray, colour: bool, cell: int = CELL, out: np.ndarray | None = None
) -> np.ndarray:
    """
    Grey + fHOG (+ Colour Names on colour frames) of a uint8 patch.

    The map is ``(C, H // cell, W // cell)`` float32.

    Parameters
    ----------
    patch_bgr : ndarray
        (H, W, 3) BGR or (H, W) grey uint8 patch.
    colour : bool
        Whether the frame has colour (a grey frame's fHOG is taken on one channel and has no CN).
    cell : int
        Cell side, px.
    out : ndarray, optional
        (C, H // cell, W // cell) float32 filled in place.

    Returns
    -------
    ndarray
        The feature map (``out`` when given).

    """
    a = np.ascontiguousarray(patch_bgr)
    if a.ndim == 2:
        a = a[:, :, None]
    if not colour and a.shape[2] == 3:
        a = np.ascontiguousarray(a[:, :, :1])
    shape = (n_channels(colour), a.shape[0] // cell, a.shape[1] // cell)
    if out is None:
        out = np.empty(shape, np.float32)
    _colour_into(a, cell, colour_names(), colour, out, 0, CN_START)
    _fhog_into(a, cell, np.float32(0.2), out, 1)
    return out


@numba.njit(cache=True, fastmath=True, nogil=True)
def _fhog_batch(patches, cell, clip, out):
    for k in range(patches.shape[0]):
        _fhog_into(patches[k], cell, clip, out[k], 0)


def fhog_batch(patches: np.ndarray, cell: int = CELL, clip: float = 0.2) -> np.ndarray:
    """
    Return the fHOG of K equally sized patches ``(K, H, W[, C])`` in one call.

    The maps are ``(K, 31, H // cell, W // cell)`` float32.
    """
    p = np.ascontiguousarray(_kernel_input(patches))
    if p.ndim == 3:
        p = p[..., None]
    out = np.zeros((p.shape[0], N_HOG, p.shape[1] // cell, p.shape[2] // cell), np.float32)
    _fhog_batch(p, cell, np.float32(clip), out)
    return out
