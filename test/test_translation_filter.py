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
The translation filter (STRCF) and the tracker's use of its response.

The filter is iemd_ros/tracking/translation_filter.py.
"""
import cv2
from helpers import shifted, texture
from iemd_ros import IemdTracker, TrackerConfig
from iemd_ros.common.boxes import box_centre
from iemd_ros.tracking import features
from iemd_ros.tracking.tracker import _is_colour
from iemd_ros.tracking.translation_filter import CN_WEIGHT, TranslationFilter
import numpy as np
import pytest


def _learned(frame, box, angle=0.0):
    translation_filter = TranslationFilter()
    translation_filter.init(
        frame,
        box_centre(box),
        box[2:],
        colour=_is_colour(frame),  # the tracker's own rule
        angle=angle,
    )
    return translation_filter


@pytest.mark.parametrize('angle', [0.0, np.pi / 2, 0.6])
def test_recovers_a_known_shift_of_a_real_texture(car4_first, angle):
    """
    Car4's frame moved by known shifts, up to 2.5 cells.

    The filter learned on the target (in a region turned by ``angle``) finds the move in image
    pixels to within a quarter of a cell (12 image px here: the 483 px region resampled to 160 px)
    by the refinement of its peak.
    """
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    tf = _learned(frame, box, angle)
    cell_px = features.CELL * tf._scale(size)
    assert (
        np.linalg.norm(
            tf.estimate(tf.sample(frame, centre, size, angle))
            - (np.round(centre) - centre if angle == 0 else 0)
        )
        < 0.1 * cell_px
    )
    for move in [(5.0, 3.0), (-8.0, 2.0), (0.0, -10.0), (-20.0, 14.0)]:
        estimate = tf.estimate(tf.sample(shifted(frame, *move), centre, size, angle))
        assert np.linalg.norm(estimate - move) < cell_px / 4, (move, estimate, cell_px)
    assert tf.confidence['peak'] > 0 and tf.confidence['apce'] > 1


@pytest.mark.parametrize('colour', [True, False])
def test_the_sample_weighs_colour_names_against_fhog_and_grey(colour):
    """
    The region's features are grey, fHOG and Colour Names times the cosine window.

    A smooth random colour texture (and its grey version): the inverse transform of the sample's
    spectrum is ``features.extract`` of the resampled region times the separable Hann window, its
    Colour Names channels times ``CN_WEIGHT``, the other channels times 1; a grey frame has no
    Colour Names channel.
    """
    from iemd_ros.tracking.correlation_filter import hann_inner, sample_region
    from scipy import fft as sfft

    rng = np.random.default_rng(3)
    frame = cv2.GaussianBlur(rng.integers(0, 256, (240, 320, 3), dtype=np.uint8), (0, 0), 3)
    if not colour:
        frame = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    centre, size = np.array([161.0, 118.0]), np.array([40.0, 30.0])
    tf = TranslationFilter()
    tf.init(frame, centre, size, colour=colour)
    region = tf.sample(frame, centre, size)
    side = tf.support * region.scale
    patch = sample_region(frame, region.pos, (side, side), (tf.support, tf.support))
    expected = features.extract(patch, colour)
    assert len(expected) == (42 if colour else 32)
    expected *= (hann_inner(tf.map_hw[0])[:, None] * hann_inner(tf.map_hw[1])[None, :])[None]
    expected[features.CN_START:] *= CN_WEIGHT
    got = sfft.irfft2(region.zf, s=tf.map_hw)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-5 * np.abs(expected).max())


def _red_square_on_green(shape=(240, 320), box=(140, 100, 41, 33)):
    """Return a red rectangle at ``box`` on a green frame, a grey texture in both (BGR)."""
    frame = np.repeat(texture(seed=5, shape=shape)[..., None] // 4, 3, axis=2)
    frame[..., 1] += 160
    x, y, w, h = box
    frame[y:y + h, x:x + w, 1] -= 160
    frame[y:y + h, x:x + w, 2] += 160
    return frame


def test_a_colour_model_adds_its_score_averaged_over_each_cell_as_one_more_channel():
    """
    With a colour model the sample has one channel more, weighed as grey: beta per cell, less 1/2.

    A red rectangle on green, both textured, sized so that the region is not resampled: the model's
    beta is 1 on the rectangle's colours and 0 on the green's, so the last channel of the sample,
    over the cosine window, is the share of a cell's pixels on the rectangle less 1/2 (counted here
    from the region's red channel).  The estimate's sample and a new sample of the same region,
    which the filter learns from when the estimate's cannot be shifted, are the same; without the
    model there are 42.
    """
    from iemd_ros.tracking.colour_model import ColourModel
    from iemd_ros.tracking.correlation_filter import hann_inner
    from scipy import fft as sfft

    box = (140, 100, 33, 29)  # 25 w h within [150^2, 160^2]: no resampling
    frame = _red_square_on_green(box=box)
    centre, size = box_centre(box), np.array(box[2:], float)
    model = ColourModel()
    model.init(frame, centre, size)
    tf = TranslationFilter()
    tf.init(frame, centre, size, colour=True, colour_model=model)
    plain = TranslationFilter()
    plain.init(frame, centre, size, colour=True)
    assert (tf.n_channels, plain.n_channels) == (43, 42)
    assert tf._scale(size) == 1.0
    region = tf.sample(frame, centre, size)
    tf.estimate(region)
    got = sfft.irfft2(tf._detection.zf, s=tf.map_hw)
    assert len(got) == 43
    on_red = (region.patch[..., 2] > region.patch[..., 1]).astype(float)
    n = tf.map_hw[0]
    share = on_red[:n * 4, :n * 4].reshape(n, 4, n, 4).mean(axis=(1, 3))
    assert 0.0 < share.mean() < 0.2 and share.max() == 1.0  # the region holds both colours
    window = hann_inner(n)[:, None] * hann_inner(n)[None, :]
    np.testing.assert_allclose(got[-1], (share - 0.5) * window, atol=1e-4)
    again = tf._spectrum(frame, region.pos, region.scale, region.angle)
    np.testing.assert_allclose(again, tf._detection.zf, atol=1e-3)


def test_a_frame_is_scored_by_the_colour_model_as_it_was_at_the_estimate():
    """
    The colour model learns on a worker thread while the filter learns from the same frame.

    Two filters learned alike, each with its colour model; between the estimate and the update on
    the next frame (at 1.2 times the size, so the filter takes a new sample rather than shifting
    the estimate's), one model learns a frame all in the rectangle's red, which lowers red's beta
    from 1 to 1 / 1.5.  Both filters learn the same filter: the new sample takes beta from the
    model as it was at the estimate.  With the model after learning its colour channel differs.
    """
    from iemd_ros.tracking.colour_model import ColourModel

    box = (140, 100, 41, 33)
    frame = _red_square_on_green(box=box)
    centre, size = box_centre(box), np.array(box[2:], float)
    red = frame.copy()
    red[..., 1], red[..., 2] = frame[..., 0], frame[..., 0] + 160
    moved, at = shifted(frame, 3.0, -2.0), centre + (3.0, -2.0)
    filters = []
    for learns in (False, True):
        model = ColourModel(learning_rate=0.5)
        model.init(frame, centre, size)
        tf = TranslationFilter()
        tf.init(frame, centre, size, colour=True, colour_model=model)
        tf.estimate(tf.sample(moved, centre, size))
        if learns:
            model.update(red, centre, size)
        tf.update(moved, at, size * 1.2)
        filters.append(tf.f)
    np.testing.assert_array_equal(filters[0], filters[1])
    patch = tf._patch(moved, np.round(at), tf._scale(size * 1.2), 0.0)
    at_estimate = tf._colour_channel(patch, tf._scores)
    assert not np.allclose(tf._colour_channel(patch, model.pixel_scores()), at_estimate, atol=0.05)


def test_a_grey_frame_in_a_colour_stream_is_tracked_with_the_colour_channel():
    """
    A grey frame in a colour stream (a camera switching modes) is answered.

    The filter's colour channel scores its levels as colours; on the next colour frame, whose
    filter estimate may be confident with no colour estimate since the first frame, the tracker
    follows the target.
    """
    box = (140, 100, 41, 33)
    frame = _red_square_on_green(box=box)
    tracker = IemdTracker()
    tracker.init(frame, box)
    assert tracker._translation_filter.n_channels == 43
    tracker.update(cv2.cvtColor(shifted(frame, 3.0, 0.0), cv2.COLOR_BGR2GRAY))
    result = tracker.update(shifted(frame, 6.0, 0.0))
    assert abs(result.box[0] - 146.0) < 2.0, result.box


def test_response_at_reads_the_map_between_cells(car4_first):
    """
    At the region's centre response_at is the map's cell (0, 0).

    Half a cell to the right the mean of cells (0, 0) and (0, 1); the map is circular over the
    search region.
    """
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    tf = _learned(frame, box)
    with pytest.raises(RuntimeError, match='needs an estimate'):
        TranslationFilter().response_at(centre)
    tf.estimate(tf.sample(shifted(frame, 3.0, 2.0), centre, size))
    response, pos, cell_px, _ = tf._response
    assert tf.response_at(pos) == pytest.approx(response[0, 0])
    assert tf.response_at(pos + [cell_px / 2.0, 0.0]) == pytest.approx(
        (response[0, 0] + response[0, 1]) / 2.0
    )
    n = tf.map_hw[0]
    assert tf.response_at(pos + [n * cell_px, 0.0]) == pytest.approx(response[0, 0])


def test_update_learns_the_tracked_window(car4_first):
    """
    Learned again on a frame moved by (6, 4) at the window it found there.

    The filter finds (almost) no move from the new centre: the temporal term keeps a share of the
    old filter.
    """
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    tf = _learned(frame, box)
    moved = shifted(frame, 6.0, 4.0)
    new_centre = centre + tf.estimate(tf.sample(moved, centre, size))
    assert np.linalg.norm(new_centre - centre - (6.0, 4.0)) < 1.5
    tf.update(moved, new_centre, size)
    again = tf.estimate(tf.sample(moved, new_centre, size))
    assert np.linalg.norm(again - (np.round(new_centre) - new_centre)) < 1.0


def test_a_region_sampled_before_the_filter_learns_estimates_as_one_sampled_after(car4_first):
    """
    The tracker samples the next frame's region while the filter still learns from the last one.

    So :meth:`TranslationFilter.sample` must not read the filter: a region sampled before an
    update holds the same spectrum as one sampled after it, and the updated filter estimates the
    same move on both.
    """
    frame, box = car4_first
    centre, size = box_centre(box), box[2:]
    tf = _learned(frame, box)
    moved = shifted(frame, 5.0, -3.0)
    before = tf.sample(moved, centre, size)
    tf.update(shifted(frame, 1.0, 1.0), centre, size)  # a learning step changes the filter
    after = tf.sample(moved, centre, size)
    assert np.array_equal(before.zf, after.zf)
    assert np.array_equal(tf.estimate(before), tf.estimate(after))
    assert np.linalg.norm(tf.estimate(after) - (5.0, -3.0)) < 1.5


def test_the_tracker_adds_the_filter_start_and_follows_a_shift(car4_first):
    """
    Car4's frame moved by (9, -6).

    With the filter the tracker searches from one more start and ends on the moved target;
    translation_weight 0 builds no filter (two starts: the prediction and the flow).
    """
    frame, box = car4_first
    moved = shifted(frame, 9.0, -6.0)
    for weight, starts in [(1.0, 3), (0.0, 2)]:
        tracker = IemdTracker(TrackerConfig(translation_weight=weight))
        tracker.init(frame, box)
        result = tracker.update(moved)
        assert result.starts == starts
        assert np.allclose(result.box[:2], box[:2] + [9.0, -6.0], atol=1.5), (weight, result.box)


def test_the_score_weighs_the_filter_response_against_the_emd(car4_first, monkeypatch):
    """
    The search's score weighs the filter's response against the EMD.

    The search keeps the descended window of lowest EMD / background EMD - translation_weight x
    response.  A stand-in filter points at a decoy 30 px right of the target's true move (9, -6)
    and responds only there (its own estimate still runs, for the response's peak and APCE): with a
    negligible weight the EMD's window on the target is kept, with weight 1 the decoy's.
    """
    frame, box = car4_first
    moved = shifted(frame, 9.0, -6.0)
    decoy = box_centre(box) + [39.0, -6.0]
    results = {}
    for weight in (1e-6, 1.0):
        tracker = IemdTracker(TrackerConfig(translation_weight=weight, update_templates=False))
        tracker.init(frame, box)
        estimate = tracker._translation_filter.estimate
        monkeypatch.setattr(
            tracker._translation_filter,
            'estimate',
            lambda region, estimate=estimate: (estimate(region), decoy - region.center)[1],
        )
        monkeypatch.setattr(
            tracker._translation_filter,
            'response_at',
            lambda point: float(np.exp(-np.sum((np.asarray(point) - decoy) ** 2) / 50.0)),
        )
        results[weight] = tracker.update(moved)
    on_target = np.asarray(box[:2]) + [9.0, -6.0]
    assert np.allclose(results[1e-6].box[:2], on_target, atol=1.5), results[1e-6].box
    assert np.linalg.norm(np.asarray(results[1.0].box[:2]) - on_target) > 20.0, results[1.0].box


def test_search_frame_finds_the_target_moved_anywhere_in_a_drone_frame(uav_root):
    """
    building5's first 1280x720 frame with the person moved by up to 400 px.

    The whole-frame search, its strips taken in turn, puts the strongest response within one cell
    of her (a cell is 4 px of the resampled frame), and its strips cover the frame once.
    """
    from iemd_ros.datasets.otb import load_sequence, read_frame

    seq = load_sequence(uav_root / 'building5')
    frame, box = read_frame(seq.frame_paths[0]), np.asarray(seq.gt_boxes[0], float)
    tf = _learned(frame, box)
    cell_px = tf.cell_size(box[2:])
    for move in [(0.0, 0.0), (400.0, -150.0), (-300.0, -350.0)]:  # she is at (540, 555)
        moved = shifted(frame, *move)
        parts = tf.frame_strip(moved, box[2:], 0).parts
        assert parts > 1  # a 1280x720 frame is searched over several lost frames
        found = max(
            (tf.search_frame(tf.frame_strip(moved, box[2:], part)) for part in range(parts)),
            key=lambda r: r[1],
        )[0]
        assert np.linalg.norm(found - (box_centre(box) + move)) < 1.5 * cell_px, (move, found)


def test_the_frame_response_is_the_linear_correlation_of_each_strip(uav_root, monkeypatch):
    """
    Each strip's response is the cropped filter's linear correlation over it, done directly.

    building5's first 1280x720 frame at a scale with several strips (the first and last cut by
    the frame's edges): the strip's features, the Colour Names times ``CN_WEIGHT``, correlated
    with the spatial filter cropped to the target's cells, channel by channel, by
    ``scipy.signal.correlate`` (zero outside the strip), kept over the strip's own cells inside the
    frame; the FFT's wrap may touch none of them.  The crop keeps nearly all the filter's energy.
    ``search_frame`` is the response's peak.
    """
    from iemd_ros.datasets.otb import read_frame, load_sequence
    from scipy import fft as sfft, signal

    seq = load_sequence(uav_root / 'building5')
    frame, box = read_frame(seq.frame_paths[0]), np.asarray(seq.gt_boxes[0], float)
    tf = _learned(frame, box)
    size = box[2:] * 0.5  # the frame at a larger scale: more strips
    strips = []
    extract = features.extract
    # the features as extracted (the strip keeps a copy)
    monkeypatch.setattr(
        features, 'extract', lambda *a: strips.append(extract(*a)) or strips[-1].copy()
    )
    parts = tf.frame_strip(frame, size, 0).parts
    assert parts >= 3
    h = sfft.irfft2(tf.f, s=tf.map_hw, axes=(1, 2))
    crop = h[(slice(None),) + tf.target_cells]
    assert (crop ** 2).sum() > 0.9 * (h ** 2).sum()  # 0.94 on this first frame
    # the crop's cell answering for the target's centre (the full filter's centre cell)
    oy, ox = (k // 2 - t.start for k, t in zip(tf.map_hw, tf.target_cells))
    for part in range(parts):
        strips.clear()
        strip = tf.frame_strip(frame, size, part)
        resp, first, cell_px = tf.frame_response(strip), strip.first, strip.cell_px
        z = strips[0]
        z[features.CN_START:] *= CN_WEIGHT
        lo = max(first - ox, 0)
        direct = sum(signal.correlate(z[c], crop[c], mode='full') for c in range(len(z)))
        # full[p, q]: the shift (p - m + 1, q - l + 1) of an m x l crop; cell i answers at i - oy
        m, l_ = crop.shape[1:]
        rows, cols = resp.shape
        kept = direct[m - 1 - oy:][:rows, l_ - 1 - ox + first - lo:][:, :cols]
        assert kept.shape == resp.shape and rows * cell_px[1] == pytest.approx(frame.shape[0])
        np.testing.assert_allclose(resp, kept, rtol=0, atol=1e-5 * np.abs(kept).max())
        centre, value = tf.search_frame(strip)
        k = np.unravel_index(np.argmax(resp), resp.shape)
        assert value == resp[k]
        np.testing.assert_allclose(centre, (np.array([k[1] + first, k[0]]) + 0.5) * cell_px - 0.5)
    assert first + cols == int(frame.shape[1] / cell_px[0] + 0.5)  # the last strip: to the edge
