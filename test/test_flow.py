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
window_flow: the median optical flow of the target window.

The tracker's flow start (section 6.1).
"""
import dataclasses

from helpers import shifted, texture
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.tracking.appearance import grey_levels
from iemd_ros.tracking.flow import window_flow
import numpy as np
import pytest


@pytest.fixture
def car4(car4_first):
    frame, box = car4_first
    return grey_levels(frame), box


def translation(dx, dy):
    return np.array([[1.0, 0.0, dx], [0.0, 1.0, dy], [0.0, 0.0, 1.0]])


def test_finds_the_motion_of_a_real_window(car4):
    frame, box = car4
    flow = window_flow(frame, shifted(frame, 6.3, -4.2), box)
    np.testing.assert_allclose(flow, [6.3, -4.2], atol=0.2)


def test_a_prior_leaves_the_residual_motion_only(car4):
    """
    The homography (the gyro prediction) seeds Lucas-Kanade.

    A 70 px motion it predicts up to (1.5, -1) px leaves that residual.
    """
    frame, box = car4
    moved = shifted(frame, 71.5, -11.0)
    np.testing.assert_allclose(
        window_flow(frame, moved, box, prior=translation(70.0, -10.0)), [1.5, -1.0], atol=0.2
    )


def test_no_start_without_texture_or_inside_the_image():
    flat = np.full((120, 160), 128, np.uint8)
    assert window_flow(flat, flat, (40, 30, 40, 40)) is None
    frame = texture(seed=3)
    # 3x3 px of the window in the image
    assert window_flow(frame, frame, (-30, -30, 33, 33)) is None
    # Half outside: the part inside still gives the motion.
    np.testing.assert_allclose(
        window_flow(frame, shifted(frame, 2.0, 1.0), (-20, 60, 60, 50)), [2.0, 1.0], atol=0.2
    )


def test_the_forward_backward_check_drops_content_that_does_not_reappear():
    """
    Two unrelated textures.

    Lucas-Kanade ends somewhere for every point, but tracking back from there does not return to
    the point (seeded at the point itself, the backward pass returned to it: a 48 px start).
    """
    assert window_flow(texture(seed=3), texture(seed=4), (40, 30, 40, 40)) is None


def test_the_flow_start_catches_a_jump_outside_the_convergence_region(car4):
    """
    Car4 moved by 0.2 window sizes (22 px).

    Without the particles and the translation filter (which also reaches it:
    test_translation_filter.py) only the flow start does.
    """
    frame, box = car4
    jumped = shifted(frame, 22.0, 6.0)
    config = TrackerConfig(
        scale_step=0, n_particles=0, update_templates=False, translation_weight=0.0
    )
    results = {}
    for flow_start in (True, False):
        tracker = IemdTracker(dataclasses.replace(config, flow_start=flow_start))
        tracker.init(frame, box)
        results[flow_start] = tracker.update(jumped)
    assert results[True].starts == 2 and results[False].starts == 1
    assert np.allclose(results[True].box[:2], box[:2] + np.array([22.0, 6.0]), atol=1.0), results[
        True
    ].box
    assert not np.allclose(results[False].box[:2], box[:2] + np.array([22.0, 6.0]), atol=5.0), (
        results[False].box
    )
