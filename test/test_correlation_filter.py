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
Features (fHOG, Colour Names) and the correlation filters' shared pieces, and STRCF's ADMM.

The features and shared pieces against hand-computed cases, and STRCF's ADMM against a direct
solve of its objective.
"""
from iemd_ros.tracking import features as F
from iemd_ros.tracking.correlation_filter import apce, gaussian_label, sample_region, SubCellPeak
from iemd_ros.tracking.translation_filter import TranslationFilter
import numpy as np
import pytest
import scipy.fft as sfft


def _grey3(a):
    return np.repeat(np.clip(a, 0, 255).astype(np.uint8)[:, :, None], 3, axis=2)


# -------------------------------------------------------------------------------- fHOG
def test_hog_of_a_ramp_by_hand():
    """
    I = 10 x: every gradient (10, 0), angle 0.

    An interior cell: R1[0] = 10 (16 px x 10 / 16), the other bins 0; E = 100, block norm
    1 / sqrt(4 * 100) = 1/20, normalized 0.5, clipped 0.2: signed bin 0 = 0.5 * 4 * 0.2, unsigned
    bin 0 the same, texture 0.2357 * 0.2, the rest 0.
    """
    img = np.tile(np.arange(24, dtype=np.float32) * 10, (24, 1))
    h = F.fhog(img)
    assert h.shape == (31, 6, 6)
    expect = np.zeros(31)
    expect[0] = expect[18] = 0.4
    expect[27:31] = 0.2357 * 0.2
    np.testing.assert_allclose(h[:, 2, 2], expect, atol=1e-5)


def test_hog_step_edges_fill_their_orientation_bins():
    n = 32
    img = np.zeros((n, n))
    # dark left, bright right: gradient +x, signed bin 0
    img[:, n // 2:] = 255
    cell = F.fhog(_grey3(img))[:, 4, 3]
    assert np.argmax(cell[:18]) == 0 and np.argmax(cell[18:27]) == 0
    assert cell[0] > 0.1 and cell[:18].sum() - cell[0] < 1e-6
    cell = F.fhog(_grey3(255 - img))[:, 4, 3]  # 180 deg: signed bin 9, unsigned still 0
    assert np.argmax(cell[:18]) == 9 and np.argmax(cell[18:27]) == 0


@pytest.mark.parametrize(
    'theta,signed,unsigned', [(40, 2, 2), (220, 11, 2), (100, 5, 5), (260, 13, 4), (347, 17, 8)]
)
def test_hog_gradient_direction_goes_to_the_nearest_bin(theta, signed, unsigned):
    """Bin k is centred on k x 20 deg (signed), on k x 20 deg mod 180 (unsigned)."""
    yy, xx = np.mgrid[0:24, 0:24].astype(np.float32)
    t = np.deg2rad(theta)
    c = F.fhog(5.0 * (xx * np.cos(t) + yy * np.sin(t)) + 128)[:, 2, 2]
    assert np.argmax(c[:18]) == signed and c[:18].sum() - c[signed] < 1e-6
    assert np.argmax(c[18:27]) == unsigned and c[18:27].sum() - c[18 + unsigned] < 1e-6


def test_hog_of_colour_takes_the_strongest_channel_and_a_flat_image_has_none():
    img = np.zeros((24, 24, 3), np.uint8)
    img[:, 12:, 2] = 200  # a red vertical step
    img[12:, :, 0] = 50  # a weaker blue horizontal step
    assert np.argmax(F.fhog(img)[:18, 2, 2]) == 0
    assert np.abs(F.fhog(np.full((16, 16), 77, np.float32))).max() == 0


def test_hog_of_uint8_is_the_hog_of_its_float_values_and_a_batch_of_each_patch():
    """The kernel reads uint8 patches without a float copy: the same maps, bit for bit."""
    rng = np.random.default_rng(1)
    col = rng.integers(0, 256, (4, 37, 45, 3), dtype=np.uint8)
    for patch in (col[0], col[1, :, :, 0]):
        np.testing.assert_array_equal(F.fhog(patch), F.fhog(patch.astype(np.float32)))
    batch = F.fhog_batch(col)
    assert batch.shape == (4, 31, 9, 11)
    for k in range(4):
        np.testing.assert_array_equal(batch[k], F.fhog(col[k].astype(np.float32)))


# -------------------------------------------------------------------------------- Colour Names
def test_colour_names_cells_are_the_table_rows_of_their_pixels():
    """
    Row of a BGR pixel b, g, r: r // 8 + 32 (g // 8) + 1024 (b // 8).

    A cell is the mean of its pixels' rows.
    """
    table = F.colour_names()
    assert table.shape == (32768, 10) and table.dtype == np.float32
    patch = np.zeros((8, 8, 3), np.uint8)
    # b=8, g=16, r=24: 3 + 2 * 32 + 1 * 1024 = 1091
    patch[:, :4] = (8, 16, 24)
    patch[:, 4:] = (0, 0, 255)  # pure red: 31
    x = F.extract(patch, colour=True)
    assert x.shape == (42, 2, 2)
    np.testing.assert_allclose(x[32:, 0, 0], table[1091], atol=1e-6)
    np.testing.assert_allclose(x[32:, 1, 1], table[31], atol=1e-6)
    np.testing.assert_allclose(
        x[0, 0, 0], (0.299 * 24 + 0.587 * 16 + 0.114 * 8) / 255 - 0.5, atol=1e-6
    )
    patch[0:2, 0:4] = (0, 0, 255)  # half of the cell red
    np.testing.assert_allclose(
        F.extract(patch, colour=True)[32:, 0, 0], 0.5 * table[1091] + 0.5 * table[31], atol=1e-6
    )


def test_grey_frames_have_grey_and_hog_only():
    rng = np.random.default_rng(0)
    col = rng.integers(0, 256, (40, 48, 3), dtype=np.uint8)
    x = F.extract(col, colour=True)
    assert x.shape == (42, 10, 12) and F.n_channels(True) == 42
    np.testing.assert_allclose(x[1:32], F.fhog(col), atol=1e-6)
    grey = np.repeat(col[:, :, :1], 3, axis=2)
    xg = F.extract(grey, colour=False)
    assert xg.shape == (32, 10, 12) and F.n_channels(False) == 32
    np.testing.assert_allclose(xg[1:], F.fhog(grey[:, :, 0]), atol=1e-6)


# -------------------------------------------------------------------------------- sampling, peak
def test_sample_region_crops_exactly_and_turns_by_the_angle():
    rng = np.random.default_rng(1)
    img = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    same = sample_region(img, (40, 30), (20, 10), (20, 10))
    # [round(cx) - w // 2, ... + w)
    np.testing.assert_array_equal(same, img[25:35, 30:50])
    half = sample_region(img, (40, 30), (40, 20), (20, 10))
    np.testing.assert_allclose(
        half, img[20:40, 20:60].reshape(10, 2, 20, 2, 3).mean(axis=(1, 3)), atol=1
    )
    # a turn by 90 deg: transposed
    quarter = sample_region(img, (40.0, 30.0), (21, 21), (21, 21), np.pi / 2)
    # sample[v, u] = img[20 + u, 50 - v]
    np.testing.assert_array_equal(quarter, img[20:41, 30:51].transpose(1, 0, 2)[::-1])


def test_the_sub_cell_peak_of_a_shifted_gaussian():
    rows, cols, dy0, dx0 = 20, 24, 3.3, -4.6
    yy, xx = np.mgrid[0:rows, 0:cols]
    d2 = ((yy - dy0 + rows / 2) % rows - rows / 2) ** 2 + (
        (xx - dx0 + cols / 2) % cols - cols / 2
    ) ** 2
    resp = np.exp(-0.5 * d2 / 4.0)
    dy, dx, _ = SubCellPeak(rows, cols)(resp, sfft.rfft2(resp))
    assert abs(dy - dy0) < 0.02 and abs(dx - dx0) < 0.02 and apce(resp) > 10


# -------------------------------------------------------------------------------- STRCF's solver
def _tiny(rows, cols, C, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((C, rows, cols))
    y = gaussian_label(rows, cols, 1.0).astype(np.float64)
    w2 = rng.uniform(0.0, 4.0, (rows, cols))
    w2[rows // 2 - 1:rows // 2 + 1, cols // 2 - 1:cols // 2 + 1] = 1e-6
    f_prev = rng.standard_normal((C, rows, cols)) * 0.1
    tf = TranslationFilter()
    tf.map_hw, tf.T, tf.reg_sq = (rows, cols), rows * cols, w2
    tf.yf_conj = np.conj(sfft.rfft2(y))
    return tf, x, y, w2, f_prev


def _correlation_matrix(x):
    """
    Return A, (T, C T), with (A f)(n) = sum_d sum_m f_d(m) x_d(m + n) (circular).

    A f is the response of f on x.
    """
    C, R, Cc = x.shape
    T = R * Cc
    A = np.zeros((T, C * T))
    for n in range(T):
        ny, nx = divmod(n, Cc)
        for d in range(C):
            A[n, d * T:(d + 1) * T] = np.roll(np.roll(x[d], -ny, axis=0), -nx, axis=1).ravel()
    return A


@pytest.mark.parametrize('rows,cols', [(6, 6), (5, 7)])
def test_admm_converges_to_the_direct_solve_of_strcf_objective(rows, cols):
    """
    The direct solve of STRCF's objective against ADMM run long at a fixed penalty.

    The objective argmin 1/(2T) ||sum_d x_d * f_d - y||^2 + 1/2 sum_d ||w f_d||^2
    + mu/2 sum_d ||f_d - f_prev||^2 is solved by the normal equations; and the response convention
    r = A f.
    """
    C, mu = 2, 0.7
    tf, x, y, w2, f_prev = _tiny(rows, cols, C)
    T = rows * cols
    A = _correlation_matrix(x)
    lhs = A.T @ A / T + np.diag(np.tile(w2.ravel(), C)) + mu * np.eye(C * T)
    f_direct = np.linalg.solve(lhs, A.T @ y.ravel() / T + mu * f_prev.ravel()).reshape(
        C, rows, cols
    )
    f_hat = tf._admm(
        sfft.rfft2(x), sfft.rfft2(f_prev), iterations=3000, gamma=(1.0, 1.0, 1.0), mu=mu
    )
    np.testing.assert_allclose(
        sfft.irfft2(f_hat, s=(rows, cols)), f_direct, atol=2e-4 * np.abs(f_direct).max()
    )
    r = sfft.irfft2(np.sum(np.conj(sfft.rfft2(f_direct)) * sfft.rfft2(x), axis=0), s=(rows, cols))
    np.testing.assert_allclose(r.ravel(), A @ f_direct.ravel(), atol=1e-9)


def test_the_first_f_step_is_the_per_frequency_solve():
    """
    One f-step from g = h = 0, mu = 0.

    It solves (x x^H + T gamma I) f = x conj(y) at every frequency (Sherman-Morrison).
    """
    rows, cols, C = 4, 6, 3
    tf, x, y, _, _ = _tiny(rows, cols, C)
    xf = sfft.rfft2(x)
    f_hat = tf._admm(xf, None, iterations=1, gamma=(2.0, 1.0, 2.0))
    yf = sfft.rfft2(y)
    for i in range(rows):
        for j in range(cols // 2 + 1):
            a = xf[:, i, j]
            ref = np.linalg.solve(
                np.outer(a, np.conj(a)) + rows * cols * 2.0 * np.eye(C), a * np.conj(yf[i, j])
            )
            np.testing.assert_allclose(f_hat[:, i, j], ref, rtol=1e-6, atol=1e-9)
