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
iemd-eval end to end (iemd_ros.evaluation.ope).

Protocol wiring on synthetic data, CLI on real OTB frames.
"""
import importlib.util
import json
from pathlib import Path

import cv2
from helpers import (
    cli_error,
    node_parameter_file,
    PNG_SIGNATURE,
    REPO,
    run_module,
    run_python,
)
from iemd_ros import TrackerConfig
from iemd_ros.apps.eval import main
from iemd_ros.datasets.otb import load_sequence
from iemd_ros.evaluation import ope as evaluation
from iemd_ros.evaluation.ope import (
    make_tracker,
    results_digest,
    run_tracker,
    sequence_names,
    WALL_CLOCK_FIELDS,
)
import numpy as np
import pytest

# CSRT on Car4 frames 1-20 (OpenCV 5.0.0 contrib) tracks the car (docs/decisions.md#test-bounds)
CSRT_CAR4_20_MIN_OVERLAP = 0.75


def _synthetic_root(tmp_path: Path, n: int = 6) -> tuple[Path, np.ndarray]:
    seq = tmp_path / 'data' / 'Toy'
    (seq / 'img').mkdir(parents=True)
    gt1 = np.array([[11 + 2 * k, 21 + k, 10, 12] for k in range(n)], float)  # 1-based
    for k in range(n):
        cv2.imwrite(str(seq / 'img' / f'{k + 1:04d}.jpg'), np.full((60, 80, 3), k, np.uint8))
    (seq / 'groundtruth_rect.txt').write_text(
        '\n'.join(','.join(f'{v:g}' for v in b) for b in gt1)
    )
    return tmp_path / 'data', gt1 - [1, 1, 0, 0]


class _Oracle:
    """
    Fake tracker that returns the 0-based GT of the frame it is given.

    (frame k has brightness k).
    """

    gt: np.ndarray

    intervals: list = []  # every update's interval, in order

    def init(self, frame, box):
        assert int(frame[0, 0, 0]) == 0
        np.testing.assert_array_equal(box, self.gt[0])

    def update(self, frame, interval=None):
        k = int(round(frame.mean()))
        self.intervals.append(interval)
        return self.gt[k], k != 3  # reports one failure, at frame index 3


def test_protocol_with_oracle_tracker(tmp_path, monkeypatch, capsys):
    root, gt = _synthetic_root(tmp_path)
    monkeypatch.setattr(_Oracle, 'gt', gt, raising=False)
    monkeypatch.setitem(evaluation.TRACKERS, 'oracle', _Oracle)
    out = tmp_path / 'out'
    assert (
        main(
            [
                str(root),
                '--trackers',
                'oracle',
                '--out',
                str(out),
                '--max-frames',
                '5',
                '--jobs',
                '1',
            ]
        )
        == 0
    )
    doc = json.loads((out / 'results.json').read_text())
    res = doc['results']['oracle']['Toy']
    np.testing.assert_array_equal(res['boxes'], gt[:5])  # frame/GT alignment, first frame = GT
    assert res['average_overlap'] == 1.0 and res['precision_20'] == 1.0 and res['n_frames'] == 5
    assert res['failures'] == 1 and res['ok'] == [True, True, True, False, True]
    assert doc['results']['oracle']['mean']['success_auc'] == pytest.approx(20 / 21)
    assert 'Toy' in capsys.readouterr().out


def test_a_frame_rate_gives_the_tracker_the_frames_interval(tmp_path, monkeypatch):
    root, gt = _synthetic_root(tmp_path)
    monkeypatch.setattr(_Oracle, 'gt', gt, raising=False)
    monkeypatch.setattr(_Oracle, 'intervals', [])
    monkeypatch.setitem(evaluation.TRACKERS, 'oracle', _Oracle)
    argv = [str(root), '--trackers', 'oracle', '--out', str(tmp_path / 'out'), '--jobs', '1']
    assert main(argv + ['--frame-rate', '12.5']) == 0
    assert _Oracle.intervals == [0.08] * 5
    assert json.loads((tmp_path / 'out' / 'results.json').read_text())['frame_rates'] == {
        'Toy': 12.5
    }
    _Oracle.intervals.clear()
    assert main(argv) == 0  # the OTB layout records no rate
    assert _Oracle.intervals == [None] * 5


def test_run_tracker_keeps_last_box_when_tracker_returns_none():
    class Flaky:
        def init(self, frame, box):
            self.k = 0

        def update(self, frame, interval=None):
            self.k += 1
            if self.k in (2, 3):
                return np.zeros(4), False  # what cv2.TrackerCSRT/KCF return when lost
            if self.k == 4:
                return np.full(4, np.nan), True  # no box at all
            return np.array([self.k, 0, 5, 5.0]), True

    frames = [np.zeros((8, 8, 3), np.uint8)] * 6
    run = run_tracker(Flaky(), frames, (1, 1, 4, 4))
    assert run.ok.tolist() == [
        True,
        True,
        False,
        False,
        True,
        True,
    ] and run.update_seconds.shape == (5,)
    # frames 2-4 hold frame 1's box
    np.testing.assert_array_equal(run.boxes[:, 0], [1, 1, 1, 1, 1, 5])
    np.testing.assert_array_equal(run.boxes[0], [1, 1, 4, 4])


def test_opencv_failure_returns_empty_box_and_keeps_position(otb_root):
    """
    Backs the hold-last rule: OpenCV's failure box is (0,0,0,0).

    The tracker resumes where it was.
    """
    seq = load_sequence('Car4', otb_root).head(3)
    f0, f1, _ = list(seq.frames())
    noise = np.random.default_rng(0).integers(0, 256, f0.shape, dtype=np.uint8)
    trk = make_tracker('kcf')
    trk.init(f0, seq.gt_boxes[0])
    box1, ok1 = trk.update(f1)
    box_fail, ok_fail = trk.update(noise)
    box_back, ok_back = trk.update(f1)
    assert ok1 and not ok_fail and np.all(box_fail == 0)
    assert ok_back and np.abs(box_back - box1).max() <= 2  # resumed from its last position


def test_cli_real_excerpt_csrt_kcf(otb_root, tmp_path, capsys):
    out = tmp_path / 'eval'
    rc = main(
        [
            str(otb_root),
            '--trackers',
            'csrt,kcf',
            '--sequences',
            'Car4',
            '--max-frames',
            '20',
            '--out',
            str(out),
        ]
    )
    assert rc == 0
    doc = json.loads((out / 'results.json').read_text())
    assert {'protocol', 'trackers', 'sequences', 'ground_truth', 'results'} <= doc.keys()
    assert 'iemd_config' not in doc  # iEMD did not run
    assert doc['trackers'] == ['csrt', 'kcf'] and doc['sequences'] == ['Car4']
    for trk in ('csrt', 'kcf'):
        car = doc['results'][trk]['Car4']
        for key in (
            'average_overlap',
            'success_auc',
            'precision_20',
            'overlap_gt_0',
            'overlap_gt_04',
            'fps',
            'success_curve',
            'boxes',
            'failures',
        ):
            assert key in car, (trk, key)
        assert len(car['boxes']) == 20 and len(car['success_curve']) == 21
        assert car['boxes'][0] == doc['ground_truth']['Car4'][0]
        assert 0 < car['fps'] < 1e6
        assert doc['results'][trk]['mean']['average_overlap'] == pytest.approx(
            car['average_overlap']
        )
    assert doc['results']['csrt']['Car4']['average_overlap'] > CSRT_CAR4_20_MIN_OVERLAP
    for png in ('success_Car4.png', 'success_overall.png'):
        data = (out / png).read_bytes()
        assert data[:8] == PNG_SIGNATURE
        img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
        assert img is not None and img.shape[0] > 100 and img.shape[1] > 100
    table = capsys.readouterr().out
    assert 'MEAN (1)' in table and 'csrt' in table and 'kcf' in table


def test_cli_iemd_parameters_from_the_node_parameter_file(otb_root, tmp_path):
    """
    --config takes the node's config/tracker.yaml.

    Its tracker.* values are the ones iEMD runs with.
    """
    node_parameter_file(tmp_path / 'p.yaml', tracker={'scale_step': 0.0})
    common = [str(otb_root), '--trackers', 'iemd', '--sequences', 'Car4', '--max-frames', '40']
    assert main(common + ['--out', str(tmp_path / 'default')]) == 0
    assert (
        main(common + ['--out', str(tmp_path / 'fixed'), '--config', str(tmp_path / 'p.yaml')])
        == 0
    )
    default, fixed = (
        json.loads((tmp_path / d / 'results.json').read_text()) for d in ('default', 'fixed')
    )
    assert TrackerConfig.from_dict(default['iemd_config']) == TrackerConfig()
    assert TrackerConfig.from_dict(fixed['iemd_config']) == TrackerConfig(scale_step=0.0)
    sizes = {
        d: np.array(doc['results']['iemd']['Car4']['boxes'])[:, 2:]
        for d, doc in (('default', default), ('fixed', fixed))
    }
    # the default scale search resizes the window
    assert np.ptp(sizes['default'], axis=0).max() > 1.0
    np.testing.assert_allclose(
        sizes['fixed'], np.broadcast_to(sizes['fixed'][0], sizes['fixed'].shape)
    )


@pytest.mark.parametrize(
    'argv, match',
    [
        (['--trackers', 'nope'], "unknown tracker 'nope'"),
        (['--max-frames', 'zero', '--trackers', 'kcf'], 'not an integer'),
        (['--jobs', '0', '--trackers', 'kcf'], '--jobs must be >= 1, got 0'),
        (
            ['--jobs', '2', '--cluster', 'tcp://127.0.0.1:9', '--trackers', 'kcf'],
            'not allowed with',
        ),
        (['--max-frames', '1', '--trackers', 'kcf'], 'must be >= 2'),
        (['--frame-rate', '0', '--trackers', 'kcf'], 'must be a finite number > 0'),
        (['--frame-rate', 'fast', '--trackers', 'kcf'], 'not a number'),
        (['--bogus'], 'unrecognized arguments'),
        (['/no/such/dir', '--trackers', 'kcf'], 'neither an OTB root nor a sequence folder'),
        (['--config', '/no/such/params.yaml', '--trackers', 'iemd'], 'cannot read config'),
        (['--config', 'config/tracker.yaml', '--trackers', 'kcf'], 'iemd is not among --trackers'),
    ],
)
def test_bad_arguments_exit_2_one_line(argv, match, capsys):
    assert match in cli_error(main, argv, capsys, 'iemd-eval: error:')


PERTURBED_STARTS = REPO / 'benchmarks' / 'perturbed_starts.py'


@pytest.fixture(scope='module')
def script():
    """``benchmarks/perturbed_starts.py`` imported as a module (benchmarks is no package)."""
    spec = importlib.util.spec_from_file_location('perturbed_starts', PERTURBED_STARTS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(
    'argv, match',
    [
        (['--frame-rate', 'inf'], "argument --frame-rate: must be a finite number > 0, got 'inf'"),
        (['--jpeg-quality', '0'], '--jpeg-quality must be in 1-100, got 0'),
        (['--exposure', '-1'], '--exposure must be in [0, 3], got -1.0'),
        (['--noise', '100'], '--noise must be in [0, 64], got 100.0'),
        (['--blur', '-2'], '--blur must be in [0, 64], got -2.0'),
    ],
)
def test_perturbed_starts_refuses_a_bad_camera_in_one_line(argv, match):
    proc = run_python(str(PERTURBED_STARTS), *argv, timeout=60)
    assert proc.returncode == 2
    assert 'Traceback' not in proc.stderr
    assert match in proc.stderr


def test_perturbed_starts_jpeg_camera_compresses_at_its_quality_and_keeps_the_boxes(script):
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 256, (48, 64, 3), dtype=np.uint8) for _ in range(3)]
    boxes = [[1.0, 2.0, 10.0, 12.0]] * 3

    def error(quality, mono=False):
        camera = script.Camera(mono=mono, jpeg_quality=quality)
        out, kept = script._as_camera(iter(frames), boxes, camera)
        np.testing.assert_array_equal(kept, boxes)
        shape = (48, 64) if mono else (48, 64, 3)
        assert all(f.shape == shape and f.dtype == np.uint8 for f in out)
        sources = [cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) for f in frames] if mono else frames
        return np.mean([np.abs(f.astype(int) - g).mean() for f, g in zip(out, sources)])

    assert error(None) == 0.0  # read as they are
    # noise is what JPEG discards first: the lower the quality, the more of it is lost
    assert 0.0 < error(95) < error(10)
    assert error(10, mono=True) > 0.0  # a mono8 frame stays one channel


def test_perturbed_starts_exposure_multiplies_each_frames_levels_by_its_gain(script):
    quarter = script.EXPOSURE_PERIOD // 4
    n = 3 * quarter + 1
    ramp = np.tile(np.arange(256, dtype=np.uint8), (2, 1))
    frames = [np.dstack([ramp] * 3)] * n
    boxes = [[1.0, 2.0, 10.0, 12.0]] * n
    out, kept = script._as_camera(iter(frames), boxes, script.Camera(exposure=1.0))
    np.testing.assert_array_equal(kept, boxes)
    levels = np.arange(256)
    np.testing.assert_array_equal(out[0][0, :, 0], levels)  # gain 1 on the first frame
    # a quarter period on, one stop up (saturating at 255); three quarters on, one stop down
    np.testing.assert_array_equal(out[quarter][0, :, 1], np.minimum(2 * levels, 255))
    np.testing.assert_array_equal(out[3 * quarter][1, :, 2], np.round(levels / 2.0))
    # a twelfth of the period on, sin = 1/2: half the stops
    assert script.exposure_gain(script.EXPOSURE_PERIOD // 12, 2.0) == pytest.approx(2.0)
    # every other frame kept: the gain follows the frames the camera gives, a mono frame too
    grey, _ = script._as_camera(
        iter(frames), boxes, script.Camera(mono=True, every=2, exposure=1.0)
    )
    assert grey[quarter].ndim == 2
    np.testing.assert_array_equal(grey[quarter][0], np.minimum(2 * levels, 255))


def test_perturbed_starts_noise_adds_the_same_grain_of_its_deviation_to_every_run(script):
    grey, bright = np.full((60, 80, 3), 128, np.uint8), np.full((60, 80, 3), 250, np.uint8)
    frames = [grey, grey, bright]
    boxes = [[1.0, 2.0, 10.0, 12.0]] * 3
    out, kept = script._as_camera(iter(frames), boxes, script.Camera(noise=8.0))
    np.testing.assert_array_equal(kept, boxes)
    grain = out[0].astype(float) - 128.0
    assert abs(grain.mean()) < 0.5 and 7.5 < grain.std() < 8.5
    assert not np.array_equal(out[0][:, :, 0], out[0][:, :, 1])  # every level its own draw
    assert not np.array_equal(out[0], out[1])  # a new draw each frame
    assert out[2].max() == 255 and out[2].dtype == np.uint8  # within the levels
    again, _ = script._as_camera(iter(frames), boxes, script.Camera(noise=8.0))
    np.testing.assert_array_equal(again[0], out[0])  # seeded: every run sees the same noise
    clean, _ = script._as_camera(iter(frames), boxes, script.Camera())
    np.testing.assert_array_equal(clean[0], frames[0])


def test_perturbed_starts_blur_smears_a_point_along_a_line_turning_every_frame(script):
    point = np.zeros((41, 41, 3), np.uint8)
    point[20, 20] = 240
    frames = [point] * 3
    boxes = [[1.0, 2.0, 10.0, 12.0]] * 3
    out, kept = script._as_camera(iter(frames), boxes, script.Camera(blur=8.0))
    np.testing.assert_array_equal(kept, boxes)
    # the first frame's line is along x: 8 px through the point, from 4 px left of it to 4 right
    lit = np.argwhere(out[0][:, :, 0] > 0)
    assert set(lit[:, 0]) == {20}
    assert lit[:, 1].min() == 16 and lit[:, 1].max() == 24
    assert abs(int(out[0][:, :, 0].sum()) - 240) <= 8  # the light is spread, not lost
    # each later frame's line is turned by the golden angle: its second moments show the direction
    for k in (1, 2):
        ys, xs = np.nonzero(out[k][:, :, 0] > 0)
        weights = out[k][ys, xs, 0].astype(float)
        cov = np.cov(np.vstack([xs, ys]), aweights=weights)
        direction = np.linalg.eigh(cov)[1][:, -1]
        cos = abs(direction @ [np.cos(k * script.BLUR_TURN), np.sin(k * script.BLUR_TURN)])
        assert cos > 0.99
        assert 0.5 * 8.0 ** 2 / 12 < np.linalg.eigvalsh(cov)[-1] < 1.5 * 8.0 ** 2 / 12
    for k, length in ((0, 0.5), (3, 8.0), (5, 21.0)):
        kernel = script.blur_kernel(k, length)
        assert kernel.sum() == pytest.approx(1.0)
        assert kernel.shape[0] % 2 == 1 and np.allclose(kernel, kernel[::-1, ::-1])  # no shift
    clean, _ = script._as_camera(iter(frames), boxes, script.Camera())
    np.testing.assert_array_equal(clean[0], frames[0])


def test_unknown_sequence_exits_2_one_line(tmp_path, capsys):
    """
    An unknown --sequences name is an argument error.

    (a root of its own: no ../shared needed).
    """
    root, _ = _synthetic_root(tmp_path)
    argv = [str(root), '--sequences', 'NoSuchSeq', '--trackers', 'kcf']
    assert "unknown sequence 'NoSuchSeq'" in cli_error(main, argv, capsys, 'iemd-eval: error:')


def test_bad_argument_subprocess_no_traceback(tmp_path):
    proc = run_module('iemd_ros.apps.eval', str(tmp_path), '--trackers', 'kcf', timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.count('\n') == 1 and 'Traceback' not in proc.stderr
    assert 'holds no OTB sequence' in proc.stderr


def test_sequence_names_selects_from_the_shared_otb_root(otb_root):
    assert sequence_names('jogging,Car4') == ['Jogging-1', 'Jogging-2', 'Car4']
    everything = sequence_names(None)
    assert sequence_names('') == everything and {'Car4', 'Woman', 'Jogging-1'} <= set(everything)
    with pytest.raises(ValueError, match="unknown sequence 'Nope'"):
        sequence_names('Nope')


def test_group_means_and_published_ranking(tmp_path, monkeypatch, capsys):
    """
    Sequences from two folders get a mean each and one over all.

    --published ranks the run among the file's trackers on the sequences both have, per set.
    """
    root_a, gt = _synthetic_root(tmp_path / 'a')
    root_b, _ = _synthetic_root(tmp_path / 'b')
    (root_b / 'Toy').rename(root_b / 'Toy2')
    root_b = root_b.rename(root_b.with_name('other'))
    monkeypatch.setattr(_Oracle, 'gt', gt, raising=False)
    monkeypatch.setitem(evaluation.TRACKERS, 'oracle', _Oracle)
    published = {
        'setA': {
            'Good': {'Toy': {'avg_overlap': 90.0, 'auc': 88.0}},
            'LADCF': {'Toy': {'avg_overlap': 99.0, 'auc': 98.0}},
            'Partial': {'Other': {'avg_overlap': 50.0, 'auc': 50.0}},
        }
    }
    path = tmp_path / 'published.json'
    path.write_text(json.dumps(published))
    out = tmp_path / 'out'
    assert (
        main(
            [
                str(root_a),
                str(root_b),
                '--trackers',
                'oracle',
                '--out',
                str(out),
                '--max-frames',
                '5',
                # the oracle is known to this process only
                '--published',
                str(path),
                '--jobs',
                '1',
            ]
        )
        == 0
    )
    doc = json.loads((out / 'results.json').read_text())
    means = {k for k in doc['results']['oracle'] if k.startswith('mean')}
    assert means == {'mean', 'mean data', 'mean other'} and doc['groups'] == {
        'Toy': 'data',
        'Toy2': 'other',
    }
    assert (
        doc['results']['oracle']['mean data']['n_sequences']
        == 1
        == doc['results']['oracle']['mean other']['n_sequences']
    )
    text = capsys.readouterr().out
    lines = text[text.index('published results, set setA'):].splitlines()
    assert '1 sequence(s) of this run (Toy)' in lines[0]
    order = [line.split()[0] for line in lines[2:5]]
    assert (
        order == ['oracle', 'LADCF', 'Good'] and 'deep' in lines[3] and 'hand-crafted' in lines[4]
    )
    assert 'Partial' not in text and 'first 5 frames only' in text


def test_published_file_errors(tmp_path, capsys):
    bad = tmp_path / 'bad.json'
    bad.write_text('[1, 2]')
    assert 'expected {set: {tracker:' in cli_error(
        main, ['--published', str(bad), '--trackers', 'kcf'], capsys, 'iemd-eval: error:'
    )


def test_the_split_is_the_hash_rule_over_the_shared_sequences(otb_root):
    from iemd_ros.datasets.otb import list_sequences
    from iemd_ros.evaluation.split import hash_split, split, split_names

    for group in ('otb', 'uav'):
        folder = otb_root.parent / group
        if not folder.is_dir():
            pytest.skip(f'{folder} is absent')
        train, validation = hash_split(list_sequences(folder))
        assert (train, validation) == (split()['train'][group], split()['validation'][group])
    assert not set(split_names('train')) & set(split_names('validation'))
    with pytest.raises(ValueError, match="unknown split part 'test'"):
        split_names('test')


def _without_wall_clock(doc: dict) -> dict:
    return {
        **doc,
        'results': {
            t: {
                k: {f: v for f, v in e.items() if f not in WALL_CLOCK_FIELDS} for k, e in r.items()
            }
            for t, r in doc['results'].items()
        },
    }


def test_results_are_the_serial_ones_on_local_processes_and_on_a_cluster(
    otb_root, tmp_path, dask_cluster, capsys
):
    """
    The same jobs in this process, on 2 local processes and on the test's Dask cluster.

    The same results.json (keys, order, numbers) but for the wall-clock fields, the same digest,
    the same plots.  CSRT and KCF are in: OpenCV's trackers are deterministic too.
    """
    common = [
        str(otb_root),
        '--trackers',
        'iemd,csrt,kcf',
        '--sequences',
        'Deer,Skiing',
        '--max-frames',
        '12',
    ]
    runs = {
        'serial': ['--jobs', '1'],
        'local': ['--jobs', '2'],
        'cluster': ['--cluster', dask_cluster],
    }
    docs, texts = {}, {}
    for name, where in runs.items():
        assert main(common + where + ['--out', str(tmp_path / name)]) == 0
        texts[name] = (tmp_path / name / 'results.json').read_text()
        docs[name] = json.loads(texts[name])
        # the digest it prints
        assert capsys.readouterr().out.rstrip().endswith(results_digest(docs[name]))
    serial = docs['serial']
    assert len(serial['results']['iemd']['Deer']['boxes']) == 12 and results_digest(
        serial
    ) != results_digest(
        # order counts
        {**serial, 'sequences': serial['sequences'][::-1]}
    )
    for name in ('local', 'cluster'):
        assert results_digest(docs[name]) == results_digest(serial), name
        assert json.dumps(_without_wall_clock(docs[name])) == json.dumps(
            _without_wall_clock(serial)
        )
        for png in ('success_Deer.png', 'success_Skiing.png', 'success_overall.png'):
            assert (tmp_path / name / png).read_bytes() == (
                tmp_path / 'serial' / png
            ).read_bytes(), (name, png)


def test_the_digest_leaves_out_the_wall_clock_fields_only(tmp_path, monkeypatch):
    root, gt = _synthetic_root(tmp_path)
    monkeypatch.setattr(_Oracle, 'gt', gt, raising=False)
    monkeypatch.setitem(evaluation.TRACKERS, 'oracle', _Oracle)
    assert (
        main([str(root), '--trackers', 'oracle', '--out', str(tmp_path / 'out'), '--jobs', '1'])
        == 0
    )
    doc = json.loads((tmp_path / 'out' / 'results.json').read_text())
    entry = doc['results']['oracle']['Toy']
    assert set(WALL_CLOCK_FIELDS) <= entry.keys()
    digest = results_digest(doc)
    for field in WALL_CLOCK_FIELDS:
        changed = json.loads(json.dumps(doc))
        changed['results']['oracle']['Toy'][field] = 12345.0
        assert results_digest(changed) == digest, field
    changed = json.loads(json.dumps(doc))
    changed['results']['oracle']['Toy']['boxes'][1][0] += 1e-9
    assert results_digest(changed) != digest


def test_unreachable_cluster_exits_2_one_line(otb_root, capsys, monkeypatch):
    import dask

    with dask.config.set({'distributed.comm.timeouts.connect': '2s'}):
        err = cli_error(
            main,
            [
                str(otb_root),
                '--trackers',
                'kcf',
                '--sequences',
                'Deer',
                '--max-frames',
                '3',
                '--cluster',
                'tcp://127.0.0.1:9',
            ],
            capsys,
            'iemd-eval: error:',
        )
    assert '127.0.0.1:9' in err
