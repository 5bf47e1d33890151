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

"""Sparse codes (eq. lagrange), max-alignment pooling and the kernel weights (section 4)."""
from iemd_ros.tracking.histogram import candidate_weights, target_weights
from iemd_ros.tracking.sparse_coding import lasso_objective, max_alignment_pooling, SparseCoder
import numpy as np
import pytest


def patch_dictionary(seed=0, dim=64, n_atoms=147, n_signals=40):
    """Zero-mean unit-norm patches with the strong coherence of real template patches."""
    rng = np.random.default_rng(seed)
    base = rng.normal(size=(dim, n_atoms // 3))
    atoms = np.hstack([base + 0.3 * rng.normal(size=base.shape) for _ in range(3)])
    atoms -= atoms.mean(0)
    atoms /= np.linalg.norm(atoms, axis=0)
    signals = atoms[:, rng.integers(0, n_atoms, n_signals)] * rng.uniform(0.5, 1.5, n_signals)
    signals += 0.2 * rng.normal(size=signals.shape)
    return atoms, signals


def kkt_residual(atoms, signals, codes, lam):
    """
    Optimality of min ||e - Phi a||^2 + lam |a|_1, a >= 0.

    Gradient g = 2 Phi'(Phi a - e) + lam must vanish where a > 0 and be >= 0 where a = 0.
    """
    g = 2 * atoms.T @ (atoms @ codes - signals) + lam
    return np.where(codes > 0, np.abs(g), np.maximum(-g, 0)).max()


@pytest.mark.parametrize('lam', [0.01, 0.1, 0.5])
def test_codes_satisfy_kkt_conditions(lam):
    atoms, signals = patch_dictionary()
    codes = SparseCoder(atoms, lam).encode(signals)
    assert codes.min() >= 0
    assert kkt_residual(atoms, signals, codes, lam) < 1e-7
    assert 0 < (codes > 0).sum(0).mean() < 64  # sparse, not empty


def test_codes_are_optimal_against_perturbations():
    atoms, signals = patch_dictionary(seed=1)
    lam = 0.05
    codes = SparseCoder(atoms, lam).encode(signals)
    best = lasso_objective(atoms, signals, codes, lam)
    rng = np.random.default_rng(0)
    for _ in range(20):
        other = np.maximum(codes + 0.01 * rng.normal(size=codes.shape), 0)
        assert np.all(lasso_objective(atoms, signals, other, lam) >= best - 1e-12)


def test_duplicate_atoms_do_not_break_the_solver():
    atoms, signals = patch_dictionary(seed=4, n_atoms=30)
    doubled = np.hstack([atoms, atoms])  # e.g. two identical templates
    codes = SparseCoder(doubled, 0.05).encode(signals)
    assert np.all(np.isfinite(codes))
    assert kkt_residual(doubled, signals, codes, 0.05) < 1e-6


def test_max_alignment_pooling_by_hand():
    # 2 templates x 3 positions, 2 patches.
    codes = np.array([
        [0.1, 0.0],  # template 1, position 1
        [0.0, 0.3],  # template 1, position 2
        [0.2, 0.0],  # template 1, position 3
        [0.4, 0.1],  # template 2, position 1
        [0.0, 0.3],  # template 2, position 2
        [0.0, 0.0],  # template 2, position 3
    ])
    # a_bar = sum over templates per position: patch 1 -> (0.5, 0, 0.2), patch 2 -> (0.1, 0.6, 0)
    assert np.allclose(max_alignment_pooling(codes, 2), [0.5, 0.6])
    with pytest.raises(ValueError):
        max_alignment_pooling(codes, 4)


def test_target_weights_by_hand():
    """Epanechnikov profile 1 - ||c / h||^2 (zero outside) times |p|, normalized."""
    pos = np.array([[0.0, 0.0], [0.5, 0.0], [0.6, 0.8], [1.0, 1.0]])
    codes = np.array([2.0, 1.0, 5.0, -1.0])
    # h = 1: profile (1, 0.75, 0, 0)
    assert np.allclose(target_weights(codes, pos, 1.0), np.array([2.0, 0.75, 0.0, 0.0]) / 2.75)
    # h = 2: profile (1, 1 - 0.0625, 0.75, 0.5); |p| of the negative code
    expected = np.array([2.0, 0.9375, 3.75, 0.5])
    assert np.allclose(target_weights(codes, pos, 2.0), expected / expected.sum())
    with pytest.raises(ValueError, match='empty'):
        target_weights(np.zeros(4), pos, 1.0)
    with pytest.raises(ValueError, match='empty'):
        target_weights(np.array([0.0, 0.0, 1.0, 1.0]), pos, 1.0)  # codes only outside the kernel


def test_candidate_weights_jacobian_matches_finite_differences():
    rng = np.random.default_rng(5)
    pos = rng.uniform(-1.2, 1.2, (60, 2))
    q = rng.uniform(0, 1, 60)
    y = np.array([0.1, -0.05])
    w, dw = candidate_weights(q, pos, y, 1.02)
    assert w.sum() == pytest.approx(1.0)
    assert np.allclose(dw.sum(0), 0.0, atol=1e-12)  # normalization is differentiated too
    h = 1e-7
    for k, e in enumerate(np.eye(2)):
        fd = (
            candidate_weights(q, pos, y + h * e, 1.02)[0]
            - candidate_weights(q, pos, y - h * e, 1.02)[0]
        ) / (2 * h)
        assert np.allclose(dw[:, k], fd, atol=1e-6)
