"""draw_result: the node's debug image and the replay's video frames."""
import numpy as np

from iemd_ros.pipeline.drawing import GYRO, INIT, LOST, TRACKING, draw_result
from iemd_ros.pipeline import FrameResult, Rejection, TrackState


def _pixels(img, colour):
    return int(np.all(img == colour, axis=2).sum())


def test_boxes_are_drawn_in_the_state_colours_on_a_copy():
    grey = np.full((120, 160), 128, np.uint8)
    init = draw_result(grey, FrameResult(stamp_ns=1, state=TrackState.TRACKING, box=(20.0, 30.0, 40.0, 30.0), score=1.0, is_init=True))
    assert init.shape == (120, 160, 3) and _pixels(init, INIT) > 100 and _pixels(init, TRACKING) == 0
    tracked = FrameResult(stamp_ns=2, state=TrackState.TRACKING, box=(20.0, 30.0, 40.0, 30.0), emd=0.1, gyro_used=True,
                          gyro_box=(60.0, 50.0, 40.0, 30.0))
    img = draw_result(grey, tracked)
    assert _pixels(img, TRACKING) > 100 and _pixels(img, GYRO) > 50 and _pixels(img, LOST) == 0
    lost = draw_result(grey, FrameResult(stamp_ns=3, state=TrackState.LOST, box=(20.0, 30.0, 40.0, 30.0), emd=2.0, lost=True))
    assert _pixels(lost, LOST) > 100 and _pixels(lost, TRACKING) == 0
    bgr = np.zeros((120, 160, 3), np.uint8)
    rejected = draw_result(bgr, FrameResult(stamp_ns=4, state=TrackState.TRACKING, rejection=Rejection.STAMP, reason="image stamp repeats the previous frame's"))
    assert _pixels(rejected, TRACKING) == 0 and rejected.any() and not bgr.any()   # text only; input untouched
