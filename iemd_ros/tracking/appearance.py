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
Appearance sampling: target window -> fixed-size template -> local patches (section 4).

Geometry conventions (0-based image pixels, pixel centres at integer coordinates): a window is its
centre ``(cx, cy)`` and size ``(w, h)``.  Template pixel ``u`` (0..T-1) samples image point
``cx + (u - (T-1)/2) * w/T`` along the window's x axis, which a window turned by ``angle`` points
along (cos, sin) (:meth:`ImagePyramid.sample`).  Patch positions ``c`` are the patch centres
relative to the window centre in *normalized window units*: the window spans [-1, 1] on each axis,
so positions, the spatial kernel and the spatial term of the ground distance do not depend on the
target's size in pixels.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import cv2
import numba
import numpy as np


def to_gray(frame: np.ndarray) -> np.ndarray:
    """
    Grey levels in [0, 1] of a uint8 frame.

    The paper's "normalized pixel values" are grey levels
    (docs/decisions.md#grey-patches-template-size).

    Parameters
    ----------
    frame : ndarray
        HxW or HxWx3 (BGR) uint8 frame.

    Returns
    -------
    ndarray
        HxW float32 grey levels in [0, 1].

    """
    return np.multiply(grey_levels(frame), np.float32(1.0 / 255.0), dtype=np.float32)


def grey_levels(frame: np.ndarray, copy: bool = False) -> np.ndarray:
    """
    Return the HxW uint8 grey levels of a uint8 frame.

    Parameters
    ----------
    frame : ndarray
        HxW or HxWx3 (BGR) uint8 frame.
    copy : bool, optional
        Copy a grey frame rather than return it: for a result to keep, which must not share the
        caller's buffer.

    Returns
    -------
    ndarray
        HxW uint8 grey levels: the frame itself if it is grey, unless ``copy``.

    """
    if frame.ndim == 3:
        return cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    return frame.copy() if copy else frame


def window_axes(angle: float) -> np.ndarray:
    """
    Rotation taking the axes of a window turned by ``angle`` to image axes.

    Parameters
    ----------
    angle : float
        The window's turn, radians.

    Returns
    -------
    ndarray
        2x2 rotation whose columns are the window's x and y axes in the image.

    """
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def warp_window(
    image: np.ndarray,
    centre,
    linear: np.ndarray,
    out_size,
    interpolation: int = cv2.INTER_LINEAR,
    origin=(0, 0),
):
    """
    Sample ``image`` on a grid of ``out_size`` pixels mapped affinely around ``centre``.

    Parameters
    ----------
    image : ndarray
        The image to sample.
    centre : array_like
        (x, y) image point of the grid's centre.
    linear : ndarray
        2x2 linear map of grid pixels to image pixels.
    out_size : tuple of int
        (Tw, Th), the sample's size.
    interpolation : int, optional
        OpenCV interpolation flag.
    origin : array_like, optional
        (x, y) whole pixels: where ``image``, a crop, starts in the image ``centre`` refers to
        (its border must be the image's wherever the sample reaches past it).

    Returns
    -------
    ndarray
        The (Th, Tw) sample whose pixel u (0..T-1 per axis) is the image point
        ``centre + linear @ (u - (T-1)/2)``; parts outside the image replicate its border.

    """
    tw, th = (int(v) for v in out_size)
    warp = np.column_stack(
        [linear, np.asarray(centre, dtype=np.float64) - linear @ [(tw - 1) / 2, (th - 1) / 2]]
    )
    warp[:, 2] -= origin
    return cv2.warpAffine(
        image,
        warp,
        (tw, th),
        flags=interpolation | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )


class ImagePyramid:
    """
    Gaussian pyramid of one frame, so large windows are sampled without aliasing.

    A window whose template scale (image pixels per template pixel) is s is sampled bilinearly from
    level ``floor(log2(s))``, where its scale is in [1, 2): every template pixel then integrates at
    least one pyrDown-smoothed pixel.  The levels are built on demand (:meth:`level`).

    Uint8 grey levels are :func:`to_gray`'s levels in [0, 1], converted only where a window at
    level 0 reads them until a level above needs the whole frame.

    Parameters
    ----------
    gray : ndarray
        The frame's grey levels (level 0): HxW uint8, or float.
    max_levels : int, optional
        Most levels above the frame; a level is added only while the one below it has both sides of
        at least 32 pixels.

    """

    def __init__(self, gray: np.ndarray, max_levels: int = 4):
        self._grey = gray if gray.dtype == np.uint8 else None
        # built on demand by level(): most frames only need one or two
        self._levels = [None if self._grey is not None else gray]
        h, w = gray.shape[:2]
        self.n_levels = 1
        while self.n_levels <= max_levels and min(h, w) >= 32:
            h, w = (h + 1) // 2, (w + 1) // 2  # cv2.pyrDown's output size
            self.n_levels += 1

    def level(self, index: int) -> np.ndarray:
        """
        Pyramid level ``index``, computed with the ones below it on first use.

        Parameters
        ----------
        index : int
            Level number, 0 for the frame itself.

        Returns
        -------
        ndarray
            The level's image.

        """
        if self._levels[0] is None:
            self._levels[0] = to_gray(self._grey)
        while len(self._levels) <= index:
            self._levels.append(cv2.pyrDown(self._levels[-1]))
        return self._levels[index]

    def _crops(self, level: int) -> bool:
        """Whether a sample at ``level`` reads a crop: level 0, the whole frame not converted."""
        return level == 0 and self._levels[0] is None

    def _crop(self, xs, ys) -> tuple[np.ndarray, tuple[int, int]]:
        """
        Return (level 0 around the points ``xs``, ``ys``, the crop's origin in it).

        Bilinear reads one pixel past the points; the crop ends where the frame does, so its border
        is the frame's wherever a read falls outside.  Non-finite points read the whole level.
        """
        lo, hi = (np.array([np.min(xs), np.min(ys)]), np.array([np.max(xs), np.max(ys)]))
        if not np.all(np.isfinite([lo, hi])):
            return self.level(0), (0, 0)
        n = self._grey.shape[::-1]
        x0, y0 = (min(max(int(np.floor(v)) - 1, 0), k - 1) for v, k in zip(lo, n))
        x1, y1 = (
            min(max(int(np.ceil(v)) + 2, start + 1), k) for v, start, k in zip(hi, (x0, y0), n)
        )
        return to_gray(self._grey[y0:y1, x0:x1]), (x0, y0)

    def sample(self, center, size, template_size, angle: float = 0.0) -> np.ndarray:
        """
        Resample a window to a template.

        Parameters
        ----------
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like
            (w, h) window size, image pixels.
        template_size : tuple of int
            (Tw, Th).
        angle : float, optional
            Rotation of the window about its centre, radians: its x axis points along (cos, sin) in
            the image.

        Returns
        -------
        ndarray
            The (Th, Tw) template; parts outside the image are padded by replicating the border.

        """
        level, linear, centre = self._geometry(center, size, template_size, angle)
        if not self._crops(level):
            return warp_window(self.level(level), centre, linear, template_size)
        half = (np.asarray(template_size, dtype=np.float64) - 1) / 2
        corners = centre[:, None] + linear @ ([[-1, 1, 1, -1], [-1, -1, 1, 1]] * half[:, None])
        image, origin = self._crop(corners[0], corners[1])
        return warp_window(image, centre, linear, template_size, origin=origin)

    def sample_scales(
        self, center, size, template_size, factors, angle: float = 0.0
    ) -> np.ndarray:
        """
        Return the window scaled by each of ``factors`` about its centre, resampled to templates.

        One remap from the anti-aliasing level of the unscaled window: the same smoothing at every
        scale, so the templates differ by their scale only.

        Parameters
        ----------
        center, size : array_like
            The window, as in :meth:`sample`.
        template_size : tuple of int
            (Tw, Th).
        factors : array_like
            Scale factors of the window.
        angle : float, optional
            The window's turn, as in :meth:`sample`.

        Returns
        -------
        ndarray
            (len(factors), Th, Tw) templates.

        """
        tw, th = template_size
        level, linear, centre = self._geometry(center, size, template_size, angle)
        # (2, Th, Tw)
        grid = np.stack(np.meshgrid(np.arange(tw) - (tw - 1) / 2, np.arange(th) - (th - 1) / 2))
        # image offset of each template pixel at scale 1
        offsets = np.einsum('ij,jhw->ihw', linear, grid)
        factors = np.asarray(factors, dtype=np.float64)
        maps = centre[:, None, None, None] + factors[None, :, None, None] * offsets[:, None]
        maps = maps.reshape(2, -1, int(tw)).astype(np.float32)
        image, origin = self._crop(*maps) if self._crops(level) else (self.level(level), (0, 0))
        if origin != (0, 0):  # whole pixels off float32 coordinates: exact
            maps -= np.array(origin, dtype=np.float32)[:, None, None]
        out = cv2.remap(
            image, maps[0], maps[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        return out.reshape(len(factors), int(th), int(tw))

    def _geometry(self, center, size, template_size, angle: float):
        """
        Return where a window is sampled: (pyramid level, linear map, window centre there).

        The linear map takes template pixels to that level's pixels.
        """
        tw, th = template_size
        sx, sy = size[0] / tw, size[1] / th
        level = int(np.floor(np.log2(max(min(sx, sy), 1.0))))
        level = min(max(level, 0), self.n_levels - 1)
        f = 2.0**level
        # Image point of template pixel u: c + R(angle) ((u - (T-1)/2) * s); at level l
        # a full-resolution coordinate x sits at (x + 0.5) / 2^l - 0.5.
        linear = window_axes(angle) * [sx, sy] / f
        return level, linear, (np.asarray(center, dtype=np.float64) + 0.5) / f - 0.5


@dataclass(frozen=True)
class PatchLayout:
    """
    Local patches m x n with step s over a template (paper: 8x8 step 4 on 32x32).

    Parameters
    ----------
    template_size : tuple of int
        (Tw, Th).
    patch_size : tuple of int
        (m, n) = (width, height).
    step : int
        Stride between patches, template pixels.
    min_contrast : float, optional
        Grey-level standard deviation below which a patch counts as flat
        (docs/decisions.md#patch-normalization).

    Raises
    ------
    ValueError
        When the patches do not fit the template or the step is below 1.

    """

    template_size: tuple[int, int]  # (Tw, Th)
    patch_size: tuple[int, int]  # (m, n) = (width, height)
    step: int
    # grey-level std below which a patch counts as flat (docs/decisions.md#patch-normalization)
    min_contrast: float = 0.02

    def __post_init__(self):
        tw, th = self.template_size
        pw, ph = self.patch_size
        if pw > tw or ph > th or self.step < 1:
            raise ValueError(
                f'patches {self.patch_size} step {self.step} do not fit a template '
                f'{self.template_size}'
            )

    @property
    def cells(self) -> tuple[int, int]:
        """Return the number of patches per row and column of the template."""
        tw, th = self.template_size
        pw, ph = self.patch_size
        return (tw - pw) // self.step + 1, (th - ph) // self.step + 1

    def positions(self) -> np.ndarray:
        """
        Return the normalized centres of the window's patches.

        Returns
        -------
        ndarray
            (N, 2) centres, row-major like :meth:`extract`; read-only: one array shared by every
            model of the layout.

        """
        return self._positions

    @cached_property
    def _positions(self) -> np.ndarray:
        tw, th = self.template_size
        pw, ph = self.patch_size
        nx, ny = self.cells
        gi, gj = np.meshgrid(np.arange(nx), np.arange(ny))
        x = (gi * self.step + (pw - 1) / 2 - (tw - 1) / 2) / (tw / 2)
        y = (gj * self.step + (ph - 1) / 2 - (th - 1) / 2) / (th / 2)
        positions = np.column_stack([x.ravel(), y.ravel()]).astype(np.float64)
        positions.flags.writeable = False
        return positions

    def extract(self, template: np.ndarray) -> np.ndarray:
        """
        Appearance vectors epsilon of a template's patches (section 4).

        They are the paper's "normalized pixel values": each patch is brought to zero mean and unit
        norm, invariant to local brightness and contrast; a patch whose standard deviation is below
        ``min_contrast`` is scaled as if it had that contrast (a shorter vector), so flat patches
        do not amplify noise (docs/decisions.md#patch-normalization).

        Parameters
        ----------
        template : ndarray
            (Th, Tw) template.

        Returns
        -------
        ndarray
            (N, m*n) appearance vectors, row-major patches.

        Raises
        ------
        ValueError
            When the template's shape is not the layout's.

        """
        return self.extract_with_jacobian(template, jacobian=False)[0]

    def extract_with_jacobian(self, template: np.ndarray, jacobian: bool = True):
        """
        Appearance vectors epsilon and their derivative with respect to moving the window.

        The derivative is per template pixel of window motion (x, y): the patch pixels' grey-level
        gradients (central differences of the template) pushed through the normalization.

        Parameters
        ----------
        template : ndarray
            (Th, Tw) template.
        jacobian : bool, optional
            Compute the derivative (False: epsilon only).

        Returns
        -------
        eps : ndarray
            (N, d) appearance vectors, as :meth:`extract`.
        jac : ndarray or None
            (N, d, 2) derivative; None without ``jacobian``.

        Raises
        ------
        ValueError
            When the template's shape is not the layout's.

        """
        template = np.asarray(template, dtype=np.float64)
        if template.shape != self.template_size[::-1]:
            raise ValueError(
                f'template of shape {template.shape} does not match {self.template_size[::-1]}'
            )
        pw, ph = self.patch_size
        floor = self.min_contrast * np.sqrt(pw * ph)
        gx, gy = _gradient(template) if jacobian else (template, template)
        eps, jac = _unit_patches(
            template.ravel(), gx.ravel(), gy.ravel(), self._patch_index, floor, jacobian
        )
        return eps, (jac if jacobian else None)

    @cached_property
    def _patch_index(self) -> np.ndarray:
        """(N, m*n) flat template indices of each patch's pixels, row-major patches."""
        tw = self.template_size[0]
        pw, ph = self.patch_size
        nx, ny = self.cells
        corners = (
            np.arange(ny)[:, None] * self.step * tw + np.arange(nx)[None, :] * self.step
        ).ravel()
        offsets = (np.arange(ph)[:, None] * tw + np.arange(pw)[None, :]).ravel()
        return corners[:, None] + offsets[None, :]

    def _patches(self, image: np.ndarray) -> np.ndarray:
        return image.ravel()[self._patch_index]


@numba.njit(cache=True, nogil=True)
def _patch_mean(flat, pixels):
    total = 0.0
    for j in range(pixels.size):
        total += flat[pixels[j]]
    return total / pixels.size


@numba.njit(cache=True, nogil=True)
def _unit_patches(flat, gx, gy, index, floor, jacobian):
    """
    Patches of a flat template brought to zero mean and unit norm, and their Jacobian.

    eps = p / max(||p||, floor); above the floor d eps = (I - eps eps') dp / ||p||, below it dp /
    floor, with dp the zero-mean patch of the grey-level gradients; one pass per patch.
    """
    n, d = index.shape
    eps = np.empty((n, d))
    jac = np.zeros((n, d, 2)) if jacobian else np.zeros((0, d, 2))
    for i in range(n):
        mean = _patch_mean(flat, index[i])
        norm = 0.0
        for j in range(d):
            eps[i, j] = flat[index[i, j]] - mean
            norm += eps[i, j] * eps[i, j]
        norm = np.sqrt(norm)
        scale = max(norm, floor)
        for j in range(d):
            eps[i, j] /= scale
        if not jacobian:
            continue
        for k in range(2):
            g = gx if k == 0 else gy
            gmean = _patch_mean(g, index[i])
            dot = 0.0
            for j in range(d):
                jac[i, j, k] = g[index[i, j]] - gmean
                dot += eps[i, j] * jac[i, j, k]
            if norm > floor:
                for j in range(d):
                    jac[i, j, k] = (jac[i, j, k] - eps[i, j] * dot) / scale
            else:
                for j in range(d):
                    jac[i, j, k] /= scale
    return eps, jac


@numba.njit(cache=True, nogil=True)
def _gradient(image):
    """
    (d/dx, d/dy) of a 2-D image as ``np.gradient``.

    Central differences, one-sided at the borders.
    """
    h, w = image.shape
    gx = np.empty((h, w))
    gy = np.empty((h, w))
    for i in range(h):
        for j in range(w):
            if w == 1:
                gx[i, j] = 0.0
            elif j == 0:
                gx[i, j] = image[i, 1] - image[i, 0]
            elif j == w - 1:
                gx[i, j] = image[i, j] - image[i, j - 1]
            else:
                gx[i, j] = 0.5 * (image[i, j + 1] - image[i, j - 1])
            if h == 1:
                gy[i, j] = 0.0
            elif i == 0:
                gy[i, j] = image[1, j] - image[0, j]
            elif i == h - 1:
                gy[i, j] = image[i, j] - image[i - 1, j]
            else:
                gy[i, j] = 0.5 * (image[i + 1, j] - image[i - 1, j])
    return gx, gy
