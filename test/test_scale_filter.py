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

"""The fDSST scale filter (iemd_ros/tracking/scale_filter.py) and the tracker's use of it."""
from helpers import zoomed
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking.scale_filter import ScaleFilter
import numpy as np
import pytest


@pytest.mark.parametrize('angle', [0.0, 0.6])
def test_recovers_a_known_scale_change_of_a_real_window(car4_first, angle):
    """
    Learned on Car4's target, the filter measures the target against known scale changes.

    Against windows 10 % too small or too large (1/0.9 = 1.111 and 1/1.1 = 0.909), and against a
    frame magnified by 6 %; with the window turned too.
    """
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    sf = ScaleFilter()
    sf.init(frame, centre, size, angle)
    assert sf.estimate(frame, centre, size, angle) == pytest.approx(1.0, abs=0.005)
    for window in (0.9, 1.1):
        assert sf.estimate(frame, centre, size * window, angle) == pytest.approx(
            1.0 / window, rel=0.03
        )
    assert sf.estimate(zoomed(frame, centre, 1.06), centre, size, angle) == pytest.approx(
        1.06, rel=0.015
    )


def test_the_estimate_stays_within_the_bounds_and_update_learns_the_new_size(car4_first):
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    sf = ScaleFilter()
    sf.init(frame, centre, size)
    bigger = zoomed(frame, centre, 1.06)
    assert sf.estimate(bigger, centre, size, bounds=(0.5, 1.0)) == 1.0
    for _ in range(40):  # the running template learns the larger target at its larger size
        sf.update(bigger, centre, size * 1.06)
    assert sf.estimate(bigger, centre, size * 1.06) == pytest.approx(1.0, abs=0.01)


def test_invalid_use_is_refused():
    with pytest.raises(RuntimeError, match='needs init'):
        ScaleFilter().estimate(np.zeros((64, 64), np.uint8), (32, 32), (16, 16))
    with pytest.raises(ValueError, match='> 1'):
        ScaleFilter(scale_step=1.0)
    with pytest.raises(ValueError, match='scale_estimator must be one of filter, emd'):
        TrackerConfig(scale_estimator='dsst')


def test_the_tracker_follows_a_zoom_the_emd_variants_cannot(car4_first):
    """
    Car4's frame magnified by 8 % about the target.

    The filter takes the window to 1.08 in one frame; the paper's EMD variants move at most
    scale_range (2 %) per frame, and scale_step 0 keeps the size.
    """
    frame, box = car4_first
    scales = {}
    for estimator, step in [('filter', 0.02), ('emd', 0.02), ('filter', 0.0)]:
        tracker = IemdTracker(
            TrackerConfig(scale_estimator=estimator, scale_step=step, update_templates=False)
        )
        tracker.init(frame, box)
        scales[estimator, step] = tracker.update(zoomed(frame, box_centre(box), 1.08)).scale
    assert scales['filter', 0.02] == pytest.approx(1.08, rel=0.02)
    assert 1.0 <= scales['emd', 0.02] <= 1.02 + 1e-12
    assert scales['filter', 0.0] == 1.0
