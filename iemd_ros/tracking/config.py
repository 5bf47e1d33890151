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
The tracker's parameters (:class:`TrackerConfig`).

Each is declared once, with its meaning, unit and range.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields
import importlib

from iemd_ros.common.params import Choice, coerce, param
from iemd_ros.tracking.appearance import PatchLayout

__all__ = [
    'TrackerConfig',
    'Gradient',
    'ScaleEstimator',
    'PRESETS',
    'MAX_PATCHES',
    'MAX_PATCH_PIXELS',
]

PRESETS = ('default', 'paper')  # modules of iemd_ros.tracking.presets
# The most patches, and patch pixels, a window may be coded with: those of a 96x96 template with
# 8x8 patches at step 4 (docs/decisions.md#patch-budget)
MAX_PATCHES = 529
MAX_PATCH_PIXELS = 529 * 64


class Gradient(Choice):
    """Descent direction of Algorithm 1."""

    APPEARANCE = 'appearance'  # derivative of the resampled model through the patches' appearance
    PAPER = 'paper'  # eq. (10): the duals times dw_C/dy, patches fixed


class ScaleEstimator(Choice):
    """How the window's scale is estimated at the converged position."""

    FILTER = 'filter'  # DSST's scale filter
    EMD = 'emd'  # the paper's EMD of the window enlarged and shrunk by scale_step


@dataclass
class TrackerConfig:
    """
    Parameters of :class:`~iemd_ros.tracking.tracker.IemdTracker`.

    The defaults are those of the ``default`` preset.

    ``TrackerConfig.preset("paper")`` gives the system of the paper; see :data:`PRESETS`.
    """

    template_size: tuple[int, int] = param(
        (32, 32),
        '[width, height] of the resampled target window',
        unit='px',
        range=(8, 96),
        length=2,
        eq='section 6.1',
        decision='grey-patches-template-size',
    )
    patch_size: tuple[int, int] = param(
        (8, 8),
        '[m, n] size of the local patches',
        unit='px',
        range=(2, 32),
        length=2,
        eq='section 4',
    )
    patch_step: int = param(
        4, 'stride between local patches', unit='px', range=(1, 32), eq='section 4'
    )
    n_templates: int = param(
        1,
        'L, templates in the dictionary',
        range=(1, 20),
        eq='Algorithm 2',
        decision='dictionary-size',
    )
    lam: float = param(
        0.1,
        'lambda of the sparse coding',
        range=(1e-4, 10.0),
        eq='eq. (lagrange)',
        decision='sparse-coding-solver',
    )
    alpha: float = param(
        0.5,
        'weight of appearance against position in the ground distance d_uv',
        range=(0.001, 0.999),
        eq='eq. (ground distance)',
    )
    kernel_bandwidth: float = param(
        1.0,
        'h, bandwidth of the Epanechnikov kernel',
        unit='window half-sizes',
        range=(0.1, 10.0),
        eq='eq. (sparse target model)',
        decision='kernel-bandwidth',
    )
    n_iter: int = param(
        0,
        'most descent iterations per start (0: each start stays where it is)',
        range=(0, 500),
        eq='Algorithm 1',
        decision='descent-off',
    )
    step_px: float = param(
        2.0,
        'first step along -dEMD/dy',
        unit='px',
        range=(0.01, 100.0),
        eq='Algorithm 1',
        decision='descent-step',
    )
    min_step_px: float = param(
        0.5,
        'stop when backtracking halves the step below this (<= step_px)',
        unit='px',
        range=(0.01, 100.0),
        eq='Algorithm 1',
        decision='descent-step',
    )
    gradient: Gradient = param(
        Gradient.APPEARANCE,
        'descent direction: appearance, or paper (eq. 10)',
        eq='eqs. (9)-(10)',
        decision='descent-gradient',
    )
    scale_estimator: ScaleEstimator = param(
        ScaleEstimator.FILTER,
        "scale estimate: filter (DSST), or emd (the paper's scale variants)",
        eq='section 6.1',
        decision='scale-estimator',
    )
    scale_step: float = param(
        0.02,
        'relative step between the scales searched (0: the size is kept)',
        range=(0.0, 0.49),
        eq='section 6.1',
        decision='scale-estimator',
    )
    scale_range: float = param(
        0.02,
        'emd: largest relative scale change per frame (>= scale_step)',
        range=(0.0, 0.49),
        decision='scale-estimator',
    )
    flow_start: bool = param(
        True,
        "also start where the window's median optical flow moves it",
        eq='section 6.1',
        decision='flow-start',
    )
    flow_max_error: float = param(
        2.0,
        'forward-backward error above which a flow point is dropped',
        unit='px',
        range=(0.01, 100.0),
        decision='flow-start',
    )
    translation_weight: float = param(
        1.0,
        "weight of the translation filter's response in the search's score (0: no filter)",
        range=(0.0, 100.0),
        decision='translation-filter',
    )
    colour_weight: float = param(
        0.75,
        "weight of the colour model's mean score in the search's score, colour frames "
        'only (0: no colour model)',
        range=(0.0, 100.0),
        decision='colour-model',
    )
    colour_merge: float = param(
        0.3,
        "share of the colour model's mean-shift step a tracked window moves by, colour "
        'frames only (0: none)',
        range=(0.0, 1.0),
        decision='colour-mean-shift',
    )
    motion_weight: float = param(
        0.05,
        "weight of the squared displacement from the prediction over the window's "
        "area in the search's score (0: none)",
        range=(0.0, 100.0),
        decision='motion-prior',
    )
    update_confidence: float = param(
        0.6,
        "a frame learns only when the filter's response at the window is at "
        'least this times its running mean (0: always)',
        range=(0.0, 0.99),
        decision='occlusion-check',
    )
    n_particles: int = param(
        0,
        'extra starts around the prediction for abrupt motion',
        range=(0, 64),
        eq='section 6.1',
        decision='particles',
    )
    particle_offset: float = param(
        0.5,
        'distance of the particles from the prediction',
        unit='window sizes',
        range=(0.0, 10.0),
        decision='particles',
    )
    particle_trigger: float = param(
        0.85,
        'search the particles when EMD > this x background EMD (0: always)',
        range=(0.0, 100.0),
        decision='background-emd',
    )
    lost_response: float = param(
        0.5,
        "lost when the filter's peak near the prediction falls below this times its "
        'running mean (0: never)',
        range=(0.0, 0.99),
        decision='re-detection',
    )
    found_response: float = param(
        1.0,
        "while lost, the window is found again when the filter's peak there reaches "
        'this times its running mean (after a long loss re-detection also takes a peak '
        "that stands out from the loss's own best peaks)",
        range=(0.01, 10.0),
        decision='re-detection',
    )
    lost_factor: float = param(
        1.0,
        'held when EMD > this x the background EMD measured at init (lost on a frame the '
        'occlusion check holds, while already lost, or without the translation filter)',
        range=(0.01, 100.0),
        decision='background-emd',
    )
    min_visible: float = param(
        0.25, 'lost when less of the window than this is inside the image', range=(0.0, 1.0)
    )
    update_templates: bool = param(
        True, 'update the template dictionary', eq='Algorithm 2', decision='template-update'
    )
    forgetting: float = param(
        0.95, 'gamma_0 of the template weights', range=(0.001, 1.0), eq='eq. (template update)'
    )
    reconstruction_lambda: float = param(
        0.1,
        'lambda of the reconstructed template',
        range=(1e-4, 10.0),
        eq='eq. (reconstructed template)',
    )
    reference_rate: float = param(
        30.0,
        "frame rate the models' per-frame learning rates hold for; a frame of known "
        'interval learns as interval x this many frames',
        unit='Hz',
        range=(1.0, 1000.0),
        decision='frame-interval-learning',
    )

    def __post_init__(self):
        coerce(self, 'tracker.')
        if self.min_step_px > self.step_px:
            raise ValueError(
                f'tracker.min_step_px ({self.min_step_px}) must not exceed step_px '
                f'({self.step_px})'
            )
        if self.scale_range < self.scale_step:
            raise ValueError(
                f'tracker.scale_range ({self.scale_range}) must be at least scale_step '
                f'({self.scale_step})'
            )
        try:
            layout = PatchLayout(self.template_size, self.patch_size, self.patch_step)
        except ValueError as exc:
            raise ValueError(f'tracker: {exc}') from None
        patches = layout.cells[0] * layout.cells[1]
        pixels = patches * self.patch_size[0] * self.patch_size[1]
        if patches > MAX_PATCHES or pixels > MAX_PATCH_PIXELS:
            raise ValueError(
                f'tracker: template_size {list(self.template_size)}, patch_size '
                f'{list(self.patch_size)} and patch_step {self.patch_step} code a window with '
                f'{patches} patches of {pixels} pixels; at most {MAX_PATCHES} patches and '
                f'{MAX_PATCH_PIXELS} pixels (a 96x96 template of 8x8 patches at step 4) keep an '
                'update within the watchdog'
            )

    @classmethod
    def preset(cls, name: str) -> 'TrackerConfig':
        """Return the configuration of the preset ``default`` or ``paper`` (:data:`PRESETS`)."""
        if name not in PRESETS:
            raise ValueError(f'unknown tracker preset {name!r} (known: {", ".join(PRESETS)})')
        return importlib.import_module(f'iemd_ros.tracking.presets.{name}').parameters()

    @classmethod
    def from_dict(cls, values: dict) -> 'TrackerConfig':
        """
        Build the configuration from plain values by field name (missing: defaults).

        ValueError for unknown names or bad values.
        """
        unknown = set(values) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f'unknown tracker parameters: {", ".join(sorted(unknown))}')
        return cls(**values)

    def to_dict(self) -> dict:
        """
        Return plain values by field name (choices as their strings).

        They round-trip through :meth:`from_dict`.
        """
        return {k: (v.value if isinstance(v, Choice) else v) for k, v in asdict(self).items()}
