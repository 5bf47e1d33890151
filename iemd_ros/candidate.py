"""The candidate model at one window position (eq. sparse candidate model).

Algorithm 1 builds a new candidate model each time the window moves: the
window at ``center`` is resampled to the template size and cut into the same
patch grid as the target, so candidate patch v and target patch u are aligned
whenever the window sits on the target (a fixed patch lattice that is not
re-sampled is misaligned between its grid points: on a pure 2.4 px
translation its EMD minimum sat 1.2 px short of the truth).

The gradient of eq. (10) is taken at the model's own position, treating its
patches as fixed while the kernel centre y moves (as in mean shift);
:meth:`CandidateModel.evaluate` therefore accepts small offsets y, which the
tests use to check the gradients against finite differences.
"""
from __future__ import annotations

import numba
import numpy as np

from .appearance import ImagePyramid, PatchLayout
from .emd import EmdSolution, appearance_distance, emd_gradient, envelope_gradient, solve_emd
from .histogram import candidate_weights
from .sparse_coding import SparseCoder, max_alignment_pooling


class CandidateModel:
    """Patches, sparse codes and pooled weights of the window at ``center`` with ``size``."""

    def __init__(self, pyramid: ImagePyramid, layout: PatchLayout, center, size, coder: SparseCoder | None,
                 n_templates: int, target_eps: np.ndarray, alpha: float, coarse: int = 0,
                 angle: float = 0.0):
        """``coder=None`` (the coarse stage) gives every patch code weight 1: only the kernel weights bins.

        ``angle``: the window's orientation in the image (see ImagePyramid.sample);
        positions and gradients are in the window's own axes.
        """
        self.center = np.asarray(center, dtype=np.float64)
        self.size = np.asarray(size, dtype=np.float64)
        self.alpha = alpha
        template = pyramid.sample(self.center, self.size, layout.template_size, coarse, angle)
        self.eps, jac = layout.extract_with_jacobian(template)
        # d epsilon / d (window centre moved along its axes, image pixels): template pixels per image pixel.
        self.eps_jacobian = jac * (np.asarray(layout.template_size, dtype=np.float64) / self.size)
        self.pos = layout.positions()
        if coder is None:
            self.code_weights = np.ones(len(self.eps))
        else:
            self.code_weights = max_alignment_pooling(coder.encode(self.eps.T), n_templates)
        self.appearance_cost = alpha * appearance_distance(target_eps, self.eps)

    def evaluate(self, y, bandwidth: float, target_pos, target_eps, target_weights, gradient: str):
        """EMD between the target and the kernel centred at offset ``y`` (normalized), and dEMD/dy.

        Returns (emd, gradient (2,) per normalized unit, EmdSolution or None when
        no bin has weight).  ``gradient``:
        - "paper": eq. (10), the duals times dw_C/dy (patches fixed, kernel moves);
        - "envelope": the same model with the spatial ground distance moving too,
          sum_uv f_uv dd_uv/dy + sum_v v_v dw_C,v/dy;
        - "appearance": the derivative of the re-sampled model that Algorithm 1
          evaluates (only at y = 0): when the window moves its patches are
          re-sampled, so d_uv changes through epsilon_v(y); with the flow fixed
          (envelope theorem) dD*/dy = -2 alpha sum_v (sum_u f_uv eps_u - w_v eps_v)
          . d eps_v/dy.  The pooled code weights also move with the content; that
          term is left out (they change slowly and have no closed-form derivative).
        """
        y = np.asarray(y, dtype=np.float64)
        w_c, dw_dy = candidate_weights(self.code_weights, self.pos, y, 1.0, bandwidth)
        keep = np.flatnonzero(w_c > 0)
        if keep.size == 0:
            return np.inf, np.zeros(2), None
        cost = _transport_cost(self.appearance_cost, keep, np.asarray(target_pos, dtype=np.float64), self.pos, y,
                               1.0 - self.alpha)
        solution: EmdSolution = solve_emd(target_weights, w_c[keep], cost, check=False)
        if gradient == "paper":
            grad = emd_gradient(solution, dw_dy[keep])
        elif gradient == "envelope":
            diff = target_pos[:, None, :] - (self.pos[keep] - y)[None, :, :]
            grad = envelope_gradient(solution, dw_dy[keep], 2.0 * (1.0 - self.alpha) * diff)
        elif gradient == "appearance":
            if np.any(y != 0):
                raise ValueError("the appearance gradient is defined at the model's own position (y = 0)")
            flow = solution.flow
            grad_px = -2.0 * self.alpha * _appearance_contraction(flow.T @ target_eps, flow.sum(0), keep, self.eps,
                                                                  self.eps_jacobian)
            grad = grad_px * self.size / 2.0  # per normalized unit, like the other two
        else:
            raise ValueError(f"unknown gradient {gradient!r}")
        return solution.value, grad, solution


@numba.njit(cache=True)
def _transport_cost(appearance_cost, keep, target_pos, pos, y, spatial_weight):
    """d_uv over the kept candidate bins: appearance part + spatial_weight ||c_u - (c_v - y)||^2."""
    n_t, n_c = appearance_cost.shape[0], keep.size
    cost = np.empty((n_t, n_c))
    for j in range(n_c):
        vx, vy = pos[keep[j], 0] - y[0], pos[keep[j], 1] - y[1]
        for u in range(n_t):
            dx, dy = target_pos[u, 0] - vx, target_pos[u, 1] - vy
            cost[u, j] = appearance_cost[u, keep[j]] + spatial_weight * (dx * dx + dy * dy)
    return cost


@numba.njit(cache=True)
def _appearance_contraction(transported, received, keep, eps, eps_jacobian):
    """sum_v (sum_u f_uv eps_u - w_v eps_v) . d eps_v/dy over the kept bins v.

    ``transported`` = F' eps_T (rows: kept bins), ``received`` = F' 1.
    """
    out = np.zeros(2)
    for j in range(keep.size):
        v = keep[j]
        for d in range(eps.shape[1]):
            r = transported[j, d] - received[j] * eps[v, d]
            out[0] += r * eps_jacobian[v, d, 0]
            out[1] += r * eps_jacobian[v, d, 1]
    return out
