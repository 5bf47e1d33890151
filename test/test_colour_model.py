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
Staple's colour histograms.

The per-pixel score beta, the window means, the start, the mean-shift step and the tracker's use.
"""
from helpers import run_python, shifted, texture
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.datasets.otb import load_sequence, read_frame
from iemd_ros.evaluation.metrics import iou
from iemd_ros.tracking.colour_model import ColourModel
import numpy as np
import pytest

RED, GREEN, BLUE = (0, 0, 255), (0, 255, 0), (255, 0, 0)  # BGR


def _scene(shape=(120, 160), background=GREEN, target=RED, box=(60, 40, 21, 31)):
    frame = np.empty((*shape, 3), np.uint8)
    frame[:] = background
    x, y, w, h = box
    frame[y:y + h, x:x + w] = target
    return frame


def test_beta_is_the_share_of_a_colour_on_the_target_and_windows_average_it():
    """
    Target all red, surroundings all green.

    beta(red) = 1, beta(green) = 0, so a window's mean is the share of it on red (hand-computed for
    the 21 x 31 px target: 1 on it, 16/21 5 px off, 1/2 half a width or height off, between the
    positions 10 and 11 px off; 0 on bare background and outside the region); a colour neither has
    scores 0.  (Odd sizes: the window's pixels then sit on image pixels, and nearest-neighbour
    sampling is exact.)
    """
    box = (60, 40, 21, 31)
    model = ColourModel(model_area=10**6)  # no resampling: model pixels are image pixels
    frame = _scene(box=box)
    model.init(frame, box_centre(box), box[2:])
    assert np.allclose(model.estimate(frame, box_centre(box), box[2:]), 0.0)
    c = box_centre(box)
    assert model.score_at(c) == pytest.approx(1.0)
    assert model.score_at(c + [10.5, 0.0]) == pytest.approx(0.5)
    assert model.score_at(c + [0.0, 15.5]) == pytest.approx(0.5)
    assert model.score_at(c + [5.0, 0.0]) == pytest.approx(16 / 21)
    assert model.score_at(c + [30.0, 0.0]) == pytest.approx(0.0)
    assert model.score_at(c + [500.0, 0.0]) == 0.0
    blue = _scene(background=BLUE, target=BLUE, box=box)
    model.estimate(blue, c, box[2:])
    assert model.score_at(c) == 0.0


def test_the_estimate_finds_the_moved_target_at_any_resampling_and_turn():
    """
    The red target moved by (17, -9) px is found within a model pixel.

    (half from nearest-neighbour sampling, half from the window's size rounded to model pixels),
    with and without resampling the region, and by a window turned by 90 degrees (its axes swap the
    target's width and height).
    """
    box, move = (60, 40, 21, 31), np.array([17.0, -9.0])
    moved = (box[0] + 17, box[1] - 9, *box[2:])
    first, second = _scene(box=box), _scene(box=moved)
    for model_area, angle, size in [
        (10**6, 0.0, box[2:]),
        (2048, 0.0, box[2:]),
        (10**6, np.pi / 2, box[:1:-1]),
    ]:
        model = ColourModel(model_area=model_area)
        model.init(first, box_centre(box), size, angle)
        estimate = model.estimate(second, box_centre(box), size, angle)
        region = 2.0 * np.asarray(size) + 2.0 * np.sqrt(21 * 31)
        tolerance = 1.0 / min(1.0, np.sqrt(model_area / np.prod(region))) + 1e-9
        assert np.allclose(estimate, move, atol=tolerance), (model_area, angle, estimate)
        assert model.score_at(box_centre(moved)) > 0.9


def test_the_mean_shift_step_is_the_beta_weighted_mean_of_the_window():
    """
    Target all red (beta 1), surroundings all green (beta 0).

    A 21 x 31 px window 5 px right of and 8 px below the target holds red on its columns -10 .. 5
    and rows -15 .. 7 from its centre, so its step is their mean, (-2.5, -4); on the target or on
    bare background it is (0, 0).  Resampled, and in a window turned by 90 degrees (its axes swap
    width and height), the same step in image pixels.
    """
    box = (60, 40, 21, 31)
    frame, c = _scene(box=box), box_centre(box)
    for model_area, angle, size in [
        (10**6, 0.0, box[2:]),
        (2048, 0.0, box[2:]),
        (10**6, np.pi / 2, box[:1:-1]),
    ]:
        model = ColourModel(model_area=model_area)
        model.init(frame, c, size, angle)
        assert np.allclose(model.mean_shift(frame, c + [5.0, 8.0], size, angle), [-2.5, -4.0])
        assert np.allclose(model.mean_shift(frame, c, size, angle), 0.0)
        assert np.allclose(model.mean_shift(frame, c + [40.0, 0.0], size, angle), 0.0)


def test_a_tracked_window_moves_toward_the_target_colours():
    """
    A red square on a grey texture, the first box 6 px right of and below it; 30 frames of it.

    Without the colour model's share (``colour_merge`` 0) the translation filter keeps the first
    box's offset; with the shipped share the window's centre moves toward the square's, ending
    nearer than 0.85 times the first offset (docs/decisions.md#colour-mean-shift).
    """
    scene = np.repeat(texture(seed=3)[..., None], 3, axis=2)
    scene[40:80, 50:90] = RED
    target, start = (50, 40, 40, 40), (56, 46, 40, 40)
    offsets = {}
    for merge in (0.0, TrackerConfig().colour_merge):
        tracker = IemdTracker(TrackerConfig(colour_merge=merge))
        tracker.init(scene, start)
        for _ in range(30):
            box = tracker.update(scene).box
        offsets[merge] = np.linalg.norm(box_centre(box) - box_centre(target))
    first = np.linalg.norm(box_centre(start) - box_centre(target))
    assert offsets[0.0] > 0.95 * first, offsets
    assert offsets[TrackerConfig().colour_merge] < 0.85 * first, offsets


def test_update_blends_the_histograms_at_the_learning_rate():
    """
    After the target turns blue, one update at rate 0.25 gives beta(blue) = 0.25 /.

    (0.25 + 0) = 1 and leaves beta(red) = 0.75 / 0.75 = 1 (neither colour is in the surroundings);
    the green surroundings stay at 0.
    """
    box = (60, 40, 21, 31)
    model = ColourModel(learning_rate=0.25, model_area=10**6)
    model.init(_scene(box=box), box_centre(box), box[2:])
    blue = _scene(target=BLUE, box=box)
    model.update(blue, box_centre(box), box[2:])
    model.estimate(blue, box_centre(box), box[2:])
    assert model.score_at(box_centre(box)) == pytest.approx(1.0)
    assert model.score_at(box_centre(box) + [10.5, 0.0]) == pytest.approx(0.5)


def test_pixel_scores_give_each_pixel_its_beta_and_keep_their_table():
    """
    Target red, surroundings green: a pixel scores 1 on red, 0 on green and on blue (on neither).

    After the target turns blue and the model learns at rate 0.25, a scorer made before still gives
    blue 0; one made after gives it 0.25 / (0.25 + 0) = 1, and red 0.75 / 0.75 = 1.
    """
    box = (60, 40, 21, 31)
    model = ColourModel(learning_rate=0.25, model_area=10**6)
    model.init(_scene(box=box), box_centre(box), box[2:])
    before = model.pixel_scores()
    patch = np.array([[RED, GREEN, BLUE], [BLUE, RED, RED]], np.uint8)
    np.testing.assert_array_equal(before(patch), [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    model.update(_scene(target=BLUE, box=box), box_centre(box), box[2:])
    np.testing.assert_array_equal(before(patch), [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    np.testing.assert_allclose(model.pixel_scores()(patch), [[1.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    # a grey patch reads as the colours of three equal levels: here none is in either histogram
    grey = np.array([[0, 128, 255]], np.uint8)
    np.testing.assert_array_equal(before(grey), [[0.0, 0.0, 0.0]])
    np.testing.assert_array_equal(before(grey[..., None]), before(np.dstack([grey] * 3)))


def test_invalid_parameters_and_calls_raise():
    for kwargs, message in [
        ({'padding': -1.0}, 'padding'),
        ({'learning_rate': 0.0}, 'learning_rate'),
        ({'bins': 20}, 'bins'),
        ({'bins': 128}, 'bins'),
    ]:
        with pytest.raises(ValueError, match=message):
            ColourModel(**kwargs)
    with pytest.raises(RuntimeError, match='before init'):
        ColourModel().estimate(_scene(), (70, 55), (20, 30))
    with pytest.raises(RuntimeError, match='before init'):
        ColourModel().mean_shift(_scene(), (70, 55), (20, 30))
    with pytest.raises(RuntimeError, match='before init'):
        ColourModel().pixel_scores()
    with pytest.raises(RuntimeError, match='estimate'):
        ColourModel().score_at((70, 55))
    with pytest.raises(ValueError, match=r'colour_weight must be in \[0, 100\]'):
        TrackerConfig(colour_weight=-1.0)
    with pytest.raises(ValueError, match=r'colour_merge must be in \[0, 1\]'):
        TrackerConfig(colour_merge=1.5)


def test_the_tracker_uses_colour_on_colour_frames_only():
    """
    A grey texture stored as BGR and a copy with the target tinted red, moved by 6 px.

    The colour model's peak is one more start on the colour frames only; colour_weight 0 builds no
    model, and a grey frame in a colour stream is tracked without it.
    """
    grey = np.repeat(texture(seed=3)[..., None], 3, axis=2)
    colour = grey.copy()
    colour[40:80, 50:90, 2] = 255
    box = (50, 40, 40, 40)
    for first, second, weight, starts in [
        (grey, grey, 1.0, 1),
        (colour, colour, 1.0, 2),
        (colour, colour, 0.0, 1),
        (colour, colour[..., 2], 1.0, 1),
    ]:
        tracker = IemdTracker(
            TrackerConfig(colour_weight=weight, flow_start=False, translation_weight=0.0)
        )
        tracker.init(first, box)
        result = tracker.update(shifted(second, 6.0, 0.0))
        assert result.starts == starts, (weight, second.ndim)
        if starts == 2:
            assert abs(result.box[0] - 56.0) < 1.0, result.box


def test_tracks_a_real_colour_otb_excerpt(otb_root):
    """
    Woman frames 1-100: average overlap > 0.7 (docs/decisions.md#test-bounds).

    A colour sequence, so the colour model is on and its start is searched, a fourth after the
    prediction, the flow and the translation filter.
    """
    seq = load_sequence(otb_root / 'Woman')
    tracker = IemdTracker()
    tracker.init(read_frame(seq.frame_paths[0]), seq.gt_boxes[0])
    results = [tracker.update(read_frame(path)) for path in seq.frame_paths[1:100]]
    overlap = iou(np.array([seq.gt_boxes[0]] + [r.box for r in results]), seq.gt_boxes[:100])
    assert max(r.starts for r in results) == 4
    assert overlap.mean() > 0.7, overlap.mean()


def test_the_warm_up_compiles_the_colour_models_kernels():
    """
    ``warm_up`` (``iemd-compile``, a pipeline's start) tracks a colour frame too.

    In a process of its own, after ``warm_up`` alone, the colour model's kernels are compiled (or
    loaded): a fresh install's first colour frame compiles nothing
    (docs/decisions.md#colour-model-kernels).
    """
    code = (
        'from iemd_ros.tracking import colour_model as c, tracker as t; t.warm_up(); '
        'print(all(k.signatures for k in (c._bin_index, c._fractions, c._blend)))'
    )
    done = run_python('-c', code, timeout=300)
    assert done.stdout.strip() == 'True', (done.stdout, done.stderr)
