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
The watchdog on the tracker update.

A call that does not return in time is abandoned, the next runs on a new thread, and abandoned
calls still running cannot pile up.
"""
import threading

from iemd_ros.datasets.synthetic import generate
from iemd_ros.pipeline import PipelineConfig, Rejection, TrackingPipeline, TrackState
from iemd_ros.pipeline.watchdog import Abandoned, Watchdog
from iemd_ros.tracking import IemdTracker
import pytest


def test_results_and_exceptions_come_back_from_the_watchdog_thread():
    dog = Watchdog()
    assert dog.run(lambda: 42, 10.0) == 42
    with pytest.raises(KeyError, match='raised there'):
        dog.run(lambda: {}['raised there'], 10.0)
    assert dog.abandoned == 0
    dog.close()


def test_a_call_that_does_not_return_is_abandoned_and_they_cannot_pile_up():
    dog = Watchdog(max_running=1)
    release = threading.Event()
    with pytest.raises(Abandoned) as first:
        dog.run(release.wait, 0.05)                     # "never" returns
    assert first.value.ran and dog.abandoned == 1
    with pytest.raises(
        Abandoned, match='not started: 1 abandoned calls are still running'
    ) as second:
        dog.run(lambda: 1, 10.0)
    assert not second.value.ran
    (left,) = dog._left
    release.set()
    # the abandoned call returns and its thread ends
    left.join(10.0)
    # the abandoned call returned: calls start again
    assert not left.is_alive() and dog.run(lambda: 2, 10.0) == 2
    dog.close()


def test_the_pipeline_answers_a_frame_whose_update_hangs_and_tracks_the_next(monkeypatch):
    seq = generate(n_frames=5, seed=3)
    s = [int(v) for v in seq.frame_stamps_ns]
    release, armed = threading.Event(), []
    update = IemdTracker.update

    def hangs_once(self, frame, prior=None, interval=None):
        if armed:
            armed.pop()
            release.wait(60.0)
        return update(self, frame, prior, interval)

    p = TrackingPipeline(PipelineConfig(use_gyro=False, watchdog_ms=100.0))
    monkeypatch.setattr(IemdTracker, 'update', hangs_once)
    try:
        p.init(seq.frames[0], seq.gt_boxes[0], s[0])
        r = p.process(seq.frames[1], s[1])
        assert r.state is TrackState.TRACKING and r.rejection is None
        armed.append(1)
        r = p.process(seq.frames[2], s[2])
        assert (
            r.rejection is Rejection.ABANDONED
            and 'abandoned after 100 ms' in r.reason
            and not r.tracking
        )
        assert p.statuses()[0].level == 2 and '1 abandoned so far' in p.statuses()[0].message
        r = p.process(seq.frames[3], s[3])  # the rebuilt tracker
        assert r.state is TrackState.TRACKING and r.rejection is None
        assert p.statuses()[0].level == 0 and p.diagnostics()['updates_abandoned'] == 1
    finally:
        release.set()


def test_an_offline_pipeline_waits_for_a_slow_update_in_the_callers_thread(monkeypatch):
    """
    ``live=False`` (the replay): no update is abandoned, however long it takes, and none leaves.

    An update taking 3x ``watchdog_ms`` gives the frame its result; every tracker call runs in
    the thread that called process.
    """
    seq = generate(n_frames=4, seed=3)
    s = [int(v) for v in seq.frame_stamps_ns]
    update, callers = IemdTracker.update, set()

    def slow(self, frame, prior=None, interval=None):
        callers.add(threading.get_ident())
        threading.Event().wait(0.3)
        return update(self, frame, prior, interval)

    p = TrackingPipeline(PipelineConfig(use_gyro=False, watchdog_ms=100.0), live=False)
    monkeypatch.setattr(IemdTracker, 'update', slow)
    p.init(seq.frames[0], seq.gt_boxes[0], s[0])
    for k in (1, 2, 3):
        r = p.process(seq.frames[k], s[k])
        assert r.state is TrackState.TRACKING and r.rejection is None
    assert callers == {threading.get_ident()}
    assert p.diagnostics()['updates_abandoned'] == 0 and p.statuses()[0].level == 0
