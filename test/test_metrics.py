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

"""Hand-computed checks of the OTB metrics (iemd_ros.evaluation.metrics)."""
from iemd_ros.evaluation.metrics import (
    average_overlap,
    center_error,
    fraction_above,
    iou,
    OTB_THRESHOLDS,
    paired_difference,
    precision_at,
    score_sequence,
    success_auc,
    success_curve,
    valid_boxes,
)
import numpy as np
import pytest

A = (0.0, 0.0, 10.0, 10.0)


@pytest.mark.parametrize(
    'b, expected',
    [
        ((0, 0, 10, 10), 1.0),                 # identical
        ((5, 5, 10, 10), 25 / 175),            # partial: 5x5 inside, union 100 + 100 - 25
        ((5, 0, 10, 10), 50 / 150),            # half shifted
        ((2, 2, 4, 4), 16 / 100),              # containment
        ((-5, -5, 20, 20), 100 / 400),         # contains A
        ((20, 20, 5, 5), 0.0),                 # disjoint
        ((10, 0, 10, 10), 0.0),                # touching edge: no area
        ((2.5, 0, 10, 10), 75 / 125),          # sub-pixel shift
        ((np.nan, 0, 10, 10), 0.0),            # NaN box
        ((0, 0, 0, 10), 0.0),                  # zero width
        ((0, 0, 10, -3), 0.0),                 # negative height
    ],
)
def test_iou_hand_cases(b, expected):
    assert iou(A, b)[0] == pytest.approx(expected)
    assert iou(b, A)[0] == pytest.approx(expected)  # symmetric


def test_iou_matches_otb_pixel_inclusive_case():
    # OTB calcRectInt on 1-based pixels (1,1,3,3) and (2,2,3,3): columns 2..3 and rows 2..3 overlap
    # -> 4 px.
    assert iou((1, 1, 3, 3), (2, 2, 3, 3))[0] == pytest.approx(4 / 14)


def test_iou_vectorized_and_broadcast():
    b = np.array([[0, 0, 10, 10], [5, 5, 10, 10], [20, 20, 5, 5], [np.nan] * 4])
    out = iou(np.repeat([A], 4, axis=0), b)
    np.testing.assert_allclose(out, [1.0, 1 / 7, 0.0, 0.0])
    np.testing.assert_allclose(iou(A, b), out)  # one box against N
    assert out.shape == (4,)


def test_iou_rejects_bad_shapes():
    with pytest.raises(ValueError, match='shape'):
        iou([1, 2, 3], A)
    with pytest.raises(ValueError, match='different lengths'):
        iou(np.zeros((3, 4)), np.ones((2, 4)))


def test_valid_boxes():
    np.testing.assert_array_equal(
        valid_boxes([[0, 0, 1, 1], [0, 0, 0, 1], [np.nan, 0, 1, 1], [0, 0, 1, np.inf]]),
        [True, False, False, False],
    )


def test_center_error():
    np.testing.assert_allclose(
        center_error(A, [[3, 4, 10, 10], [0, 0, 10, 10], [0, 0, 20, 20]]),
        [5.0, 0.0, np.hypot(5, 5)],
    )
    assert center_error(A, (np.nan, 0, 1, 1))[0] == np.inf
    assert center_error((0, 0, 0, 0), A)[0] == np.inf  # OpenCV's failure box


def test_success_curve_is_strict():
    ious = np.array([0.0, 0.3, 0.5, 1.0])
    np.testing.assert_allclose(
        success_curve(ious, [0.0, 0.3, 0.5, 0.99, 1.0]), [0.75, 0.5, 0.25, 0.25, 0.0]
    )


def test_success_auc_on_hand_arrays():
    assert len(OTB_THRESHOLDS) == 21
    assert success_auc(np.ones(5)) == pytest.approx(20 / 21)  # overlap 1 passes every t < 1
    assert success_auc(np.zeros(5)) == 0.0
    assert success_auc([0.52]) == pytest.approx(11 / 21)  # t = 0, 0.05, ..., 0.5
    assert success_auc([0.52, 0.0]) == pytest.approx(11 / 42)


def test_auc_tends_to_average_overlap():
    ious = np.random.default_rng(0).uniform(0, 1, 200)
    assert success_auc(ious, np.linspace(0, 1, 20001)) == pytest.approx(
        average_overlap(ious), abs=1e-3
    )
    assert abs(success_auc(ious) - average_overlap(ious)) < 0.05  # 21 thresholds: close, not equal


def test_precision_and_fractions():
    assert precision_at([0.0, 20.0, 20.1, np.inf]) == 0.5  # <= 20 px
    assert precision_at([0.0, 5.0, 9.0], 5) == pytest.approx(2 / 3)
    ious = [0.0, 0.3, 0.5]
    assert average_overlap(ious) == pytest.approx(0.8 / 3)
    assert fraction_above(ious, 0) == pytest.approx(2 / 3)
    assert fraction_above(ious, 0.4) == pytest.approx(1 / 3)
    assert fraction_above([0.4], 0.4) == 0.0  # strictly greater


def test_empty_or_nan_inputs_raise():
    with pytest.raises(ValueError, match='empty'):
        average_overlap([])
    with pytest.raises(ValueError, match='NaN'):
        success_auc([0.5, np.nan])


def test_score_sequence_excludes_absent_gt_frames():
    gt = np.array([[0, 0, 10, 10], [5, 5, 10, 10], [np.nan] * 4, [0, 0, 10, 10]])
    pred = np.array([[0, 0, 10, 10], [0, 0, 10, 10], [0, 0, 10, 10], [0, 0, 0, 0]])
    s = score_sequence(pred, gt, 'toy', fps=12.5)
    assert (s.n_frames, s.n_absent) == (3, 1)
    assert s.average_overlap == pytest.approx((1 + 1 / 7 + 0) / 3)
    assert s.precision_20 == pytest.approx(2 / 3)  # centre errors 0, 7.07, inf
    assert s.overlap_gt_0 == pytest.approx(2 / 3)
    assert s.overlap_gt_04 == pytest.approx(1 / 3)
    assert s.success_auc == pytest.approx(np.mean(s.success_curve))
    assert s.fps == 12.5 and s.to_dict()['name'] == 'toy'
    assert s.recall == s.average_overlap  # every frame reported
    # the recall counts a frame reported lost as a miss whatever its box, and skips an absent one
    lost = score_sequence(pred, gt, 'toy', reported=[True, False, False, True])
    assert lost.recall == pytest.approx((1 + 0 + 0) / 3)
    assert lost.average_overlap == s.average_overlap


def test_score_sequence_errors():
    with pytest.raises(ValueError, match='2 predicted boxes for 3'):
        score_sequence(np.zeros((2, 4)), np.ones((3, 4)), 'x')
    with pytest.raises(ValueError, match='no frame has a valid'):
        score_sequence(np.zeros((2, 4)), np.full((2, 4), np.nan), 'x')
    with pytest.raises(ValueError, match='3 report flags for 2'):
        score_sequence(np.zeros((2, 4)), np.ones((2, 4)), 'x', reported=[True] * 3)


def test_a_gain_on_every_run_has_a_tight_interval_and_one_sequence_alone_does_not():
    reference = np.arange(50.0).reshape(10, 5)
    shifted = paired_difference(reference + 2.0, reference)
    assert (shifted.mean, shifted.low, shifted.high) == pytest.approx((2.0, 2.0, 2.0))
    assert (shifted.better, shifted.worse, shifted.equal) == (50, 0, 0)
    # one sequence far better, the nine others a little worse: the mean is positive, the interval
    # over sequences is not
    ours = reference - 1.0
    ours[3] += 21.0
    lucky = paired_difference(ours, reference)
    assert lucky.mean == pytest.approx((5 * 20 - 45) / 50)
    assert lucky.low < 0 < lucky.high
    assert (lucky.better, lucky.worse, lucky.equal) == (5, 45, 0)
    # the draws are seeded: the same inputs give the same interval
    assert paired_difference(ours, reference) == lucky
    ties = paired_difference(reference, reference)
    assert (ties.mean, ties.equal) == (0.0, 50)


def test_a_paired_difference_gives_each_sequence_its_own_mean():
    reference = np.zeros((3, 4))
    ours = np.array([[1.0, 3.0, 1.0, 3.0], [0.0, 0.0, 0.0, -4.0], [0.0, 0.0, 0.0, 0.0]])
    assert paired_difference(ours, reference).per_sequence == pytest.approx((2.0, -1.0, 0.0))


def test_a_paired_difference_gives_each_start_its_mean_over_the_sequences():
    reference = np.zeros((3, 4))
    ours = np.array([[1.0, 3.0, 1.0, 3.0], [0.0, 0.0, 0.0, -4.0], [2.0, 0.0, 0.0, -2.0]])
    assert paired_difference(ours, reference).per_start == pytest.approx((1.0, 1.0, 1 / 3, -1.0))


@pytest.mark.parametrize(
    'ours, reference, kwargs, message',
    [
        (np.zeros(5), np.zeros(5), {}, 'sequences, starts'),
        (np.zeros((2, 3)), np.zeros((3, 2)), {}, 'one shape'),
        (np.zeros((0, 3)), np.zeros((0, 3)), {}, 'one shape'),
        (np.full((2, 2), np.nan), np.zeros((2, 2)), {}, 'finite'),
        (np.zeros((2, 2)), np.zeros((2, 2)), {'resamples': 0}, 'resamples'),
    ],
)
def test_paired_difference_refuses_what_it_cannot_compare(ours, reference, kwargs, message):
    with pytest.raises(ValueError, match=message):
        paired_difference(ours, reference, **kwargs)
