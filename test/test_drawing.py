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

"""draw_result: the node's debug image and the replay's video frames."""
from iemd_ros.pipeline import FrameResult, Rejection, TrackState
from iemd_ros.pipeline.drawing import draw_result, GYRO, INIT, LOST, TRACKING
import numpy as np


def _pixels(img, colour):
    return int(np.all(img == colour, axis=2).sum())


def test_boxes_are_drawn_in_the_state_colours_on_a_copy():
    grey = np.full((120, 160), 128, np.uint8)
    init = draw_result(
        grey,
        FrameResult(
            stamp_ns=1,
            state=TrackState.TRACKING,
            box=(20.0, 30.0, 40.0, 30.0),
            score=1.0,
            is_init=True,
        ),
    )
    assert (
        init.shape == (120, 160, 3) and _pixels(init, INIT) > 100 and _pixels(init, TRACKING) == 0
    )
    tracked = FrameResult(
        stamp_ns=2,
        state=TrackState.TRACKING,
        box=(20.0, 30.0, 40.0, 30.0),
        emd=0.1,
        gyro_used=True,
        gyro_box=(60.0, 50.0, 40.0, 30.0),
    )
    img = draw_result(grey, tracked)
    assert _pixels(img, TRACKING) > 100 and _pixels(img, GYRO) > 50 and _pixels(img, LOST) == 0
    lost = draw_result(
        grey,
        FrameResult(
            stamp_ns=3, state=TrackState.LOST, box=(20.0, 30.0, 40.0, 30.0), emd=2.0, lost=True
        ),
    )
    assert _pixels(lost, LOST) > 100 and _pixels(lost, TRACKING) == 0
    bgr = np.zeros((120, 160, 3), np.uint8)
    rejected = draw_result(
        bgr,
        FrameResult(
            stamp_ns=4,
            state=TrackState.TRACKING,
            rejection=Rejection.STAMP,
            reason="image stamp repeats the previous frame's",
        ),
    )
    # text only; input untouched
    assert _pixels(rejected, TRACKING) == 0 and rejected.any() and not bgr.any()
