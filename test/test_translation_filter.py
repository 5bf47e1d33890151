"""The translation filter (iemd_ros/translation_filter.py) and the tracker's discriminative check of its starts."""
import numpy as np
import pytest
from helpers import shifted

from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking.correlation_filter import CELL
from iemd_ros.tracking.translation_filter import TranslationFilter


def _learned(frame, box, angle=0.0, **kwargs):
    translation_filter = TranslationFilter(**kwargs)
    translation_filter.init(ImagePyramid(to_gray(frame)), box_centre(box), box[2:], angle)
    return translation_filter


@pytest.mark.parametrize("angle", [0.0, np.pi / 2, 0.6])
def test_recovers_a_known_shift_of_a_real_texture(car4_first, angle):
    """Car4's frame moved by known shifts: the filter learned on the target (in a window turned by ``angle``)
    finds the move in image pixels to within a quarter of its cell (4 model px: 14.9 x 15.5 image px here, the
    267 x 218 px search region resampled to 72 x 56; errors of 1.1-3.7 px measured), between cells by the
    parabola through the response peak.  The EMD descent refines this start."""
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    translation_filter = _learned(frame, box, angle)
    assert np.allclose(translation_filter.estimate(ImagePyramid(to_gray(frame)), centre, size, angle), 0.0, atol=1e-9)
    cell_px = size * (1.0 + translation_filter.padding) / np.array(translation_filter.model_size) * CELL
    for move in [(5.0, 3.0), (-8.0, 2.0), (0.0, -10.0), (-20.0, 14.0)]:
        estimate = translation_filter.estimate(ImagePyramid(to_gray(shifted(frame, *move))), centre, size, angle)
        assert np.linalg.norm(estimate - move) < 0.25 * np.linalg.norm(cell_px), (move, estimate)


def test_response_at_reads_the_map_between_cells(car4_first):
    """At the window centre response_at is the map's cell (0, 0); half a cell to the right the mean of cells
    (0, 0) and (0, 1); beyond the search region 0 (the map is cyclic, and must not wrap around)."""
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    translation_filter = _learned(frame, box)
    translation_filter.estimate(ImagePyramid(to_gray(shifted(frame, 3.0, 2.0))), centre, size)
    response, _, cell_px, _ = translation_filter._response
    assert translation_filter.response_at(centre) == pytest.approx(response[0, 0])
    half_cell = centre + [cell_px[0] / 2.0, 0.0]
    assert translation_filter.response_at(half_cell) == pytest.approx((response[0, 0] + response[0, 1]) / 2.0)
    assert translation_filter.response_at(centre + 2.0 * size) == 0.0


def test_update_learns_the_tracked_window(car4_first):
    """With learning rate 1 the sample at the tracked window replaces the filter: on a frame moved by (6, 4)
    and updated there, the filter then finds no move from the new centre."""
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    translation_filter = _learned(frame, box, learning_rate=1.0)
    moved = ImagePyramid(to_gray(shifted(frame, 6.0, 4.0)))
    new_centre = centre + translation_filter.estimate(moved, centre, size)
    translation_filter.update(moved, new_centre, size)
    assert np.linalg.norm(translation_filter.estimate(moved, new_centre, size)) < 0.5


def test_invalid_use_is_refused():
    pyramid = ImagePyramid(np.zeros((64, 64), np.float32))
    with pytest.raises(RuntimeError, match="before init"):
        TranslationFilter().estimate(pyramid, (32, 32), (16, 16))
    translation_filter = TranslationFilter()
    translation_filter.init(pyramid, (32, 32), (16, 16))
    with pytest.raises(RuntimeError, match="needs an estimate"):
        translation_filter.response_at((32, 32))
    for kwargs, message in [({"padding": -1.0}, "padding"), ({"learning_rate": 0.0}, "learning_rate")]:
        with pytest.raises(ValueError, match=message):
            TranslationFilter(**kwargs)
    with pytest.raises(ValueError, match=r"translation_weight must be in \[0, 100\]"):
        TrackerConfig(translation_weight=-1.0)


def test_the_tracker_adds_the_filter_start_and_follows_a_shift(car4_first):
    """Car4's frame moved by (9, -6): with the filter the tracker searches from one more start and ends on the
    moved target; translation_weight 0 builds no filter (two starts: the prediction and the flow)."""
    frame, box = car4_first
    moved = shifted(frame, 9.0, -6.0)
    for weight, starts in [(1.0, 3), (0.0, 2)]:
        tracker = IemdTracker(TrackerConfig(translation_weight=weight))
        tracker.init(frame, box)
        result = tracker.update(moved)
        assert result.starts == starts
        assert np.allclose(result.box[:2], box[:2] + [9.0, -6.0], atol=1.5), (weight, result.box)


def test_the_score_weighs_the_filter_response_against_the_emd(car4_first, monkeypatch):
    """The search keeps the descended window of lowest EMD / background EMD - translation_weight x response.  A
    stand-in filter points at a decoy 30 px right of the target's true move (9, -6) and responds only there: with a
    negligible weight the EMD's window on the target is kept, with weight 1 the decoy's."""
    frame, box = car4_first
    moved = shifted(frame, 9.0, -6.0)
    decoy = box_centre(box) + [39.0, -6.0]
    results = {}
    for weight in (1e-6, 1.0):
        tracker = IemdTracker(TrackerConfig(translation_weight=weight, update_templates=False))
        tracker.init(frame, box)
        monkeypatch.setattr(tracker._translation_filter, "estimate", lambda pyramid, centre, *_: decoy - centre)
        monkeypatch.setattr(tracker._translation_filter, "response_at",
                            lambda point: float(np.exp(-np.sum((np.asarray(point) - decoy) ** 2) / 50.0)))
        results[weight] = tracker.update(moved)
    on_target = np.asarray(box[:2]) + [9.0, -6.0]
    assert np.allclose(results[1e-6].box[:2], on_target, atol=1.5), results[1e-6].box
    assert np.linalg.norm(np.asarray(results[1.0].box[:2]) - on_target) > 20.0, results[1.0].box
