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
iemd-replay --out-dir.

A folder or a list of bags replayed as one job per bag, in this process, on 2 local processes and
on the test's Dask cluster (127.0.0.1); each CSV is the bytes a replay of that bag alone writes.
"""
import os
import shutil

from bag_fixtures import make_bag, shaky_sequence
from helpers import cli_error
from iemd_ros.apps.replay import main
from iemd_ros.bags.batch import find_bags
from iemd_ros.bags.io import BagError, open_bag
from iemd_ros.bags.replay import DETECTIONS_TOPIC
import pytest

N = 8
SIZES = {'a': 48.0, 'b': 40.0, 'c.bag': 56.0}   # three bags, three targets, three storage formats
FORMATS = {'a': 'mcap', 'b': 'sqlite3', 'c.bag': 'ros1'}


def _box(seq) -> str:
    return ','.join(repr(float(v)) for v in seq.gt_boxes[0])


@pytest.fixture(scope='module')
def folder(tmp_path_factory):
    """
    Return a folder of three bags (and a file that is no bag), and each bag's init box.

    In name order.
    """
    d = tmp_path_factory.mktemp('batch') / 'bags'
    d.mkdir()
    boxes = []
    for name, size in SIZES.items():
        seq = shaky_sequence(N, target_size_px=size)
        make_bag(seq, d / name, FORMATS[name])
        boxes.append(_box(seq))
    (d / 'notes.txt').write_text('not a bag')
    assert len(set(boxes)) == 3
    return d, boxes


@pytest.fixture(scope='module')
def alone(folder, tmp_path_factory):
    """Return each bag's CSV and result bag from a replay of that bag by itself (the reference)."""
    d, boxes = folder
    out = tmp_path_factory.mktemp('alone')
    for name, box in zip(SIZES, boxes):
        stem = name.removesuffix('.bag')
        assert main([str(d / name), '--init', box, '--csv', str(out / f'{stem}.csv'),
                     '--out-bag', str(out / f'{stem}_result')]) == 0
    return out


def _raw_messages(path) -> list[tuple[str, int, bytes]]:
    """Every message of a bag as (topic, log time, serialized bytes), in the bag's order."""
    reader = open_bag(path)
    try:
        return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]
    finally:
        reader.close()


def _inits(boxes):
    return [arg for box in boxes for arg in ('--init', box)]


@pytest.mark.parametrize(
    'where', [['--jobs', '1'], ['--jobs', '2'], 'cluster'], ids=['serial', 'local', 'cluster']
)
def test_each_csv_is_the_one_of_its_bag_alone(
    folder, alone, tmp_path, where, dask_cluster, capsys
):
    d, boxes = folder
    where = ['--cluster', dask_cluster] if where == 'cluster' else where
    out = tmp_path / 'out'
    assert main([str(d), *_inits(boxes), '--out-dir', str(out), '--out-bags', *where]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        'a.csv',
        'a_result',
        'b.csv',
        'b_result',
        'c.csv',
        'c_result',
    ]
    for stem in ('a', 'b', 'c'):
        assert (out / f'{stem}.csv').read_bytes() == (alone / f'{stem}.csv').read_bytes(), stem
        batch, single = (_raw_messages(p / f'{stem}_result') for p in (out, alone))
        # per image: detections, annotations, debug image, diagnostics (#26)
        assert [m[:2] for m in batch] == [m[:2] for m in single] and len(batch) == 4 * N, stem
        # the diagnostics hold wall-clock times
        detections = [m for m in batch if m[0] == DETECTIONS_TOPIC]
        assert detections == [m for m in single if m[0] == DETECTIONS_TOPIC], stem
    text = capsys.readouterr().out
    assert all(f'  {stem}: {N} images' in text for stem in ('a', 'b', 'c')) and '3 bag(s)' in text


def test_one_box_for_every_bag_and_bags_listed_one_by_one(folder, tmp_path, alone):
    """The bags named one by one (a bag twice counts once); one --init for all of them."""
    d, boxes = folder
    out = tmp_path / 'out'
    assert (
        main(
            [
                str(d / 'a'),
                str(d / 'b'),
                str(d / 'a'),
                '--init',
                boxes[0],
                '--out-dir',
                str(out),
                '--jobs',
                '2',
            ]
        )
        == 0
    )
    assert sorted(p.name for p in out.iterdir()) == ['a.csv', 'b.csv']
    assert (out / 'a.csv').read_bytes() == (alone / 'a.csv').read_bytes()
    # b started from a's box
    assert (out / 'b.csv').read_bytes() != (alone / 'b.csv').read_bytes()


def test_a_bare_mcap_file_in_a_batch(folder, tmp_path, alone):
    """
    A bare .mcap file (no metadata.yaml beside it), as open_bag reads it.

    Is a bag of the batch too.
    """
    d, boxes = folder
    bare = tmp_path / 'bare' / 'a.mcap'
    bare.parent.mkdir()
    shutil.copy(next((d / 'a').glob('*.mcap')), bare)
    assert find_bags([bare]) == [bare]
    assert (
        main(
            [
                str(bare),
                str(d / 'b'),
                *_inits(boxes[:2]),
                '--out-dir',
                str(tmp_path / 'out'),
                '--jobs',
                '1',
            ]
        )
        == 0
    )
    assert (tmp_path / 'out' / 'a.csv').read_bytes() == (alone / 'a.csv').read_bytes()


def test_find_bags(folder, tmp_path):
    d, _ = folder
    assert find_bags([d]) == [d / 'a', d / 'b', d / 'c.bag']
    assert find_bags([d / 'c.bag', d / 'a' / 'metadata.yaml', d]) == [
        d / 'c.bag',
        d / 'a',
        d / 'b',
    ]
    (tmp_path / 'empty').mkdir()
    with pytest.raises(BagError, match='is not a rosbag2 folder: it has no metadata.yaml'):
        find_bags([tmp_path / 'empty'])


def test_batch_bad_input_exits_2_one_line(folder, tmp_path, capsys):
    d, boxes = folder
    (tmp_path / 'x').mkdir()
    make_bag(shaky_sequence(3), tmp_path / 'x' / 'a')  # a second bag named a
    broken = tmp_path / 'broken'
    broken.mkdir()
    make_bag(shaky_sequence(3), broken / 'y')
    # a good bag and a truncated one
    make_bag(shaky_sequence(3), broken / 'z')
    mcap = next((broken / 'z').glob('*.mcap'))
    os.truncate(mcap, mcap.stat().st_size // 2)
    out = ['--out-dir', str(tmp_path / 'out')]
    cases = [
        ([str(d), '--init', boxes[0], '--csv', str(tmp_path / 'o.csv')], '--out-dir DIR'),
        (
            [
                str(d / 'a'),
                '--init',
                boxes[0],
                '--init',
                boxes[1],
                '--csv',
                str(tmp_path / 'o.csv'),
            ],
            '--init is given 2 times for one bag',
        ),
        (
            [str(d / 'a'), '--init', boxes[0], '--jobs', '2', '--csv', str(tmp_path / 'o.csv')],
            'apply to a batch',
        ),
        ([str(d), *_inits(boxes[:2]), *out], 'one box for every bag or one per bag (3), got 2'),
        (
            [str(d), '--init', boxes[0], '--csv', str(tmp_path / 'o.csv'), *out],
            '--csv replay one bag',
        ),
        ([str(d), str(tmp_path / 'x'), '--init', boxes[0], *out], "two bags are named 'a'"),
        ([str(tmp_path / 'nothing'), '--init', boxes[0], *out], 'does not exist'),
        ([str(d), '--init', '1,2,3', *out], '--init must be 4 numbers'),
        ([str(broken), '--init', boxes[0], *out, '--jobs', '2'], 'truncated or corrupt'),
    ]
    for argv, text in cases:
        assert text in cli_error(main, argv, capsys, 'iemd-replay: error:'), argv
    # the failed bag named
    assert cli_error(main, cases[-1][0], capsys).startswith('iemd-replay: error: z: ')
    assert not (tmp_path / 'o.csv').exists()
    (tmp_path / 'taken' / 'a_result').mkdir(parents=True)
    assert 'exists already' in cli_error(
        main,
        [str(d), *_inits(boxes), '--out-dir', str(tmp_path / 'taken'), '--out-bags'],
        capsys,
        'iemd-replay: error:',
    )
    # checked before any bag ran
    assert not (tmp_path / 'taken' / 'a.csv').exists()
