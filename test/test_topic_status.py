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
diagnostic_updater's FrequencyStatus and TimeStampStatus as the node's detections status.

(ROS-free).
"""
from iemd_ros.pipeline.diagnostics import Level
from iemd_ros.pipeline.topic_status import TopicStatus


def _status(**over):
    args = {
        'min_rate_hz': 10.0,
        'max_rate_hz': 40.0,
        'tolerance': 0.1,
        'window': 5,
        'stamp_age_min_s': -1.0,
        'stamp_age_max_s': 5.0,
        'start_s': 0.0,
    }
    args.update(over)
    return TopicStatus(**args)


def _feed(s, rate_hz, t0, t1, age=0.01):
    n = int(round((t1 - t0) * rate_hz))
    for k in range(n):
        s.tick(t0 + k / rate_hz, age)


def test_no_events_is_an_error_and_no_data_a_warning():
    level, message, values = _status().status(1.0)
    assert level is Level.ERROR and message == 'No events recorded.; No data since last update.'
    assert values['Events in window'] == 0


def test_rate_inside_the_window_is_ok_outside_a_warning():
    s = _status()
    for t in range(1, 6):
        _feed(s, 30.0, t - 1.0, t)
        level, message, values = s.status(float(t))
    assert level is Level.OK and message.startswith('Desired frequency met')
    assert abs(float(values['Actual frequency (Hz)']) - 30.0) < 0.5
    slow = _status()
    for t in range(1, 6):
        _feed(slow, 8.0, t - 1.0, t)
        level, message, _ = slow.status(float(t))
    assert level is Level.WARN and message == 'Frequency too low.'
    fast = _status(max_rate_hz=20.0)
    _feed(fast, 30.0, 0.0, 1.0)
    assert fast.status(1.0)[1] == 'Frequency too high.'
    unbounded = _status(max_rate_hz=0.0)
    _feed(unbounded, 300.0, 0.0, 1.0)
    assert unbounded.status(1.0)[0] is Level.OK


def test_the_rate_window_forgets_old_events():
    s = _status(window=2)
    _feed(s, 30.0, 0.0, 1.0)
    s.status(1.0)
    s.status(2.0)
    # the 30 events of the first second left the 2-update window
    level, message, values = s.status(3.0)
    assert values['Events in window'] == 0 and level is Level.ERROR


def test_stamp_ages_out_of_range_and_zero_stamps_are_errors():
    s = _status()
    _feed(s, 30.0, 0.0, 1.0, age=7.5)
    level, message, values = s.status(1.0)
    assert level is Level.ERROR and 'Timestamps too far in the past seen.' in message
    assert (
        values['Late diagnostic update count'] == 1
        and float(values['Latest timestamp delay']) == 7.5
    )
    _feed(s, 30.0, 1.0, 2.0, age=-2.0)
    assert 'Timestamps too far in future seen.' in s.status(2.0)[1]
    s.tick(2.1, 0.0, zero_stamp=True)
    assert 'Zero timestamp seen.' in s.status(3.0)[1]
    _feed(s, 30.0, 3.0, 4.0, age=0.02)
    assert s.status(4.0)[0] is Level.OK  # the ages start over at every update
