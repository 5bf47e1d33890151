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

"""Dictionary of templates and the EMD-weighted template update (section 5.1, Algorithm 2)."""
from __future__ import annotations

from iemd_ros.tracking.appearance import PatchLayout
from iemd_ros.tracking.sparse_coding import max_alignment_pooling, SparseCoder
import numpy as np


class TemplateDictionary:
    """
    Dictionary Phi of local patches from up to L templates (section 4).

    The first L tracked templates fill the dictionary; afterwards only the latest one is replaced
    (Algorithm 2).  Atoms are ordered template by template, each template contributing the patches
    of ``layout`` in the same order, which is what max-alignment pooling needs.

    Parameters
    ----------
    layout : PatchLayout
        The patches of a template.
    n_templates : int
        The number L of templates.
    lam : float
        The lambda of the patches' sparse coding (eq. lagrange).
    forgetting : float
        The decay gamma0 of the latest template's weight (eq. template update).
    reconstruction_lambda : float
        The lambda of the reconstructed template (eq. reconstructed template).

    """

    def __init__(self, layout: PatchLayout, n_templates: int, lam: float,
                 forgetting: float, reconstruction_lambda: float):
        self.layout = layout
        self.n_templates = n_templates
        self.lam = lam
        self.forgetting = forgetting
        self.reconstruction_lambda = reconstruction_lambda
        self.templates: list[np.ndarray] = []
        self.latest_weight = 0.0  # omega_{i-1} of the latest template
        self.latest_index = 0  # frame index k at which it entered
        self.coder: SparseCoder | None = None

    def _rebuild(self) -> None:
        atoms = np.hstack([self.layout.extract(t).T for t in self.templates])
        self.coder = SparseCoder(atoms, self.lam)

    def add(self, template: np.ndarray, emd: float, index: int) -> None:
        """
        Append a template while the dictionary holds fewer than L.

        Parameters
        ----------
        template : ndarray
            (Th, Tw) tracked template.
        emd : float
            Its EMD D*; its weight is omega = exp(-emd).
        index : int
            Frame index k at which it enters.

        """
        self.templates.append(np.asarray(template, dtype=np.float64))
        self.latest_weight, self.latest_index = float(np.exp(-emd)), index
        self._rebuild()

    def code_weights(self, eps: np.ndarray) -> np.ndarray:
        """
        Pooled bin weights ||a-bar||_inf of patches.

        Their sparse codes over Phi (eq. lagrange) with max-alignment pooling over the L templates
        (section 4).

        Parameters
        ----------
        eps : ndarray
            (N, d) appearance vectors of the patches.

        Returns
        -------
        ndarray
            (N,) weights.

        """
        return max_alignment_pooling(self.coder.encode(eps.T), len(self.templates))

    @property
    def full(self) -> bool:
        """Whether the dictionary holds L templates."""
        return len(self.templates) >= self.n_templates

    def observe(self, template: np.ndarray, emd: float, index: int) -> bool:
        """
        Algorithm 2 for the tracked template I_k with EMD D*_k.

        The latest template's weight decays as omega_{i-1} = gamma0^{Delta i} omega (eq. template
        update) and the current one has omega_i = exp(-D*_k).  Reading of the comparison: the
        paper's text and pseudo-code replace when omega_i < omega_{i-1}, which would insert
        templates that match *worse* (drifting into occluders and background).  We replace when the
        current template is the better-weighted one, omega_i > gamma0^{Delta i} omega_{i-1}, i.e.
        D*_k < D*_last + Delta i |ln gamma0|: confident templates refresh the dictionary, and a
        stale one is refreshed more readily as it ages.  The first L-1 templates are never
        replaced, which anchors the appearance.

        Parameters
        ----------
        template : ndarray
            (Th, Tw) tracked template I_k.
        emd : float
            Its EMD D*_k.
        index : float
            The frame's time k in reference frames (``TrackerConfig.reference_rate``): the
            frame index at that rate.

        Returns
        -------
        bool
            True if Phi changed.

        """
        if not self.full:
            # Filling the first L slots: the tracked templates themselves (a
            # reconstruction from fewer templates could only repeat them).
            self.add(template, emd, index)
            return True
        weight = float(np.exp(-emd))
        decayed = self.forgetting ** (index - self.latest_index) * self.latest_weight
        if weight <= decayed:
            return False
        self.templates[-1] = self.reconstruct(template)
        self.latest_weight, self.latest_index = weight, index
        self._rebuild()
        return True

    def reconstruct(self, template: np.ndarray) -> np.ndarray:
        """
        Reconstructed template of eq. (reconstructed template), occluders removed.

        Solves min ||I_k - [Phi_T I] a||^2 + lambda ||a||_1 with a >= 0 on the template part and a
        free sign on the trivial (identity) part, by block coordinate descent: the trivial part e
        has the closed form of soft thresholding the residual at lambda/2, the template part is a
        small non-negative lasso over the L whole templates.  The paper keeps Phi_T a* alone; but
        that only recombines the templates already in the dictionary, so the dictionary could never
        take in a new appearance (lighting, pose).  Keeping the unclaimed observed pixels does,
        while an occluder is still replaced by what the dictionary predicts.

        Parameters
        ----------
        template : ndarray
            (Th, Tw) observed template I_k.

        Returns
        -------
        ndarray
            I_k - e, of the template's shape: the observed template where the trivial templates
            claim nothing and Phi_T a* (+- lambda/2) where they do (occluders, noise).

        """
        x = np.asarray(template, dtype=np.float64).ravel()
        phi_t = np.column_stack([t.ravel() for t in self.templates])
        coder = SparseCoder(phi_t, self.reconstruction_lambda)
        half = 0.5 * self.reconstruction_lambda
        trivial = np.zeros_like(x)
        for _ in range(20):
            codes = coder.encode((x - trivial)[:, None])[:, 0]
            residual = x - phi_t @ codes
            new_trivial = np.sign(residual) * np.maximum(np.abs(residual) - half, 0.0)
            if np.max(np.abs(new_trivial - trivial)) < 1e-6:
                trivial = new_trivial
                break
            trivial = new_trivial
        return (x - trivial).reshape(template.shape)
