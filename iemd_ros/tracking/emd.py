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
Earth Mover's Distance between target and candidate histograms (section 3).

The transportation problem of eqs. (4)-(8) is solved with POT's network simplex (``ot.emd``'s
solver ``emd_c``), which returns the optimal flow and the dual potentials ``u`` (target bins) and
``v`` (candidate bins) of eq. (dual).  By strong duality ``D* = <u, w_T> + <v, w_C>``, so ``v`` is
the vector ``M`` of eq. (9) that expresses the EMD as a linear function of the candidate weights on
the optimal basis, and the paper's gradient eq. (10) is ``sum_v v_v dw_C,v/dy``.  Non-optimal
solver exits are reported in :class:`EmdSolution`, never hidden.  Both histograms are normalized
and all their mass is moved, as in the paper (docs/decisions.md#emd-solver).
"""
from __future__ import annotations

from dataclasses import dataclass
import importlib
import importlib.machinery
import importlib.util
import os
import sys
import types

import numpy as np


def _network_simplex():
    """
    Return POT's network simplex ``ot.lp.emd_wrap.emd_c`` without running ``ot/__init__.py``.

    The package's ``__init__`` imports all of POT (its datasets import scipy.stats, its Bregman
    solvers scipy.optimize, ``ot.utils`` scipy.spatial: most of a command's start); the tracker
    needs the one compiled solver.  The extension is imported under placeholder ``ot`` and
    ``ot.lp`` packages (POT's own folders) and a placeholder ``ot.utils`` whose ``dist`` (the one
    name the extension takes from it, for ``emd_1d_sorted``) calls POT's own on first use; then
    every ``ot`` module is taken out of ``sys.modules`` again, so that a later ``import ot`` runs
    POT's ``__init__`` as usual and finds the same extension.  With POT already imported, or when
    the placeholders fail, it is the plain import (docs/decisions.md#pot-import).

    Returns
    -------
    callable
        ``emd_c(a, b, M, max_iter, num_threads) -> (G, cost, u, v, result_code)``.

    """
    spec = None if 'ot' in sys.modules else importlib.util.find_spec('ot')
    if spec is not None and spec.submodule_search_locations:
        root, before = spec.submodule_search_locations[0], set(sys.modules)
        try:
            for name, path in (('ot', root), ('ot.lp', os.path.join(root, 'lp'))):
                placeholder = importlib.machinery.ModuleSpec(name, None, is_package=True)
                placeholder.submodule_search_locations = [path]
                sys.modules[name] = importlib.util.module_from_spec(placeholder)
            utils = sys.modules['ot.utils'] = types.ModuleType('ot.utils')
            utils.dist = _pot_dist
            return importlib.import_module('ot.lp.emd_wrap').emd_c
        except Exception:  # any failure: the plain import below says what is wrong
            pass
        finally:
            for name in set(sys.modules) - before:
                if name == 'ot' or name.startswith('ot.'):
                    del sys.modules[name]
    from ot.lp.emd_wrap import emd_c

    return emd_c


def _pot_dist(*args, **kwargs):
    """Call POT's ``ot.utils.dist``, imported on the first call."""
    from ot.utils import dist

    return dist(*args, **kwargs)


# POT's network simplex without the backend dispatch of ``ot.emd`` around it
# (docs/decisions.md#emd-solver)
emd_c = _network_simplex()

_RESULT_MESSAGES = {0: 'infeasible', 1: 'optimal', 2: 'unbounded',
                    3: 'max_iter reached before optimality'}


@dataclass
class EmdSolution:
    """
    Result of :func:`solve_emd`: the optimal transport and its duals.

    Parameters
    ----------
    value : float
        D*, eq. (4).
    flow : ndarray
        The flow f_uv, (N_T, N_C).
    u : ndarray
        Dual potentials of the target constraints, eq. (6).
    v : ndarray
        Dual potentials of the candidate constraints, eq. (5).
    optimal : bool
        Whether the solver ended optimal.
    message : str
        The solver's exit in words ("optimal", "infeasible", "unbounded", "max_iter reached before
        optimality", or the result code).

    """

    value: float  # D*, eq. (4)
    flow: np.ndarray  # f_uv, (N_T, N_C)
    u: np.ndarray  # dual potentials of the target constraints, eq. (6)
    v: np.ndarray  # dual potentials of the candidate constraints, eq. (5)
    optimal: bool
    message: str


def ground_distance(eps_t, pos_t, eps_c, pos_c, alpha: float) -> np.ndarray:
    """
    Ground distance d_uv = alpha ||eps_u - eps_v||^2 + (1 - alpha) ||c_u - c_v||^2.

    The paper's eq. (ground distance).

    Parameters
    ----------
    eps_t : ndarray
        (N_T, d) appearance vectors of the target bins.
    pos_t : ndarray
        (N_T, 2) positions of the target bins.
    eps_c : ndarray
        (N_C, d) appearance vectors of the candidate bins.
    pos_c : ndarray
        (N_C, 2) positions of the candidate bins.
    alpha : float
        Weight of appearance against space.

    Returns
    -------
    ndarray
        (N_T, N_C) distances.

    """
    return alpha * appearance_distance(eps_t, eps_c) + (1.0 - alpha) * spatial_distance(
        pos_t, pos_c
    )


def appearance_distance(eps_t, eps_c, sq_norms_t=None) -> np.ndarray:
    """
    Squared appearance distances ||eps_u - eps_v||^2 for all pairs.

    The pairs are rows of ``eps_t`` x rows of ``eps_c``.

    Parameters
    ----------
    eps_t : ndarray
        (N_T, d) rows u.
    eps_c : ndarray
        (N_C, d) rows v.
    sq_norms_t : ndarray, optional
        The rows' squared norms of ``eps_t`` if already known (the target's, per candidate).

    Returns
    -------
    ndarray
        (N_T, N_C) squared distances (negative rounding clipped to 0).

    """
    if sq_norms_t is None:
        sq_norms_t = (eps_t**2).sum(1)
    sq = sq_norms_t[:, None] + (eps_c**2).sum(1)[None, :] - 2.0 * eps_t @ eps_c.T
    return np.maximum(sq, 0.0)


def spatial_distance(pos_t, pos_c) -> np.ndarray:
    """
    Squared distances ||c_u - c_v||^2 for all pairs of positions.

    Parameters
    ----------
    pos_t, pos_c : ndarray
        (N_T, 2) and (N_C, 2) positions.

    Returns
    -------
    ndarray
        (N_T, N_C) squared distances.

    """
    diff = pos_t[:, None, :] - pos_c[None, :, :]
    return (diff**2).sum(-1)


def solve_emd(
    w_t: np.ndarray, w_c: np.ndarray, cost: np.ndarray, max_iter: int = 100000, check: bool = True
) -> EmdSolution:
    """
    Optimal transport of the normalized weights ``w_t`` onto ``w_c`` under ``cost``.

    Parameters
    ----------
    w_t : ndarray
        (N_T,) target weights.
    w_c : ndarray
        (N_C,) candidate weights, of the same total.
    cost : ndarray
        (N_T, N_C) ground distances.
    max_iter : int, optional
        Most iterations of the network simplex.
    check : bool, optional
        Check the inputs and repair the duals of zero-weight bins; False skips both, for callers
        that build valid inputs with positive weights only, like the candidate model.

    Returns
    -------
    EmdSolution
        The flow, its value and the duals; a non-optimal solver exit is reported in it.

    Raises
    ------
    ValueError
        With ``check``, for weights that are negative, not finite or of different totals, or a cost
        matrix that does not match them or is not finite.

    """
    w_t = np.asarray(w_t, dtype=np.float64)
    w_c = np.asarray(w_c, dtype=np.float64)
    if check:
        _check_problem(w_t, w_c, cost)
    flow, value, u, v, code = emd_c(
        w_t, w_c, np.ascontiguousarray(cost, dtype=np.float64), max_iter, 1
    )
    # The network simplex drops zero-weight bins and leaves their duals arbitrary;
    # the tightest feasible ones keep every reduced cost d_uv - u_u - v_v >= 0.
    # (Unchecked callers pass positive weights only.)
    if check and np.any(w_t == 0) and np.any(w_c > 0):
        u = np.where(w_t > 0, u, (cost[:, w_c > 0] - v[w_c > 0]).min(axis=1))
    if check and np.any(w_c == 0) and np.any(w_t > 0):
        v = np.where(w_c > 0, v, (cost[w_t > 0] - u[w_t > 0, None]).min(axis=0))
    return EmdSolution(
        value=float(value),
        flow=flow,
        u=u,
        v=v,
        optimal=code == 1,
        message=_RESULT_MESSAGES.get(int(code), f'solver result code {code}'),
    )


def _check_problem(w_t: np.ndarray, w_c: np.ndarray, cost: np.ndarray) -> None:
    if cost.shape != (w_t.size, w_c.size):
        raise ValueError(
            f'cost matrix {cost.shape} does not match weights {w_t.size} x {w_c.size}'
        )
    if not (np.all(np.isfinite(w_t)) and np.all(np.isfinite(w_c)) and np.all(np.isfinite(cost))):
        raise ValueError('EMD weights and costs must be finite')
    if w_t.min() < 0 or w_c.min() < 0:
        raise ValueError('EMD weights must be non-negative')
    if abs(w_t.sum() - w_c.sum()) > 1e-9 * max(1.0, w_t.sum()):
        raise ValueError(f'EMD needs equal total weights, got {w_t.sum()} and {w_c.sum()}')


def emd_gradient(solution: EmdSolution, dw_c_dy: np.ndarray) -> np.ndarray:
    """
    Return the paper's eq. (10): dD*/dy = sum_v v_v dw_C,v/dy.

    Parameters
    ----------
    solution : EmdSolution
        The solved EMD; its candidate duals v are the vector M of eq. (9).
    dw_c_dy : ndarray
        (N_C, 2) derivative of the candidate weights.

    Returns
    -------
    ndarray
        (2,) gradient.

    """
    return solution.v @ dw_c_dy
