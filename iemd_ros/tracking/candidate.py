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
The candidate model at one window position (eq. sparse candidate model).

Algorithm 1 builds a new candidate model each time the window moves: the
window at ``center`` is resampled to the template size and cut into the same
patch grid as the target, so candidate patch v and target patch u are aligned
whenever the window sits on the target (a fixed patch lattice that is not
re-sampled is misaligned between its grid points).

Everything but the window is fixed for one search on one frame: it is held
in a :class:`SearchContext`, and a candidate model is ``CandidateModel(context,
center, size)``.

The gradient of eq. (10) is taken at the model's own position, treating its
patches as fixed while the kernel centre y moves (as in mean shift);
:meth:`CandidateModel.evaluate` therefore accepts small offsets y, which the
tests use to check the gradients against finite differences.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

from iemd_ros.tracking.appearance import ImagePyramid, PatchLayout
from iemd_ros.tracking.emd import appearance_distance, emd_gradient, EmdSolution, solve_emd
from iemd_ros.tracking.histogram import candidate_weights, target_weights
from iemd_ros.tracking.template import TemplateDictionary
import numba
import numpy as np


@dataclass(frozen=True)
class TargetModel:
    """
    The target histogram of eq. (sparse target model): the bins that carry mass.

    Bins outside the kernel (the window's corners) are dropped: they change neither the optimal
    flow nor the candidate duals, and dropping them once saves the solver's filtering on every
    solve.

    Parameters
    ----------
    pos : ndarray
        (N_T, 2) normalized patch centres.
    eps : ndarray
        (N_T, d) appearance vectors.
    weights : ndarray
        (N_T,) weights w_T, summing to 1.

    """

    pos: np.ndarray
    eps: np.ndarray
    weights: np.ndarray

    @classmethod
    def from_patches(cls, pos, eps, code_weights, bandwidth: float) -> 'TargetModel':
        """
        Return the target model of a window's patches, without the bins outside the kernel.

        Parameters
        ----------
        pos : array_like
            (N, 2) normalized patch centres.
        eps : array_like
            (N, d) appearance vectors.
        code_weights : ndarray
            (N,) pooled code weights of the patches.
        bandwidth : float
            The kernel's h.

        Returns
        -------
        TargetModel
            The bins of non-zero weight w_T (:func:`~iemd_ros.tracking.histogram.target_weights`).

        Raises
        ------
        ValueError
            When no patch with a non-zero code is inside the kernel.

        """
        weights = target_weights(code_weights, pos, bandwidth)
        keep = np.flatnonzero(weights > 0)
        return cls(
            pos=np.asarray(pos, dtype=np.float64)[keep],
            eps=np.asarray(eps, dtype=np.float64)[keep],
            weights=weights[keep],
        )

    @cached_property
    def eps_sq_norms(self) -> np.ndarray:
        """||eps_u||^2 per bin, for the appearance distance of every candidate."""
        return (self.eps**2).sum(1)


@dataclass(frozen=True, eq=False)
class SearchContext:
    """
    What the candidate windows of one search on one frame are sampled from and compared against.

    Parameters
    ----------
    pyramid : ImagePyramid
        The frame the windows are resampled from, turned by ``angle`` (see
        :meth:`ImagePyramid.sample`).
    layout : PatchLayout
        Cuts the windows into patches.
    target : TargetModel
        The target histogram the windows are compared against.
    dictionary : TemplateDictionary or None
        Codes the patches (:meth:`TemplateDictionary.code_weights`); None gives every patch code
        weight 1, so that only the kernel weights bins.
    alpha : float
        Weight of appearance against space in the ground distance.
    bandwidth : float
        The kernel's h.
    angle : float, optional
        Orientation of the windows in the image, radians; positions and gradients are in the
        window's own axes.

    """

    pyramid: ImagePyramid
    layout: PatchLayout
    target: TargetModel
    dictionary: TemplateDictionary | None
    alpha: float
    bandwidth: float
    angle: float = 0.0


class CandidateModel:
    """
    Patches, sparse codes and pooled weights of one window in a search context.

    Parameters
    ----------
    context : SearchContext
        Frame, target, dictionary and orientation of the search.
    center : array_like
        (x, y) window centre, image pixels.
    size : array_like
        (w, h) window size, image pixels.

    """

    def __init__(self, context: SearchContext, center, size):
        self.context = context
        self.center = np.asarray(center, dtype=np.float64)
        self.size = np.asarray(size, dtype=np.float64)
        layout, target, dictionary = context.layout, context.target, context.dictionary
        self.template = context.pyramid.sample(
            self.center, self.size, layout.template_size, context.angle
        )
        self.eps = layout.extract(self.template)
        self.pos = layout.positions()
        self.code_weights = (
            np.ones(len(self.eps)) if dictionary is None else dictionary.code_weights(self.eps)
        )
        self.appearance_cost = context.alpha * appearance_distance(
            target.eps, self.eps, target.eps_sq_norms
        )
        self._solved = None  # (y, kept bins, dw_C/dy of them, EmdSolution) of the last emd()

    @property
    def angle(self) -> float:
        """Return the window's orientation in the image (radians)."""
        return self.context.angle

    def at(self, center, size=None) -> 'CandidateModel':
        """
        Return the model at another window in the same context.

        The context is the frame, target, dictionary and orientation.  Algorithm 1's next iterate,
        or a scale variant when ``size`` is given.

        Parameters
        ----------
        center : array_like
            (x, y) window centre, image pixels.
        size : array_like, optional
            (w, h) window size (default: this model's).

        Returns
        -------
        CandidateModel
            The model at the new window.

        """
        return CandidateModel(self.context, center, self.size if size is None else size)

    @cached_property
    def patch_jacobian(self) -> np.ndarray:
        """
        Return d epsilon / d(window shift along its axes), per template pixel, (N, d, 2).

        Computed on first use: the descent needs it only where a step is accepted (rejected trials
        and scale variants need only the EMD).
        """
        return self.context.layout.extract_with_jacobian(self.template)[1]

    def evaluate(self, gradient: str, y=(0.0, 0.0)):
        """
        EMD between the target and the kernel centred at offset ``y``, and dEMD/dy.

        :meth:`emd` then :meth:`gradient`.

        Parameters
        ----------
        gradient : {"paper", "appearance"}
            Kind of gradient, as :meth:`gradient` takes it.
        y : array_like, optional
            (2,) kernel offset, normalized window units.

        Returns
        -------
        emd : float
            The EMD; inf when no bin has weight.
        gradient : ndarray
            (2,) dEMD/dy per normalized unit; zeros when no bin has weight.
        solution : EmdSolution or None
            The solved transport; None when no bin has weight.

        Raises
        ------
        ValueError
            For an unknown ``gradient``, or the appearance gradient away from y = 0.

        """
        value, solution = self.emd(y)
        if solution is None:
            return value, np.zeros(2), None
        return value, self.gradient(gradient), solution

    def emd(self, y=(0.0, 0.0)):
        """
        EMD between the target and the kernel centred at offset ``y``.

        The solution is kept for :meth:`gradient` (and reused at the same ``y``).

        Parameters
        ----------
        y : array_like, optional
            (2,) kernel offset, normalized window units.

        Returns
        -------
        value : float
            The EMD; inf when no bin has weight.
        solution : EmdSolution or None
            The solved transport; None when no bin has weight.

        """
        y = np.asarray(y, dtype=np.float64)
        if self._solved is not None and np.array_equal(self._solved[0], y):
            return self._solved[3].value, self._solved[3]
        w_c, dw_dy = candidate_weights(self.code_weights, self.pos, y, self.context.bandwidth)
        keep = np.flatnonzero(w_c > 0)
        if keep.size == 0:
            self._solved = None
            return np.inf, None
        cost = _transport_cost(
            self.appearance_cost,
            keep,
            self.context.target.pos,
            self.pos,
            y,
            1.0 - self.context.alpha,
        )
        solution: EmdSolution = solve_emd(
            self.context.target.weights, w_c[keep], cost, check=False
        )
        self._solved = (y, keep, dw_dy[keep], solution)
        return solution.value, solution

    def gradient(self, kind: str) -> np.ndarray:
        """
        dEMD/dy at the last :meth:`emd`'s offset.

        Parameters
        ----------
        kind : {"paper", "appearance"}
            - "paper": eq. (10), the duals times dw_C/dy (patches fixed, kernel moves);
            - "appearance": the derivative of the re-sampled model that Algorithm 1 evaluates (only
              at y = 0): when the window moves its patches are re-sampled, so d_uv changes through
              epsilon_v(y); with the flow fixed (envelope theorem)
              dD*/dy = -2 alpha sum_v (sum_u f_uv eps_u - w_v eps_v) . d eps_v/dy.  The pooled
              code weights also move with the content; that term is left out (they change slowly
              and have no closed-form derivative).

        Returns
        -------
        ndarray
            (2,) gradient per normalized unit.

        Raises
        ------
        ValueError
            Before a solved :meth:`emd`, for the appearance gradient away from y = 0, or for an
            unknown ``kind``.

        """
        if self._solved is None:
            raise ValueError('gradient() needs a solved emd() first')
        y, keep, dw_dy, solution = self._solved
        if kind == 'paper':
            return emd_gradient(solution, dw_dy)
        if kind == 'appearance':
            if np.any(y != 0):
                raise ValueError(
                    "the appearance gradient is defined at the model's own position (y = 0)"
                )
            flow = solution.flow
            # Per image pixel along the window's axes the Jacobian scales by T / size, and per
            # normalized unit by size / 2: together
            # -2 alpha (T / 2) sum r . d eps / d(template px).
            contraction = _appearance_contraction(
                flow.T @ self.context.target.eps, flow.sum(0), keep, self.eps, self.patch_jacobian
            )
            return (
                -self.context.alpha
                * np.asarray(self.context.layout.template_size, dtype=np.float64)
                * contraction
            )
        raise ValueError(f'unknown gradient {kind!r}')


@numba.njit(cache=True, nogil=True)
def _transport_cost(appearance_cost, keep, target_pos, pos, y, spatial_weight):
    """
    d_uv over the kept candidate bins.

    d_uv = appearance part + spatial_weight ||c_u - (c_v - y)||^2.
    """
    n_t, n_c = appearance_cost.shape[0], keep.size
    cost = np.empty((n_t, n_c))
    for j in range(n_c):
        vx, vy = pos[keep[j], 0] - y[0], pos[keep[j], 1] - y[1]
        for u in range(n_t):
            dx, dy = target_pos[u, 0] - vx, target_pos[u, 1] - vy
            cost[u, j] = appearance_cost[u, keep[j]] + spatial_weight * (dx * dx + dy * dy)
    return cost


@numba.njit(cache=True, nogil=True)
def _appearance_contraction(transported, received, keep, eps, eps_jacobian):
    """
    sum_v (sum_u f_uv eps_u - w_v eps_v) . d eps_v/dy over the kept bins v.

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
