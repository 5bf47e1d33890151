"""The DSST scale filter (iemd_ros/scale_filter.py) and the tracker's use of it."""
import numpy as np
import pytest
from helpers import zoomed

from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.tracking.appearance import ImagePyramid, to_gray
from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking.scale_filter import ScaleFilter


def test_the_scaled_windows_are_the_windows_sampled_one_by_one(car4_first):
    frame, box = car4_first
    pyramid = ImagePyramid(to_gray(frame))
    factors = 1.02 ** np.arange(-2, 3)  # these share the unscaled window's anti-aliasing level
    for angle in (0.0, 0.6):
        stacked = pyramid.sample_scales(box_centre(box), box[2:], (24, 20), factors, angle)
        one_by_one = [pyramid.sample(box_centre(box), box[2:] * f, (24, 20), angle) for f in factors]
        np.testing.assert_allclose(stacked, np.stack(one_by_one), atol=1e-4)


def test_recovers_a_known_scale_change_of_a_real_window(car4_first):
    """Learned on Car4's target, the filter measures the target against windows 10 % too small or too
    large (1/0.9 = 1.111 and 1/1.1 = 0.909), and against a frame magnified by 6 %."""
    frame, box = car4_first
    pyramid, centre, size = ImagePyramid(to_gray(frame)), box_centre(box), box[2:]
    scale_filter = ScaleFilter()
    scale_filter.init(pyramid, centre, size)
    assert scale_filter.estimate(pyramid, centre, size) == pytest.approx(1.0, abs=1e-9)
    for window in (0.9, 1.1):
        assert scale_filter.estimate(pyramid, centre, size * window) == pytest.approx(1.0 / window, rel=0.025)
    bigger = ImagePyramid(to_gray(zoomed(frame, centre, 1.06)))
    assert scale_filter.estimate(bigger, centre, size) == pytest.approx(1.06, rel=0.015)


def test_update_learns_at_the_estimated_scale(car4_first):
    """update() learns the last estimate's sample with its desired response centred on the estimated
    scale: after learning the 6 % larger target, that target is measured at scale 1 from its own size."""
    frame, box = car4_first
    pyramid, centre, size = ImagePyramid(to_gray(frame)), box_centre(box), box[2:]
    scale_filter = ScaleFilter(learning_rate=1.0)  # the new sample replaces the filter
    scale_filter.init(pyramid, centre, size)
    bigger = ImagePyramid(to_gray(zoomed(frame, centre, 1.06)))
    scale = scale_filter.estimate(bigger, centre, size)
    scale_filter.update()
    assert scale_filter.estimate(bigger, centre, size * scale) == pytest.approx(1.0, abs=0.01)
    scale_filter.update()
    with pytest.raises(RuntimeError, match="needs an estimate"):  # each estimate is learned at most once
        scale_filter.update()


def test_update_learns_at_the_scale_the_tracker_took(car4_first):
    """An estimate limited by ``bounds`` (the tracker's bounds on the window) is what update() learns: told that
    the 6 % larger target may be at most at scale 1, the filter then measures it at scale 1 from the original
    window's size."""
    frame, box = car4_first
    pyramid, centre, size = ImagePyramid(to_gray(frame)), box_centre(box), box[2:]
    scale_filter = ScaleFilter(learning_rate=1.0)
    scale_filter.init(pyramid, centre, size)
    bigger = ImagePyramid(to_gray(zoomed(frame, centre, 1.06)))
    assert scale_filter.estimate(bigger, centre, size) == pytest.approx(1.06, rel=0.015)
    assert scale_filter.estimate(bigger, centre, size, bounds=(0.5, 1.0)) == pytest.approx(1.0, abs=1e-12)
    scale_filter.update()
    assert scale_filter.estimate(bigger, centre, size) == pytest.approx(1.0, abs=0.01)


def test_invalid_use_is_refused():
    with pytest.raises(RuntimeError, match="before init"):
        ScaleFilter().estimate(ImagePyramid(np.zeros((64, 64), np.float32)), (32, 32), (16, 16))
    for kwargs, message in [({"n_scales": 4}, "odd"), ({"scale_step": 1.0}, "> 1"), ({"learning_rate": 0}, "learning_rate must be")]:
        with pytest.raises(ValueError, match=message):
            ScaleFilter(**kwargs)
    with pytest.raises(ValueError, match="scale_estimator must be one of filter, emd"):
        TrackerConfig(scale_estimator="dsst")


def test_the_tracker_follows_a_zoom_the_emd_variants_cannot(car4_first):
    """Car4's frame magnified by 8 % about the target: the filter takes the window to 1.08 in one frame; the
    paper's EMD variants move at most scale_range (2 %) per frame, and scale_step 0 keeps the size."""
    frame, box = car4_first
    scales = {}
    for estimator, step in [("filter", 0.02), ("emd", 0.02), ("filter", 0.0)]:
        tracker = IemdTracker(TrackerConfig(scale_estimator=estimator, scale_step=step, update_templates=False))
        tracker.init(frame, box)
        scales[estimator, step] = tracker.update(zoomed(frame, box_centre(box), 1.08)).scale
    assert scales["filter", 0.02] == pytest.approx(1.08, rel=0.02)
    assert 1.0 <= scales["emd", 0.02] <= 1.02 + 1e-12
    assert scales["filter", 0.0] == 1.0
