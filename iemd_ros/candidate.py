"""The candidate model of one frame: a lattice of local patches, coded once each.

Eq. (sparse candidate model) weights *fixed* patches c_r by a kernel centred at
the window position y, so moving y only changes kernel weights.  The lattice
continues the window's patch grid (same size and step, in template pixels of
the window size being searched) in every direction; a patch is sampled and
sparse-coded the first time the kernel reaches it and then reused for every
later position in the frame.  Positions are normalized to the anchor window
(the window at the start of the search), which spans [-1, 1]^2.
"""
from __future__ import annotations

import numpy as np

from .appearance import ImagePyramid, PatchLayout
from .emd import EmdSolution, appearance_distance, emd_gradient, envelope_gradient, solve_emd
from .histogram import candidate_weights
from .sparse_coding import SparseCoder, max_alignment_pooling


class CandidateLattice:
    """Patches of one frame around an anchor window, coded on demand."""

    def __init__(self, pyramid: ImagePyramid, layout: PatchLayout, anchor_center, size,
                 coder: SparseCoder, n_templates: int, target_eps: np.ndarray, alpha: float,
                 target_codes: np.ndarray):
        self.pyramid = pyramid
        self.layout = layout
        self.center = np.asarray(anchor_center, dtype=np.float64)
        self.size = np.asarray(size, dtype=np.float64)
        self.coder = coder
        self.n_templates = n_templates
        self.target_eps = target_eps
        self.alpha = alpha
        self.target_codes = target_codes  # warm starts: codes of the target patch at the same cell
        self._index: dict[tuple[int, int], int] = {}
        self.pos = np.zeros((0, 2))
        self.code_weights = np.zeros(0)
        self.appearance_cost = np.zeros((len(target_eps), 0))
        self.codings = 0  # patches sparse-coded so far

    def ensure(self, y: np.ndarray, radius: float) -> None:
        """Sample and code every lattice cell whose centre lies within ``radius`` of ``y``."""
        tw, th = self.layout.template_size
        pw, ph = self.layout.patch_size
        step = self.layout.step
        first = self.layout.cell_positions(0, 0)[0]
        dx, dy = 2.0 * step / tw, 2.0 * step / th
        i0, i1 = int(np.ceil((y[0] - radius - first[0]) / dx)), int(np.floor((y[0] + radius - first[0]) / dx))
        j0, j1 = int(np.ceil((y[1] - radius - first[1]) / dy)), int(np.floor((y[1] + radius - first[1]) / dy))
        gi, gj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        missing = [(i, j) for i, j in zip(gi.ravel(), gj.ravel()) if (i, j) not in self._index]
        if not missing:
            return
        mi = np.array([m[0] for m in missing])
        mj = np.array([m[1] for m in missing])
        a0, b0 = mi.min(), mj.min()
        region = self.pyramid.sample(
            self.center, self.size, self.layout.template_size, origin=(a0 * step, b0 * step),
            out_size=((mi.max() - a0) * step + pw, (mj.max() - b0) * step + ph),
        )
        n_cols = mi.max() - a0 + 1
        eps_all = self.layout.extract(region)
        eps = eps_all[(mj - b0) * n_cols + (mi - a0)]
        nx, ny = self.layout.cells
        nearest = np.clip(mj, 0, ny - 1) * nx + np.clip(mi, 0, nx - 1)
        codes = self.coder.encode(eps.T, warm=self.target_codes[:, nearest])
        start = len(self.pos)
        for k, cell in enumerate(missing):
            self._index[cell] = start + k
        self.pos = np.vstack([self.pos, self.layout.cell_positions(mi, mj)])
        self.code_weights = np.concatenate([self.code_weights, max_alignment_pooling(codes, self.n_templates)])
        self.appearance_cost = np.hstack(
            [self.appearance_cost, self.alpha * appearance_distance(self.target_eps, eps)])
        self.codings += len(missing)

    def evaluate(self, y, scale, bandwidth, target_pos, target_weights, full_gradient: bool):
        """EMD between the target and the candidate at (y, scale), and dEMD/dy.

        Returns (emd, gradient (2,), EmdSolution or None when no bin has weight).
        ``full_gradient`` selects the envelope gradient over the paper's eq. (10).
        """
        self.ensure(y, bandwidth * scale)
        w_c, dw_dy = candidate_weights(self.code_weights, self.pos, y, scale, bandwidth)
        keep = w_c > 0
        if not keep.any():
            return np.inf, np.zeros(2), None
        rel = (self.pos[keep] - y) / scale
        diff = target_pos[:, None, :] - rel[None, :, :]
        cost = self.appearance_cost[:, keep] + (1.0 - self.alpha) * (diff**2).sum(-1)
        solution: EmdSolution = solve_emd(target_weights, w_c[keep], cost)
        if full_gradient:
            grad = envelope_gradient(solution, dw_dy[keep], 2.0 * (1.0 - self.alpha) / scale * diff)
        else:
            grad = emd_gradient(solution, dw_dy[keep])
        return solution.value, grad, solution
