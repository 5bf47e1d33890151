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
Gradients of the EMD with respect to the window position (eqs.

9-10, and the appearance gradient).
"""
from dataclasses import replace

from helpers import shifted, texture
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking.analysis import search_context
from iemd_ros.tracking.appearance import ImagePyramid, PatchLayout, to_gray
from iemd_ros.tracking.candidate import CandidateModel
from iemd_ros.tracking.emd import ground_distance, solve_emd, spatial_distance
from iemd_ros.tracking.histogram import candidate_weights
import numpy as np
import pytest


@pytest.fixture
def model_setup():
    import cv2

    frame0 = texture(blob=4)
    frame1 = shifted(frame0, 2.3, -1.6, cv2.INTER_LINEAR)
    tracker = IemdTracker(TrackerConfig())
    box = (120, 80, 48, 40)
    tracker.init(frame0, box)
    center = box_centre(box)
    model = CandidateModel(
        search_context(tracker, ImagePyramid(to_gray(frame1))), center, np.array(box[2:], float)
    )
    return tracker, model


def test_candidate_at_is_the_same_model_at_another_window(model_setup):
    """
    CandidateModel.at (Algorithm 1's next iterate, a scale variant) keeps the frame, target.

    Dictionary and orientation, and equals a model built at that window.
    """
    tracker, model = model_setup

    def context(dictionary, angle=0.0):  # a new context, with the fixture model's frame and target
        return replace(model.context, dictionary=dictionary, angle=angle)

    turned = CandidateModel(context(None, angle=0.3), model.center, model.size)
    for start, dictionary in ((model, tracker.dictionary), (turned, None)):
        center, size = start.center + (1.7, -0.4), start.size * 1.02
        moved = start.at(center, size)
        built = CandidateModel(context(dictionary, angle=start.angle), center, size)
        assert moved.angle == start.angle
        np.testing.assert_array_equal(moved.template, built.template)
        np.testing.assert_array_equal(moved.code_weights, built.code_weights)
        assert moved.emd()[0] == built.emd()[0] != start.emd()[0]
        np.testing.assert_array_equal(start.at(center).size, start.size)


@pytest.mark.parametrize('y', [(0.0, 0.0), (0.05, -0.03)])
def test_candidate_emd_uses_the_ground_distance(model_setup, y):
    """
    The model's compiled transport cost is eq..

    (ground distance) between the target bins and the candidate bins inside the kernel, with the
    candidate positions relative to the kernel centre.
    """
    tracker, model = model_setup
    cfg, target = tracker.config, tracker._target
    value, solution = model.emd(y)
    w, _ = candidate_weights(model.code_weights, model.pos, y, cfg.kernel_bandwidth)
    keep = w > 0
    cost = ground_distance(
        target.eps, target.pos, model.eps[keep], model.pos[keep] - np.array(y), cfg.alpha
    )
    reference = solve_emd(target.weights, w[keep], cost)
    assert value == pytest.approx(reference.value, rel=1e-12, abs=1e-14)
    assert np.allclose(solution.flow, reference.flow)
    assert 0 < value < 1


def test_paper_gradient_is_the_derivative_through_the_weights_only(model_setup):
    """Eq. (10) differentiates D* through w_C(y) with the ground distances held fixed."""
    tracker, model = model_setup
    cfg, target = tracker.config, tracker._target
    # A position where no model bin sits on the kernel boundary (there D* has a kink).
    y0 = next(
        np.array(y)
        for y in [(0.04, -0.03), (0.037, -0.021), (0.051, 0.013), (0.021, 0.033)]
        if np.abs(1 - ((model.pos - y) ** 2).sum(1) / cfg.kernel_bandwidth**2).min() > 1e-3
    )
    _, grad_paper, _ = model.evaluate('paper', y0)
    h = 1e-6
    grad_full = np.array(
        [(model.emd(y0 + h * e)[0] - model.emd(y0 - h * e)[0]) / (2 * h) for e in np.eye(2)]
    )
    probes = [y0 + d for d in (h, -h) for d in np.eye(2) * d]
    keep = np.any(
        [
            candidate_weights(model.code_weights, model.pos, y, cfg.kernel_bandwidth)[0] > 0
            for y in [y0] + probes
        ],
        axis=0,
    )
    rel = model.pos[keep] - y0
    cost = model.appearance_cost[:, keep] + (1 - cfg.alpha) * spatial_distance(target.pos, rel)

    def frozen_cost_emd(y):
        w, _ = candidate_weights(model.code_weights, model.pos, y, cfg.kernel_bandwidth)
        return solve_emd(target.weights, w[keep], cost).value

    fd = np.array(
        [(frozen_cost_emd(y0 + h * e) - frozen_cost_emd(y0 - h * e)) / (2 * h) for e in np.eye(2)]
    )
    assert np.allclose(grad_paper, fd, rtol=1e-3, atol=1e-6), (grad_paper, fd)
    # The spatial term of the ground distance depends on y too: the paper's form misses it.
    assert np.linalg.norm(grad_full - grad_paper) > 0.05 * np.linalg.norm(grad_full)


def test_appearance_gradient_matches_finite_differences_of_the_resampled_emd():
    """The gradient Algorithm 1 needs: of the EMD of the candidate re-sampled at each position."""
    frame0 = texture(seed=4, blob=4)
    frame1 = shifted(frame0, 1.3, 0.7)
    tracker = IemdTracker(TrackerConfig(gradient='appearance'))
    box = (120, 80, 48, 40)
    tracker.init(frame0, box)
    context = search_context(tracker, ImagePyramid(to_gray(frame1)))
    center = box_centre(box)
    size = np.array(box[2:], float)

    def emd(c):
        value, grad, _ = CandidateModel(context, c, size).evaluate('appearance')
        return value, grad / (size / 2)  # per image pixel

    _, grad = emd(center)
    h = 0.05
    fd = np.array([(emd(center + h * e)[0] - emd(center - h * e)[0]) / (2 * h) for e in np.eye(2)])
    # The pooled code weights also move with the content and are left out of the analytic form.
    assert np.linalg.norm(grad - fd) < 0.25 * np.linalg.norm(fd), (grad, fd)
    assert grad @ fd > 0.95 * np.linalg.norm(grad) * np.linalg.norm(fd)


def test_patch_jacobian_matches_finite_differences_of_the_resampled_patches():
    """
    The d epsilon / d(window shift) of PatchLayout.extract_with_jacobian (numba), smooth image.

    Within 10 % (the central differences of the template's grey levels approximate the resampling's
    derivative).
    """
    import cv2

    rng = np.random.default_rng(0)
    image = cv2.GaussianBlur(rng.uniform(0, 1, (120, 160)).astype(np.float32), (0, 0), 4)
    pyramid = ImagePyramid((image - image.min()) / (image.max() - image.min()))
    layout = PatchLayout((32, 32), (8, 8), 4)
    center, size, h = np.array([80.0, 60.0]), np.array([32.0, 32.0]), 0.05
    _, jac = layout.extract_with_jacobian(pyramid.sample(center, size, (32, 32)))
    for k, e in enumerate(np.eye(2)):
        fd = (
            layout.extract(pyramid.sample(center + h * e, size, (32, 32)))
            - layout.extract(pyramid.sample(center - h * e, size, (32, 32)))
        ) / (2 * h)
        assert np.linalg.norm(jac[..., k] - fd) < 0.1 * np.linalg.norm(fd)
