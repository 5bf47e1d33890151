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

"""EMD (section 3): optimal value, duals, and the two gradients with respect to y."""
from iemd_ros.tracking.emd import appearance_distance, ground_distance, solve_emd, spatial_distance
import numpy as np
import pytest
from scipy.optimize import linprog


def linprog_emd(w_t, w_c, cost):
    """Return reference: the transportation problem of eqs. (4)-(8) with HiGHS."""
    n_t, n_c = cost.shape
    a_eq = np.zeros((n_t + n_c, n_t * n_c))
    for u in range(n_t):
        a_eq[u, u * n_c:(u + 1) * n_c] = 1.0
    for v in range(n_c):
        a_eq[n_t + v, v::n_c] = 1.0
    res = linprog(
        cost.ravel(), A_eq=a_eq, b_eq=np.concatenate([w_t, w_c]), bounds=(0, None), method='highs'
    )
    assert res.status == 0
    return res.fun


def random_problem(rng, n_t, n_c, dim=16):
    eps_t = rng.normal(size=(n_t, dim))
    eps_c = rng.normal(size=(n_c, dim))
    eps_t /= np.linalg.norm(eps_t, axis=1, keepdims=True)
    eps_c /= np.linalg.norm(eps_c, axis=1, keepdims=True)
    pos_t = rng.uniform(-1, 1, (n_t, 2))
    pos_c = rng.uniform(-1, 1, (n_c, 2))
    w_t = rng.uniform(0.1, 1, n_t)
    w_c = rng.uniform(0.1, 1, n_c)
    return w_t / w_t.sum(), w_c / w_c.sum(), ground_distance(eps_t, pos_t, eps_c, pos_c, 0.4)


@pytest.mark.parametrize('n_t,n_c', [(9, 9), (49, 49), (49, 81), (30, 12)])
def test_emd_equals_linprog_optimum(n_t, n_c):
    rng = np.random.default_rng(n_t * 100 + n_c)
    w_t, w_c, cost = random_problem(rng, n_t, n_c)
    sol = solve_emd(w_t, w_c, cost)
    assert sol.optimal
    assert sol.value == pytest.approx(linprog_emd(w_t, w_c, cost), rel=1e-9, abs=1e-12)
    # The flow is feasible (eqs. 5-8) and its cost is the value.
    assert np.allclose(sol.flow.sum(1), w_t) and np.allclose(sol.flow.sum(0), w_c)
    assert sol.flow.min() >= -1e-15
    assert (sol.flow * cost).sum() == pytest.approx(sol.value, rel=1e-12)


def test_strong_duality_and_dual_feasibility():
    rng = np.random.default_rng(1)
    w_t, w_c, cost = random_problem(rng, 49, 49)
    sol = solve_emd(w_t, w_c, cost)
    assert sol.u @ w_t + sol.v @ w_c == pytest.approx(sol.value, rel=1e-10)
    # Dual constraint H' pi <= d of eq. (8), with equality on the used flows.
    reduced = cost - sol.u[:, None] - sol.v[None, :]
    assert reduced.min() > -1e-10
    assert np.abs(reduced[sol.flow > 1e-12]).max() < 1e-10


def test_duals_are_the_derivative_of_emd_wrt_candidate_weights():
    """Eq. (9): on the optimal basis D* is linear in w_C with slope v (mass-preserving moves)."""
    rng = np.random.default_rng(2)
    w_t, w_c, cost = random_problem(rng, 25, 25)
    sol = solve_emd(w_t, w_c, cost)
    for _ in range(5):
        direction = rng.normal(size=w_c.size)
        direction -= direction.mean()  # keep the total mass
        h = 1e-7
        d_plus = solve_emd(w_t, w_c + h * direction, cost).value
        d_minus = solve_emd(w_t, w_c - h * direction, cost).value
        assert (d_plus - d_minus) / (2 * h) == pytest.approx(sol.v @ direction, rel=1e-5, abs=1e-9)


def test_non_optimal_exit_is_reported_not_hidden():
    rng = np.random.default_rng(3)
    w_t, w_c, cost = random_problem(rng, 60, 60)
    sol = solve_emd(w_t, w_c, cost, max_iter=5)
    assert not sol.optimal
    assert 'iteration' in sol.message.lower() or sol.message != 'optimal'


def test_invalid_weights_are_rejected():
    cost = np.ones((2, 2))
    with pytest.raises(ValueError, match='equal total'):
        solve_emd(np.array([0.5, 0.5]), np.array([0.5, 0.6]), cost)
    with pytest.raises(ValueError, match='non-negative'):
        solve_emd(np.array([1.5, -0.5]), np.array([0.5, 0.5]), cost)
    with pytest.raises(ValueError, match='finite'):
        solve_emd(np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([[0, np.nan], [1, 1]]))
    with pytest.raises(ValueError, match='does not match'):
        solve_emd(np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.ones((3, 2)))


def test_ground_distance_terms_by_hand():
    eps_t = np.array([[1.0, 0.0]])
    eps_c = np.array([[0.0, 1.0], [1.0, 0.0]])
    pos_t = np.array([[0.0, 0.0]])
    pos_c = np.array([[0.5, 0.0], [0.0, -1.0]])
    assert np.allclose(appearance_distance(eps_t, eps_c), [[2.0, 0.0]])
    assert np.allclose(spatial_distance(pos_t, pos_c), [[0.25, 1.0]])
    assert np.allclose(
        ground_distance(eps_t, pos_t, eps_c, pos_c, 0.3), [[0.3 * 2 + 0.7 * 0.25, 0.7 * 1.0]]
    )


def test_duals_of_zero_weight_bins_stay_dual_feasible():
    """
    The network simplex leaves the duals of empty bins arbitrary.

    solve_emd gives them the tightest feasible values, so every reduced cost d_uv - u_u - v_v stays
    >= 0 (eq. 8's dual).
    """
    rng = np.random.default_rng(7)
    w_t, w_c, cost = random_problem(rng, 12, 15)
    w_t[[2, 7]], w_c[[0, 5, 9]] = 0.0, 0.0
    w_t, w_c = w_t / w_t.sum(), w_c / w_c.sum()
    sol = solve_emd(w_t, w_c, cost)
    assert sol.optimal
    reduced = cost - sol.u[:, None] - sol.v[None, :]
    assert reduced.min() > -1e-10
    # tightest: one reduced cost is 0
    assert np.isclose(reduced[[2, 7]].min(axis=1), 0.0, atol=1e-12).all()
    assert np.isclose(reduced[:, [0, 5, 9]].min(axis=0), 0.0, atol=1e-12).all()


def test_the_solver_loads_without_pot_s_package_and_pot_still_imports_whole():
    """
    ``iemd_ros.tracking.emd`` loads POT's compiled solver without ``ot/__init__.py``.

    In a fresh interpreter: no ``ot`` module and no scipy.stats (POT's datasets) after the import;
    then ``import ot`` gives the whole of POT, with the same solver, and ``emd_1d_sorted``'s
    metric through ``ot.utils.dist`` (the name the placeholder forwards) works.
    """
    import subprocess
    import sys

    code = '\n'.join([
        'import sys',
        'import numpy as np',
        'from iemd_ros.tracking import emd',
        "print(sorted(m for m in sys.modules if m == 'ot' or m.startswith('ot.')))",
        "print('scipy.stats' in sys.modules)",
        'import ot',
        'a = np.array([0.2, 0.3, 0.5]); b = np.array([0.5, 0.25, 0.25])',
        'M = np.array([[0.0, 1.0, 2.0], [1.0, 0.0, 1.0], [2.0, 1.0, 0.0]])',
        'same = abs(ot.emd2(a, b, M) - emd.solve_emd(a, b, M).value) < 1e-12',
        'print(ot.lp.emd_wrap.emd_c is emd.emd_c, same)',
        'x = np.array([0.0, 1.0]); y = np.array([0.5, 2.0]); w = np.array([0.5, 0.5])',
        "print(ot.lp.emd_wrap.emd_1d_sorted(w, w, x, y, metric='cityblock')[2])",
    ])
    out = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, check=True, timeout=120
    ).stdout.split('\n')
    assert out[:4] == ['[]', 'False', 'True True', '0.75']
