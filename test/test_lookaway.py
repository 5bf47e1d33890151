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
Look-away-and-back sequences and the long-term measures.

(VOT LT precision, recall, F; false reports; returns).
"""
import json
from pathlib import Path

import cv2
from iemd_ros.apps.eval import main as eval_main
from iemd_ros.apps.make_lookaway import main as make_main
from iemd_ros.datasets.lookaway import look_away_windows, LookAway, write_look_away
from iemd_ros.datasets.otb import load_sequence, Sequence
from iemd_ros.evaluation.metrics import long_term_scores, REACQUIRE_WITHIN
from iemd_ros.evaluation.split import in_part
from iemd_ros.tracking import IemdTracker
from iemd_ros.tracking import tracker as tracker_module
from iemd_ros.tracking.tracker import Cause
import numpy as np
import pytest

NAN = [np.nan] * 4


def test_long_term_scores_by_hand():
    """
    10 frames, the target absent on frames 4-6.

    Reports with IoU 1 on 0-3, a false report on 4, none on 5-7, IoU 0.5 from frame 8 (re-acquired
    one frame after the return at 7).
    """
    gt = np.array([[10, 10, 10, 10]] * 4 + [NAN] * 3 + [[10, 10, 10, 10]] * 3, float)
    half = [15, 10, 10, 10]  # overlaps the target by 5x10 of 150: IoU 1/3
    pred = np.array(
        [[10, 10, 10, 10]] * 4 + [[50, 50, 5, 5]] + [NAN] * 3 + [[10, 10, 10, 10], half], float
    )
    reported = np.array([True] * 5 + [False] * 3 + [True] * 2)
    s = long_term_scores(pred, reported, gt)
    precision = (4 * 1.0 + 0 + 1.0 + 1 / 3) / 7  # 7 reports, the false one scores 0
    recall = (4 * 1.0 + 0 + 1.0 + 1 / 3) / 7  # 7 present frames, frame 7 unreported
    assert s.precision == pytest.approx(precision) and s.recall == pytest.approx(recall)
    assert s.f_score == pytest.approx(2 * precision * recall / (precision + recall))
    assert (s.absent_frames, s.returns, s.reacquired, s.delays) == (3, 1, 1, [1])
    assert s.false_report_rate == pytest.approx(1 / 3)
    never = long_term_scores(pred, reported & (np.arange(10) < 7), gt)
    assert never.delays == [-1] and never.reacquired == 0 and never.recall < s.recall
    with pytest.raises(ValueError, match='lengths differ'):
        long_term_scores(pred[:5], reported, gt)


def _moving_target_sequence(tmp_path: Path, n: int = 90, name: str = 'Mover') -> Sequence:
    """Return a 16x12 bright square moving 2 px per frame to the right over a 320x240 scene."""
    rng = np.random.default_rng(0)
    scene = cv2.GaussianBlur(rng.integers(0, 255, (240, 320, 3), dtype=np.uint8), (0, 0), 3)
    folder = tmp_path / 'src' / name
    (folder / 'img').mkdir(parents=True)
    boxes = []
    for k in range(n):
        x, y = 60 + 2 * k, 150
        img = scene.copy()
        img[y: y + 12, x: x + 16] = (250, 250, 250)
        cv2.imwrite(str(folder / 'img' / f'{k + 1:04d}.jpg'), img)
        boxes.append((x + 1, y + 1, 16, 12))
    (folder / 'groundtruth_rect.txt').write_text('\n'.join(','.join(map(str, b)) for b in boxes))
    return load_sequence(folder)


def test_the_window_looks_away_for_the_set_frames_and_comes_back(tmp_path):
    seq = _moving_target_sequence(tmp_path)
    cfg = LookAway(crop=0.5, follow_frames=10, away_frames=20, pan_px=30.0)
    origins, (w, h) = look_away_windows(seq, (320, 240), cfg)
    assert (w, h) == (160, 120)
    assert (
        (origins[:, 0] >= 0).all()
        and (origins[:, 0] <= 160).all()
        and (origins[:, 1] <= 120).all()
    )
    out = load_sequence(write_look_away(seq, tmp_path / 'out', cfg))
    absent = np.flatnonzero(np.isnan(out.gt_boxes[:, 0]))
    assert len(out) == len(seq) and len(absent) >= cfg.away_frames
    # one absence, after the follow
    assert absent[0] >= cfg.follow_frames and np.all(np.diff(absent) == 1)
    assert not np.isnan(out.gt_boxes[-1]).any()
    # the annotation is the target in the window's pixels: the bright square is where the GT says
    k = absent[0] - 1
    x, y, bw, bh = out.gt_boxes[k]
    frame = cv2.imread(str(out.frame_paths[k]))
    assert frame.shape[:2] == (120, 160)
    assert frame[int(y) + 2: int(y + bh) - 2, int(x) + 2: int(x + bw) - 2].mean() > 200


def test_a_target_too_large_to_leave_the_window_is_refused(tmp_path):
    seq = _moving_target_sequence(tmp_path, 60)
    with pytest.raises(ValueError, match='cannot stay out of'):
        look_away_windows(seq, (320, 240), LookAway(crop=0.9))
    with pytest.raises(ValueError, match='too few'):
        look_away_windows(seq, (320, 240), LookAway(follow_frames=40, away_frames=30))


def test_eval_reports_the_long_term_measures_of_a_look_away_sequence(tmp_path, capsys):
    seq = _moving_target_sequence(tmp_path)
    assert (
        make_main(
            [
                str(seq.frame_paths[0].parents[1]),
                '--out',
                str(tmp_path / 'la'),
                '--follow',
                '10',
                '--away',
                '20',
                '--pan-px',
                '30',
            ]
        )
        == 0
    )
    out = tmp_path / 'eval'
    assert eval_main([str(tmp_path / 'la' / 'src'), '--trackers', 'kcf', '--out', str(out)]) == 0
    text = capsys.readouterr().out
    assert 'long-term measures (the target leaves the view)' in text
    doc = json.loads((out / 'results.json').read_text())
    lt = doc['results']['kcf']['Mover']['long_term']
    assert lt['absent_frames'] >= 20 and lt['returns'] == 1 and 0 <= lt['f_score'] <= 1
    assert doc['long_term']['kcf']['n_sequences'] == 1 and REACQUIRE_WITHIN == 30


def _track_cut(seq):
    """(boxes, found flags, results) of the default tracker over a look-away cut from its GT."""
    frames = [cv2.imread(str(path)) for path in seq.frame_paths]
    tracker = IemdTracker()
    tracker.init(frames[0], seq.gt_boxes[0])
    results = [tracker.update(frame) for frame in frames[1:]]
    boxes = np.vstack([seq.gt_boxes[0]] + [np.asarray(r.box, float) for r in results])
    return boxes, np.array([True] + [not r.lost for r in results]), results


def test_the_tracker_says_lost_while_a_real_target_is_away_and_finds_it_on_return(
    tmp_path, uav_root
):
    """
    building5 (a drone's view of a walking person) cut into a look-away sequence.

    The window pans off her for about 30 frames and back.  The tracker reports no box on at least
    90 % of the absent frames, is back on her within REACQUIRE_WITHIN frames of her return, and its
    long-term F-score is at least 0.6 (docs/decisions.md#re-detection).
    """
    seq = load_sequence(
        write_look_away(load_sequence(uav_root / 'building5'), tmp_path / 'la', LookAway())
    )
    boxes, ok, _ = _track_cut(seq)
    scores = long_term_scores(boxes, ok, seq.gt_boxes)
    absent = np.isnan(seq.gt_boxes[:, 0])
    assert absent.sum() >= 25 and np.mean(ok[absent]) <= 0.1
    assert scores.reacquired == scores.returns == 1, scores
    assert scores.f_score >= 0.6, scores


def test_a_target_back_at_another_size_is_re_detected_at_that_size(
    tmp_path, otb_root, monkeypatch
):
    """
    Freeman1 cut to look away after 40 frames: he walks towards the camera while it looks away.

    He comes back about 1.4 times as tall as the window the tracker lost; at the lost size the
    filter's peak stays below ``found_response`` times its mean.  The re-detection's other sizes
    find him within REACQUIRE_WITHIN frames of his return, in a window at least 1.2 times the lost
    one's height; searched at the lost size only, he is not found in that time
    (docs/decisions.md#redetect-sizes).
    """
    seq = load_sequence(
        write_look_away(
            load_sequence(otb_root / 'Freeman1'), tmp_path / 'la', LookAway(follow_frames=40)
        )
    )
    boxes, found, results = _track_cut(seq)
    scores = long_term_scores(boxes, found, seq.gt_boxes)
    assert scores.returns == scores.reacquired == 1, scores
    redetected = [k for k, r in enumerate(results) if r.cause is Cause.REDETECTED]
    lost_before = next(r for r in results if r.lost).box
    assert redetected and results[redetected[0]].box[3] >= 1.2 * lost_before[3], results
    assert 'another size' in results[redetected[0]].reason

    monkeypatch.setattr(tracker_module, 'REDETECT_SIZES', (1.0,))
    boxes, found, _ = _track_cut(seq)
    assert long_term_scores(boxes, found, seq.gt_boxes).reacquired == 0


def test_a_target_back_changed_is_taken_where_its_peak_stands_out_from_the_losss_background(
    tmp_path, otb_root, monkeypatch
):
    """
    Freeman1 cut to look away after 15 frames; he comes back nearer, his filter peak short.

    From his return the filter's best candidate is on him at 0.75-0.97 times its running mean,
    below ``found_response`` (1.0); the best peaks of the lost frames before his return
    (background) are lower and steady, and his stands more than ``BACKGROUND_PEAK_STDS`` of their
    deviations above them: he is re-detected within REACQUIRE_WITHIN frames, with that rule as
    the reason.  With ``found_response`` alone he is not
    (docs/decisions.md#redetection-background-level).
    """
    seq = load_sequence(
        write_look_away(load_sequence(otb_root / 'Freeman1'), tmp_path / 'la', LookAway())
    )
    absent = np.isnan(seq.gt_boxes[:, 0])
    boxes, found, results = _track_cut(seq)
    scores = long_term_scores(boxes, found, seq.gt_boxes)
    assert scores.returns == scores.reacquired == 1, scores
    assert np.mean(found[absent]) <= 0.1
    back = next(k for k, r in enumerate(results, start=1) if r.cause is Cause.REDETECTED)
    assert not absent[back] and 'sd above the best peaks of' in results[back - 1].reason

    monkeypatch.setattr(tracker_module, 'BACKGROUND_PEAKS_MIN', 10**9)
    boxes, found, _ = _track_cut(seq)
    assert long_term_scores(boxes, found, seq.gt_boxes).reacquired == 0


def test_several_follow_lengths_give_one_cut_each_that_the_split_selects_by_source(
    tmp_path, capsys
):
    """
    ``--follow 10,25``: two cuts of each source, named <source>-follow<N>, looking away after N.

    ``iemd-eval --split`` keeps the cuts of the part's sources: a source named Car4 is in the
    training part, so both cuts are evaluated with it and none with the validation part.
    """
    seq = _moving_target_sequence(tmp_path, name='Car4')
    args = [str(seq.frame_paths[0].parents[1]), '--out', str(tmp_path / 'la'), '--away', '20']
    assert make_main(args + ['--follow', '10,25,10', '--pan-px', '30']) == 0
    cuts = sorted(p.name for p in (tmp_path / 'la' / 'src').iterdir())
    assert cuts == ['Car4-follow10', 'Car4-follow25']
    for name, follow in zip(cuts, (10, 25)):
        gt = load_sequence(tmp_path / 'la' / 'src' / name).gt_boxes
        absent = np.flatnonzero(np.isnan(gt[:, 0]))
        assert follow <= absent[0] <= follow + 10
    root = str(tmp_path / 'la' / 'src')
    capsys.readouterr()
    out = ['--out', str(tmp_path / 'e')]
    assert eval_main([root, '--trackers', 'kcf', '--split', 'train'] + out) == 0
    doc = json.loads((tmp_path / 'e' / 'results.json').read_text())
    assert sorted(set(doc['results']['kcf']) - {'mean'}) == cuts
    assert eval_main([root, '--trackers', 'kcf', '--split', 'validation']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["iemd-eval: error: the inputs hold none of the validation part's sequences"]
    assert make_main(args + ['--follow', '10,x']) == 2
    assert capsys.readouterr().err.count('\n') == 1


def test_a_cut_belongs_to_the_part_of_its_source():
    part = ['Car4', 'Jogging-1']
    assert in_part('car4', part) and in_part('Car4-follow40', part)
    assert in_part('Jogging-1-follow15', part)
    assert not in_part('Jogging-2', part) and not in_part('Car44', part)
