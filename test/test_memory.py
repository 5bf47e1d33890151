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
Model memory in time (iemd_ros/tracking/memory.py).

A frame of a known interval learns as that many reference frames would, in every model, the
tracker and the pipeline.
"""
from helpers import shifted, texture
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.pipeline import PipelineConfig, TrackingPipeline
from iemd_ros.tracking import memory
from iemd_ros.tracking.colour_model import ColourModel
from iemd_ros.tracking.scale_filter import ScaleFilter
from iemd_ros.tracking.translation_filter import MU, TranslationFilter
import numpy as np
import pytest

BOX = (130.0, 90.0, 48.0, 40.0)
CENTRE, SIZE = (154.0, 110.0), (48.0, 40.0)


def _colour(seed):
    return np.dstack([texture(seed=seed + k, blob=8) for k in range(3)])


def test_a_rate_over_frames_is_that_many_frames_in_turn():
    # by hand: 1 - (1 - 0.1)^2 = 0.19; one frame is the rate itself, exactly
    assert memory.rate_over(0.1, 2.0) == pytest.approx(0.19)
    assert memory.rate_over(0.025, 1.0) == 0.025
    old, new, eta = 4.0, 1.0, 0.3
    twice = (1 - eta) * ((1 - eta) * old + eta * new) + eta * new
    r = memory.rate_over(eta, 2.0)
    assert (1 - r) * old + r * new == pytest.approx(twice)
    h = memory.rate_over(eta, 0.5)  # two half frames make one
    one = (1 - eta) * old + eta * new
    assert (1 - h) * ((1 - h) * old + h * new) + h * new == pytest.approx(one)
    assert memory.penalty_over(15.0, 3.0) == 5.0


def test_a_running_average_over_frames_is_that_many_frames_in_turn():
    old, new, eta = np.array([4.0, -2.0]), np.array([1.0, 3.0]), 0.3
    # by hand: 0.7 x 4 + 0.3 x 1 = 3.1
    assert memory.running_average(4.0, 1.0, eta, 1.0) == pytest.approx(3.1)
    twice = memory.running_average(memory.running_average(old, new, eta, 1.0), new, eta, 1.0)
    np.testing.assert_allclose(memory.running_average(old, new, eta, 2.0), twice)
    np.testing.assert_array_equal(old, [4.0, -2.0])  # the average so far is not written into


def _double_twice_once(model):
    """Return a frame and three ``model()`` that learned it: as two frames, twice, once."""
    frame0, frame1 = _colour(1), shifted(_colour(5), 3.0, -2.0)
    double, twice, once = model(), model(), model()
    for m in (double, twice, once):
        m.init(frame0, CENTRE, SIZE)
    double.update(frame1, CENTRE, SIZE, frames=2.0)
    for m in (twice, twice, once):
        m.update(frame1, CENTRE, SIZE)
    return frame1, double, twice, once


def test_the_scale_filter_and_colour_model_learn_a_double_interval_as_two_frames():
    _, double, twice, once = _double_twice_once(ScaleFilter)
    np.testing.assert_allclose(double.template, twice.template, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(double.denominator, twice.denominator, rtol=1e-12, atol=1e-12)
    assert not np.allclose(double.template, once.template)
    frame1, double, twice, once = _double_twice_once(ColourModel)
    patch = frame1[90:130, 130:178]
    scores = double.pixel_scores()(patch)
    np.testing.assert_allclose(scores, twice.pixel_scores()(patch), atol=1e-6)
    assert not np.allclose(scores, once.pixel_scores()(patch), atol=1e-6)


def test_the_translation_filters_temporal_penalty_is_per_interval(monkeypatch):
    penalties = []
    admm = TranslationFilter._admm

    def spy(self, xf, f_prev, *args, **kwargs):
        penalties.append(kwargs.get('mu'))
        return admm(self, xf, f_prev, *args, **kwargs)

    monkeypatch.setattr(TranslationFilter, '_admm', spy)
    frame = _colour(2)
    tf = TranslationFilter()
    tf.init(frame, CENTRE, SIZE, True)
    tf.update(frame, CENTRE, SIZE)
    tf.update(frame, CENTRE, SIZE, frames=3.0)
    assert penalties[-2:] == [MU, MU / 3.0]


def _frames(n=6):
    frame = _colour(3)
    return [shifted(frame, 1.5 * k, -k) for k in range(n)]


def test_the_tracker_learns_for_the_interval_it_is_told(monkeypatch):
    frames = _frames()
    seen = []
    update = ScaleFilter.update

    def spy(self, frame, center, size, angle=0.0, frames=1.0):
        seen.append(frames)
        return update(self, frame, center, size, angle, frames)

    monkeypatch.setattr(ScaleFilter, 'update', spy)
    told = IemdTracker(threads=False)
    told.init(frames[0], BOX)
    untold = IemdTracker(threads=False)
    untold.init(frames[0], BOX)
    reference = IemdTracker(threads=False)
    reference.init(frames[0], BOX)
    seen.clear()
    slow = [told.update(f, interval=0.1) for f in frames[1:]]  # a 10 Hz camera: 3 frames each
    assert seen == [pytest.approx(3.0)] * len(slow)
    seen.clear()
    # an interval of one reference frame is the same as none, to the bit
    at_rate = [untold.update(f, interval=1 / 30) for f in frames[1:]]
    assert seen == [1.0] * len(at_rate)
    assert at_rate == [reference.update(f) for f in frames[1:]]
    assert TrackerConfig().reference_rate == 30.0


@pytest.mark.parametrize('interval', [0.0, -0.1, float('nan'), float('inf')])
def test_a_bad_interval_is_refused_and_changes_nothing(interval):
    frames = _frames(3)
    probed, untouched = IemdTracker(threads=False), IemdTracker(threads=False)
    probed.init(frames[0], BOX)
    untouched.init(frames[0], BOX)
    with pytest.raises(ValueError, match='interval must be a finite number of seconds > 0'):
        probed.update(frames[1], interval=interval)
    assert probed.update(frames[1]) == untouched.update(frames[1])


def test_the_pipeline_tells_the_tracker_the_interval_since_the_targets_last_frame(monkeypatch):
    frames = _frames()
    stamps = [int(1e9 + k * 50e6) for k in range(len(frames))]  # 20 Hz
    told = []
    update = IemdTracker.update

    def spy(self, frame, prior=None, interval=None):
        told.append(interval)
        return update(self, frame, prior, interval)

    monkeypatch.setattr(IemdTracker, 'update', spy)
    p = TrackingPipeline(PipelineConfig.from_dict({'use_gyro': False}), live=False)
    p.init(frames[0], BOX, stamps[0])
    told.clear()  # the kernels' warm-up tracks a frame of its own
    for k in (1, 2, 4, 5):  # frame 3 dropped
        p.process(frames[k], stamps[k])
    assert told == pytest.approx([0.05, 0.05, 0.1, 0.05])
