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
OTB-layout loading (iemd_ros.datasets.otb).

GT parsing variants on tmp files and every real sequence.
"""
from pathlib import Path

import cv2
from iemd_ros.datasets.otb import list_sequences, load_sequence, parse_groundtruth, read_frame
import numpy as np
import pytest

EXPECTED = np.array([[69.0, 50.0, 107.0, 87.0], [70.5, 49.0, 100.0, 80.0], [-1.0, 0.0, 3.0, 4.0]])


@pytest.mark.parametrize(
    'text',
    [
        # tab, CRLF, no final newline (Car4)
        '70\t51\t107\t87\r\n71.5\t50\t100\t80\r\n0\t1\t3\t4',
        '70,51,107,87\n71.5,50,100,80\n0,1,3,4\n',                    # comma LF (Bolt2)
        # no final newline (Jogging .1)
        '70,51,107,87\n71.5,50,100,80\n0,1,3,4',
        # spaces, mixed, blank lines
        '70 51 107 87\n\n71.5  50 100 80\n 0, 1,\t3 ,4 \n\n',
        '70,51,107,87\r\n71.5,50,100,80\r\n0,1,3,4\r\n',              # comma CRLF
    ],
)
def test_parse_groundtruth_variants(tmp_path, text):
    path = tmp_path / 'groundtruth_rect.txt'
    path.write_bytes(text.encode())
    np.testing.assert_array_equal(parse_groundtruth(path), EXPECTED)  # x, y shifted by -1


def test_parse_groundtruth_nan_marks_absent(tmp_path):
    path = tmp_path / 'gt.txt'
    path.write_text('1,1,2,2\nNaN,NaN,NaN,NaN\n')
    boxes = parse_groundtruth(path)
    assert boxes.shape == (2, 4) and np.isnan(boxes[1]).all()


@pytest.mark.parametrize(
    'text, match',
    [
        ('1,2,3,4\n5,6,7,8\n1,2,x,4\n', r'gt\.txt:3: not a number'),
        ('1,2,3,4\n\n1,2,3\n', r'gt\.txt:3: expected 4 values'),
        ('1,2,3,4,5\n', r'gt\.txt:1: expected 4 values'),
        ('\n \n', 'no boxes'),
    ],
)
def test_parse_groundtruth_errors_name_file_and_line(tmp_path, text, match):
    path = tmp_path / 'gt.txt'
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        parse_groundtruth(path)


def test_gt_file_parsing(tmp_path):
    p = tmp_path / 'gt.txt'
    p.write_text('10,20,30,40,ok\nNaN,NaN,NaN,NaN,absent\n1.5,2,3,4\n5,6,7,8,absent\n')
    boxes, flags = parse_groundtruth(p, with_flags=True)
    np.testing.assert_allclose(boxes[0], [9, 19, 30, 40])
    assert np.isnan(boxes[1]).all() and np.isnan(boxes[3]).all()
    np.testing.assert_allclose(boxes[2], [0.5, 1, 3, 4])
    assert list(flags) == ['ok', 'absent', 'ok', 'absent']
    p.write_text('1,2,x,4\n')
    with pytest.raises(ValueError, match='bad box line'):
        parse_groundtruth(p, with_flags=True)
    p.write_text('1 2 3 4 blur\n1,2,3,4,5,6\n')
    with pytest.raises(
        ValueError, match=r'gt\.txt:2: expected 4 values x,y,w,h and an optional flag, got 6'
    ):
        parse_groundtruth(p, with_flags=True)


def _make_seq(folder: Path, numbers, gts: dict[str, str], gray=False) -> Path:
    (folder / 'img').mkdir(parents=True)
    for k, n in enumerate(numbers):
        img = np.full((12, 16) if gray else (12, 16, 3), 10 * k, np.uint8)
        cv2.imwrite(str(folder / 'img' / f'{n:04d}.jpg'), img)
    for name, text in gts.items():
        (folder / name).write_text(text)
    return folder


def test_frame_numbers_from_file_names_and_gt_alignment(tmp_path):
    seq_dir = _make_seq(
        tmp_path / 'Dav', [300, 302, 301], {'groundtruth_rect.txt': '1,1,5,5\n2,2,5,5\n3,3,5,5\n'}
    )
    seq = load_sequence(seq_dir)
    assert seq.name == 'Dav' and len(seq) == 3
    assert seq.frame_numbers == (300, 301, 302)  # numeric order, not listing order
    assert [p.name for p in seq.frame_paths] == ['0300.jpg', '0301.jpg', '0302.jpg']
    np.testing.assert_array_equal(seq.gt_boxes[:, 0], [0, 1, 2])  # line i <-> i-th image
    means = [f.mean() for f in seq.frames()]  # written with brightness 0, 10, 20 for 300, 302, 301
    np.testing.assert_allclose(means, [0, 20, 10], atol=2)
    head = seq.head(2)
    assert len(head) == 2 and head.gt_boxes.shape == (2, 4) and head.frame_numbers == (300, 301)


def test_grayscale_jpeg_reads_as_bgr(tmp_path):
    seq = load_sequence(
        _make_seq(tmp_path / 'G', [1], {'groundtruth_rect.txt': '1,1,5,5'}, gray=True)
    )
    frame = next(seq.frames())
    assert frame.shape == (12, 16, 3) and frame.dtype == np.uint8


def test_multi_target_folder(tmp_path):
    _make_seq(
        tmp_path / 'Jog',
        [1, 2],
        {
            'groundtruth_rect.1.txt': '1,1,5,5\n1,1,5,5',
            'groundtruth_rect.2.txt': '9,9,3,3\n9,9,3,3',
        },
    )
    _make_seq(tmp_path / 'Solo', [1, 2], {'groundtruth_rect.txt': '1,1,5,5\n1,1,5,5'})
    (tmp_path / 'not_a_seq').mkdir()
    assert list_sequences(tmp_path) == ['Jog-1', 'Jog-2', 'Solo']
    assert load_sequence('Jog-2', tmp_path).gt_boxes[0, 0] == 8
    assert load_sequence(tmp_path / 'Jog-1').gt_boxes[0, 0] == 0
    with pytest.raises(ValueError, match='Jog-1, Jog-2; choose one'):
        load_sequence(tmp_path / 'Jog')


def test_load_errors(tmp_path):
    with pytest.raises(ValueError, match='not an OTB sequence: no img/'):
        load_sequence(tmp_path)
    _make_seq(tmp_path / 'Short', [1, 2, 3], {'groundtruth_rect.txt': '1,1,5,5\n1,1,5,5\n'})
    with pytest.raises(ValueError, match='2 ground-truth boxes for 3 images'):
        load_sequence(tmp_path / 'Short')
    _make_seq(tmp_path / 'NoGt', [1], {})
    with pytest.raises(ValueError, match='no groundtruth_rect.txt'):
        load_sequence(tmp_path / 'NoGt')
    with pytest.raises(ValueError, match='not found'):
        load_sequence('Missing', tmp_path)
    with pytest.raises(ValueError, match='not a directory'):
        list_sequences(tmp_path / 'nope')
    (tmp_path / 'bad.jpg').write_bytes(b'not a jpeg')
    with pytest.raises(ValueError, match='cannot read image'):
        read_frame(tmp_path / 'bad.jpg')


# ---- real data ---------------------------------------------------------------------------------


def test_every_real_sequence_loads(otb_root):
    names = list_sequences(otb_root)
    assert len(names) >= 3
    for name in names:
        seq = load_sequence(name, otb_root)
        assert len(seq.gt_boxes) == len(seq.frame_paths) > 0, name
        assert np.all(seq.gt_boxes[:, 2:] > 0), name
        h, w = read_frame(seq.frame_paths[0]).shape[:2]
        # GT boxes lie (mostly) inside the image: their centres do
        cx, cy = (
            seq.gt_boxes[:, 0] + seq.gt_boxes[:, 2] / 2,
            seq.gt_boxes[:, 1] + seq.gt_boxes[:, 3] / 2,
        )
        assert np.all((cx > -1) & (cx < w + 1) & (cy > -1) & (cy < h + 1)), name


def test_real_first_box_is_first_line_minus_one(otb_root):
    first_line = (otb_root / 'Car4' / 'groundtruth_rect.txt').read_text().splitlines()[0].split()
    expected = np.array([float(v) for v in first_line]) - [1, 1, 0, 0]
    np.testing.assert_array_equal(load_sequence('Car4', otb_root).gt_boxes[0], expected)


def test_real_david_woman_jogging(otb_root):
    david = load_sequence('David', otb_root)
    assert david.frame_numbers[0] == 300 and david.frame_numbers[-1] == 770 and len(david) == 471
    assert len(load_sequence('Woman', otb_root)) == 597
    jog = [n for n in list_sequences(otb_root) if n.startswith('Jogging')]
    assert jog == ['Jogging-1', 'Jogging-2']
    j1, j2 = (load_sequence(n, otb_root) for n in jog)
    assert j1.frame_paths == j2.frame_paths
    assert not np.allclose(j1.gt_boxes[0], j2.gt_boxes[0])  # two different targets


@pytest.mark.parametrize(
    'pattern', ['{:05d}.jpg', '{:06d}.jpg', 'img{:06d}.jpg', 'frame_{:d}.png']
)
def test_image_names_ending_in_the_frame_number(tmp_path, pattern):
    """
    UAV123's 000001.jpg, DTB70's 00001.jpg, UAVDT's img000001.jpg.

    The number that ends the name orders them.
    """
    (tmp_path / 'S' / 'img').mkdir(parents=True)
    for k, n in enumerate([10, 9, 11]):
        cv2.imwrite(
            str(tmp_path / 'S' / 'img' / pattern.format(n)), np.full((8, 8, 3), 10 * k, np.uint8)
        )
    (tmp_path / 'S' / 'groundtruth_rect.txt').write_text('1,1,4,4\n2,2,4,4\n3,3,4,4\n')
    seq = load_sequence(tmp_path / 'S')
    assert seq.frame_numbers == (9, 10, 11) and seq.group == tmp_path.name
    (tmp_path / 'S' / 'img' / 'cover.jpg').write_bytes(b'x')
    with pytest.raises(ValueError, match="must end in their frame number, got 'cover.jpg'"):
        load_sequence(tmp_path / 'S')


def test_nan_annotation_lines_are_absent_frames(tmp_path):
    seq_dir = _make_seq(
        tmp_path / 'A', [1, 2, 3], {'groundtruth_rect.txt': '1,1,5,5\nNaN,NaN,NaN,NaN\n3,3,5,5\n'}
    )
    boxes = load_sequence(seq_dir).gt_boxes
    assert np.isnan(boxes[1]).all() and not np.isnan(boxes[[0, 2]]).any()
