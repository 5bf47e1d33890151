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
Non-negative sparse coding and max-alignment pooling (paper section 4).

Every local patch ``epsilon`` is coded against the dictionary ``Phi`` by the non-negative lasso of
eq. (lagrange)::

    min_a ||epsilon - Phi a||_2^2 + lambda ||a||_1   s.t.  a >= 0

solved exactly by an active set (Lawson-Hanson on the quadratic program
``a'Ga - 2(b - lambda/2)'a``, numba), so the KKT conditions hold to rounding; the Cholesky factor
of the active block is extended by a row per entering atom
(docs/decisions.md#sparse-coding-solver).
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _factor_append(chol, order, k, j, gram, ridge):
    """
    Extend the lower Cholesky factor of G[order[:k], order[:k]] + ridge I by atom j.

    Atom j becomes its row/column k.
    """
    d = gram[j, j] + ridge
    for r in range(k):
        v = gram[order[r], j]
        for p in range(r):
            v -= chol[r, p] * chol[k, p]
        v /= chol[r, r]
        chol[k, r] = v
        d -= v * v
    chol[k, k] = np.sqrt(max(d, 1e-12))


@numba.njit(cache=True, nogil=True)
def _factor_solve(chol, order, k, b, z):
    """Solve for z = (L L')^-1 b[order[:k]] (forward then back substitution)."""
    for i in range(k):
        v = b[order[i]]
        for p in range(i):
            v -= chol[i, p] * z[p]
        z[i] = v / chol[i, i]
    for i in range(k - 1, -1, -1):
        v = z[i]
        for p in range(i + 1, k):
            v -= chol[p, i] * z[p]
        z[i] = v / chol[i, i]


@numba.njit(cache=True, nogil=True)
def _active_set_lasso(gram, correlations, lam, tol, ridge):
    """
    Exact non-negative lasso for every column of ``correlations`` (= Phi' E).

    Lawson-Hanson active set on the quadratic program a'Ga - 2(b - lambda/2)'a, from an empty
    support.  The Cholesky factor of the active block is extended by one row when an atom enters
    (O(k^2)) and rebuilt only when the step toward the new solution drops atoms.  ``ridge`` (1e-10)
    keeps the active sub-system solvable when two atoms are identical (e.g. replicated border
    padding in two templates); it changes the KKT residual by ridge * |a|, far below any tolerance
    that matters.
    """
    n_atoms, n_signals = correlations.shape
    codes = np.zeros((n_atoms, n_signals))
    half_lam = 0.5 * lam
    active = np.zeros(n_atoms, dtype=np.bool_)
    order = np.empty(n_atoms, dtype=np.int64)
    chol = np.zeros((n_atoms, n_atoms))
    a = np.zeros(n_atoms)
    b = np.empty(n_atoms)
    w = np.empty(n_atoms)
    z = np.empty(n_atoms)
    for n in range(n_signals):
        for j in range(n_atoms):
            b[j] = correlations[j, n] - half_lam
            a[j] = 0.0
            active[j] = False
        k = 0
        for _ in range(3 * n_atoms):
            # w = b - G a (half the negative gradient), G symmetric: rows of the support
            for j in range(n_atoms):
                w[j] = b[j]
            for r in range(k):
                row = order[r]
                ar = a[row]
                for j in range(n_atoms):
                    w[j] -= gram[row, j] * ar
            j_best = -1
            w_best = tol
            for j in range(n_atoms):
                if not active[j] and w[j] > w_best:
                    w_best = w[j]
                    j_best = j
            if j_best < 0:  # KKT holds: no atom outside the support would lower the objective
                break
            _factor_append(chol, order, k, j_best, gram, ridge)
            order[k] = j_best
            active[j_best] = True
            k += 1
            while True:
                _factor_solve(chol, order, k, b, z)
                feasible = True
                for r in range(k):
                    if z[r] <= 0.0:
                        feasible = False
                if feasible:
                    for r in range(k):
                        a[order[r]] = z[r]
                    break
                # Step from a toward z until the first coefficient hits zero; drop those and
                # refactor.
                alpha = 1.0
                for r in range(k):
                    if z[r] <= 0.0:
                        ratio = a[order[r]] / (a[order[r]] - z[r])
                        if ratio < alpha:
                            alpha = ratio
                kept = 0
                for r in range(k):
                    j = order[r]
                    a[j] += alpha * (z[r] - a[j])
                    if a[j] <= 1e-14:
                        a[j] = 0.0
                        active[j] = False
                    else:
                        order[kept] = j
                        kept += 1
                k = 0
                for r in range(kept):
                    _factor_append(chol, order, k, order[r], gram, ridge)
                    k += 1
        for j in range(n_atoms):
            codes[j, n] = a[j]
    return codes


class SparseCoder:
    """
    Codes patch vectors against a fixed dictionary by the non-negative lasso of eq. (lagrange).

    The Gram matrix is cached.

    Parameters
    ----------
    dictionary : ndarray
        (dim, n_atoms), one vectorized patch per column.
    lam : float
        The lambda of eq. (lagrange), > 0.
    tol : float, optional
        An atom outside the support enters while half the objective's negative gradient at it
        exceeds ``tol``.

    Raises
    ------
    ValueError
        For ``lam`` <= 0.

    """

    def __init__(self, dictionary: np.ndarray, lam: float, tol: float = 1e-10):
        if lam <= 0:
            raise ValueError(f'sparse coding lambda must be > 0, got {lam}')
        self.dictionary = np.ascontiguousarray(dictionary, dtype=np.float64)
        self.gram = self.dictionary.T @ self.dictionary
        self.lam = float(lam)
        self.tol = float(tol)

    def encode(self, signals: np.ndarray) -> np.ndarray:
        """
        Sparse codes of signals.

        Parameters
        ----------
        signals : ndarray
            (dim, n_signals), one signal per column.

        Returns
        -------
        ndarray
            (n_atoms, n_signals) non-negative codes: the exact lasso solutions (the KKT conditions
            hold to rounding).

        """
        correlations = np.ascontiguousarray(
            self.dictionary.T @ np.asarray(signals, dtype=np.float64)
        )
        return _active_set_lasso(self.gram, correlations, self.lam, self.tol, 1e-10)


def lasso_objective(dictionary, signals, codes, lam):
    """
    Per-signal value of eq. (lagrange), ||epsilon - Phi a||_2^2 + lambda ||a||_1.

    Parameters
    ----------
    dictionary : ndarray
        (dim, n_atoms) Phi.
    signals : ndarray
        (dim, n_signals) epsilon.
    codes : ndarray
        (n_atoms, n_signals) a.
    lam : float
        The lambda.

    Returns
    -------
    ndarray
        (n_signals,) objective values.

    """
    residual = signals - dictionary @ codes
    return (residual**2).sum(axis=0) + lam * np.abs(codes).sum(axis=0)


def max_alignment_pooling(codes: np.ndarray, n_templates: int) -> np.ndarray:
    """
    Bin weights ``||a_bar_r||_inf`` with ``a_bar_j = sum_i a_ij`` (section 4).

    Parameters
    ----------
    codes : ndarray
        (n_templates * n_positions, n_patches), atoms ordered template by template with the same
        patch positions in each, as the dictionary is built.
    n_templates : int
        Number of templates in the dictionary.

    Returns
    -------
    ndarray
        (n_patches,) non-negative weights, one per patch.

    Raises
    ------
    ValueError
        When the atoms are not ``n_templates`` templates of equal size.

    """
    n_atoms, n_patches = codes.shape
    if n_atoms % n_templates:
        raise ValueError(f'{n_atoms} atoms are not {n_templates} templates of equal size')
    pooled = codes.reshape(n_templates, n_atoms // n_templates, n_patches).sum(axis=0)
    return np.abs(pooled).max(axis=0)
