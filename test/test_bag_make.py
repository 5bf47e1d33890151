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
iemd-make-bag: stamps on the camera clock, IMU shifted by the recording's offset, message contents.

Formats (mcap, sqlite3, ROS 1), compressed images (--compress jpeg/png), sources (synthetic, image
folder + CSV, CMU desk, phone, OTB), bad input.
"""
from pathlib import Path

from bag_fixtures import (
    by_topic,
    IMG,
    IMG_COMPRESSED,
    IMU,
    INFO,
    make_bag,
    read_all,
    shaky_sequence,
    stamps,
)
import cv2
from helpers import cli_error, REPO, run_module
from iemd_ros.apps.make_bag import main
from iemd_ros.bags.io import custom_data, open_bag
from iemd_ros.bags.make import source_from_folder, write_bag
from iemd_ros.datasets.otb import load_sequence, parse_groundtruth
from iemd_ros.datasets.recordings import load_recording
from iemd_ros.messages.conversions import image_from_msg
import numpy as np
import pytest


@pytest.fixture(scope='module')
def seq():
    return shaky_sequence(8)


# grey levels, at quality 95 on these frames (docs/decisions.md#test-bounds)
JPEG_MEAN_ERROR = 4.0


def _check_synthetic_bag(path, seq, encoding='bgr8', compress=None):
    msgs = read_all(path)
    img_topic = IMG_COMPRESSED if compress else IMG
    imgs, infos, imus = by_topic(msgs, img_topic), by_topic(msgs, INFO), by_topic(msgs, IMU)
    assert len(imgs) == len(infos) == len(seq.frames)
    np.testing.assert_array_equal(stamps(imgs), seq.frame_stamps_ns)      # camera clock
    np.testing.assert_array_equal(stamps(infos), seq.frame_stamps_ns)
    # IMU: shifted onto the camera clock by -t_d (t_imu = t_cam + t_d), only within 0.5 s of the
    # frames
    t_cam = seq.gyro_t_ns - seq.time_offset_ns
    keep = (t_cam >= seq.frame_stamps_ns[0] - 500_000_000) & (
        t_cam <= seq.frame_stamps_ns[-1] + 500_000_000
    )
    np.testing.assert_array_equal(stamps(imus), t_cam[keep])
    w = np.array(
        [[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in imus]
    )
    np.testing.assert_array_equal(w, seq.gyro[keep])
    assert all(
        m.angular_velocity_covariance[0] == 0 and m.orientation_covariance[0] == -1 for m in imus
    )
    assert all(m.linear_acceleration_covariance[0] == -1 for m in imus)  # no accelerometer
    for k, m in enumerate(imgs):
        want = (
            seq.frames[k]
            if encoding == 'bgr8'
            else cv2.cvtColor(seq.frames[k], cv2.COLOR_BGR2GRAY)
        )
        if compress:  # image_transport's format string; PNG lossless, JPEG close
            assert (
                m.format
                == f'{encoding}; {compress} compressed {"bgr8" if encoding == "bgr8" else ""}'
            )
            got = image_from_msg(m)
            assert got.shape == want.shape
            if compress == 'png':
                np.testing.assert_array_equal(got, want)
            else:
                assert np.abs(got.astype(int) - want).mean() < JPEG_MEAN_ERROR
            continue
        assert m.encoding == encoding and (m.height, m.width) == seq.frames[k].shape[:2]
        np.testing.assert_array_equal(m.data.reshape(want.shape), want)
        assert m.step == want.shape[1] * (3 if encoding == 'bgr8' else 1)
    k_field = infos[0].k if hasattr(infos[0], 'k') else infos[0].K
    np.testing.assert_allclose(np.asarray(k_field).reshape(3, 3), seq.K)
    # log times strictly increase; images/infos are logged at their stamp (+ns tie-breaks)
    log = np.array([t for _, _, t, _ in msgs])
    assert np.all(np.diff(log) > 0)
    assert {t for t, _, _, _ in msgs} == {img_topic, INFO, IMU}
    img_log = np.array([t for topic, _, t, _ in msgs if topic == img_topic])
    assert np.all((img_log - seq.frame_stamps_ns >= 0) & (img_log - seq.frame_stamps_ns < 1000))
    return msgs


@pytest.mark.parametrize(
    'fmt,name', [('mcap', 'b_mcap'), ('sqlite3', 'b_sqlite'), ('ros1', 'b.bag')]
)
def test_synthetic_bag_formats(seq, tmp_path, fmt, name):
    info = make_bag(seq, tmp_path / name, fmt)
    assert info['frames'] == 8 and info['imu_time_shift_ns'] == -seq.time_offset_ns
    msgs = _check_synthetic_bag(tmp_path / name, seq)
    if fmt == 'ros1':  # ROS 1: Header.seq counts per topic, CameraInfo uses K/D
        assert [m.header.seq for m in by_topic(msgs, IMG)] == list(range(8))
    else:
        reader = open_bag(tmp_path / name)
        meta = custom_data(reader)
        reader.close()
        assert meta['iemd_ros.imu_time_shift_ns'] == str(-seq.time_offset_ns)
        assert (tmp_path / name / 'metadata.yaml').is_file()


@pytest.mark.parametrize(
    'fmt,name,compress,encoding',
    [
        ('mcap', 'c', 'png', 'bgr8'),
        ('sqlite3', 'c', 'jpeg', 'mono8'),
        ('ros1', 'c.bag', 'jpeg', 'bgr8'),
        ('ros1', 'c.bag', 'png', 'mono8'),
    ],
)
def test_compressed_bags(seq, tmp_path, fmt, name, compress, encoding):
    """
    --compress: CompressedImage on IMAGE_TOPIC/compressed.

    Camera info and IMU as in a raw bag.
    """
    info = make_bag(seq, tmp_path / name, fmt, encoding=encoding, compress=compress)
    assert info['image_topic'] == IMG_COMPRESSED and info['counts'][IMG_COMPRESSED] == 8
    msgs = _check_synthetic_bag(tmp_path / name, seq, encoding, compress)
    assert {t: ty for t, ty, _, _ in msgs}[IMG_COMPRESSED] == 'sensor_msgs/msg/CompressedImage'


def test_mono8_and_excerpt(seq, tmp_path):
    info = make_bag(seq, tmp_path / 'm', encoding='mono8', first=2, count=4, imu_margin_s=0.0)
    assert info['frames'] == 4
    msgs = read_all(tmp_path / 'm')
    imgs, imus = by_topic(msgs, IMG), by_topic(msgs, IMU)
    np.testing.assert_array_equal(stamps(imgs), seq.frame_stamps_ns[2:6])
    np.testing.assert_array_equal(
        imgs[0].data.reshape(240, 320), cv2.cvtColor(seq.frames[2], cv2.COLOR_BGR2GRAY)
    )
    t = stamps(imus)  # margin 0: only samples between the first and the last frame
    assert t.min() >= seq.frame_stamps_ns[2] and t.max() <= seq.frame_stamps_ns[5] and len(t) > 10


def _write_folder(seq, folder: Path, offset_ms: float, step_back: bool = False):
    """
    Return an image folder + stamps file + IMU CSV (IMU clock) + camera YAML.

    As a user brings them.
    """
    (folder / 'images').mkdir(parents=True)
    for k, f in enumerate(seq.frames):
        cv2.imwrite(str(folder / 'images' / f'frame_{k:04d}.png'), f)
    (folder / 'stamps.txt').write_text(''.join(f'{t / 1e9:.9f}\n' for t in seq.frame_stamps_ns))
    t_imu = seq.gyro_t_ns.copy()
    # a clock stepping back by 3 ms at one row (as the CMU desk log)
    if step_back:
        t_imu[40] = t_imu[39] - 3_000_000
    rows = ['# t_s, wx, wy, wz', 't,wx,wy,wz'] + [
        f'{t / 1e9:.9f},' + ','.join(repr(float(v)) for v in w) for t, w in zip(t_imu, seq.gyro)
    ]
    (folder / 'imu.csv').write_text('\n'.join(rows) + '\n')
    import yaml

    (folder / 'camera.yaml').write_text(yaml.safe_dump(seq.camera.to_camera_info()))
    return t_imu


def test_image_folder_with_imu_csv(seq, tmp_path):
    t_imu = _write_folder(seq, tmp_path / 'rec', offset_ms=4.0, step_back=True)
    rc = main(
        [
            str(tmp_path / 'rec' / 'images'),
            str(tmp_path / 'bag'),
            '--stamps',
            str(tmp_path / 'rec' / 'stamps.txt'),
            '--imu-csv',
            str(tmp_path / 'rec' / 'imu.csv'),
            '--camera-yaml',
            str(tmp_path / 'rec' / 'camera.yaml'),
            '--time-offset-ms',
            '4',
            '--imu-margin',
            '10',
        ]
    )
    assert rc == 0
    msgs = read_all(tmp_path / 'bag')
    imus = by_topic(msgs, IMU)
    # every sample, in the recorded row order (the step back kept), shifted by -4 ms
    np.testing.assert_array_equal(stamps(imus), t_imu - 4_000_000)
    assert (
        imus[0].header.frame_id == 'imu_link'
        and by_topic(msgs, IMG)[0].header.frame_id == 'camera_optical_frame'
    )
    np.testing.assert_array_equal(by_topic(msgs, IMG)[3].data.reshape(240, 320, 3), seq.frames[3])
    # the stepped-back sample is logged when it arrived (after its predecessor), so log order = row
    # order
    imu_log = [t for topic, _, t, _ in msgs if topic == IMU]
    assert np.all(np.diff(imu_log) > 0)


def test_cmu_desk_excerpt(imu_root, tmp_path):
    rec = load_recording(imu_root / 'cmu_hwangbo_desk')
    src = source_from_folder(imu_root / 'cmu_hwangbo_desk')
    info = write_bag(src, tmp_path / 'desk', 'mcap', first=10, count=5, gt_out=tmp_path / 'gt.txt')
    assert info['imu_time_shift_ns'] == 20_000_000  # t_imu = t_file - 20 ms
    msgs = read_all(tmp_path / 'desk')
    imgs, imus, infos = by_topic(msgs, IMG), by_topic(msgs, IMU), by_topic(msgs, INFO)
    np.testing.assert_array_equal(stamps(imgs), rec.frame_stamps_ns[10:15])
    np.testing.assert_array_equal(imgs[0].data.reshape(480, 640, 3), rec.load_frame(10))
    t = stamps(imus)
    sel = np.nonzero(np.isin(rec.imu_t_ns + 20_000_000, t))[0]
    np.testing.assert_array_equal(t, rec.imu_t_ns[sel] + 20_000_000)
    np.testing.assert_array_equal([m.angular_velocity.x for m in imus], rec.gyro[sel, 0])
    np.testing.assert_array_equal([m.linear_acceleration.z for m in imus], rec.accel[sel, 2])
    # camera-frame gyro: the IMU frame_id is the camera's (identity extrinsic)
    assert imus[0].header.frame_id == imgs[0].header.frame_id == 'camera_optical_frame'
    np.testing.assert_allclose(np.asarray(infos[0].k).reshape(3, 3), rec.camera.K)
    np.testing.assert_allclose(infos[0].d, rec.camera.D)
    gt, flags = parse_groundtruth(tmp_path / 'gt.txt', with_flags=True)
    np.testing.assert_allclose(gt, rec.gt_boxes[10:15], atol=1e-9)
    assert list(flags) == list(rec.gt_flags[10:15])
    # a margin that is not a finite number of seconds is refused before the bag is written
    for margin in (-1.0, float('inf'), float('nan')):
        with pytest.raises(ValueError, match='--imu-margin must be a finite number >= 0'):
            write_bag(
                src, tmp_path / f'bad{margin}', 'mcap', first=10, count=5, imu_margin_s=margin
            )
        assert not (tmp_path / f'bad{margin}').exists()


def test_phone_excerpt(imu_root, tmp_path):
    rec = load_recording(imu_root / 'phone_gyrostab_20200109_145447')
    info = write_bag(source_from_folder(rec.root), tmp_path / 'phone', 'sqlite3', count=3)
    assert info['imu_time_shift_ns'] == -rec.time_offset_ns == -13_000_000
    msgs = read_all(tmp_path / 'phone')
    assert stamps(by_topic(msgs, IMG))[0] == rec.frame_stamps_ns[0]
    # 412 Hz over ~1.07 s
    assert by_topic(msgs, IMG)[0].width == 800 and len(by_topic(msgs, IMU)) > 400


def test_otb_folder(otb_root, tmp_path):
    seq = load_sequence(otb_root / 'Deer')
    assert (
        main(
            [
                str(otb_root / 'Deer'),
                str(tmp_path / 'deer'),
                '--count',
                '5',
                '--fps',
                '25',
                '--gt-out',
                str(tmp_path / 'gt.txt'),
            ]
        )
        == 0
    )
    msgs = read_all(tmp_path / 'deer')
    assert {t for t, _, _, _ in msgs} == {IMG}  # OTB: no IMU, no calibration
    np.testing.assert_array_equal(np.diff(stamps(by_topic(msgs, IMG))), 40_000_000)
    np.testing.assert_allclose(parse_groundtruth(tmp_path / 'gt.txt'), seq.gt_boxes[:5], atol=1e-9)


def _three_frame_folder(seq, tmp_path) -> Path:
    """Write an image folder (no stamps, IMU or calibration) with the first 3 frames of ``seq``."""
    folder = tmp_path / 'imgs'
    folder.mkdir()
    for k in range(3):
        cv2.imwrite(str(folder / f'{k}.png'), seq.frames[k])
    return folder


def test_bad_input(seq, tmp_path, capsys):
    (tmp_path / 'empty').mkdir()
    make_bag(seq, tmp_path / 'exists')
    cases = [
        ([str(tmp_path / 'nope'), str(tmp_path / 'o1')], 'is not a folder'),
        ([str(tmp_path / 'empty'), str(tmp_path / 'o2')], 'holds no image'),
        ([str(tmp_path / 'empty'), str(tmp_path / 'exists')], 'holds no image'),
        ([str(tmp_path / 'empty'), str(tmp_path / 'o3'), '--format', 'zip'], 'invalid choice'),
        (
            [str(tmp_path / 'empty'), str(tmp_path / 'o3'), '--imu-margin', 'inf'],
            'must be a finite number >= 0',
        ),
    ]
    for argv, text in cases:
        assert text in cli_error(main, argv, capsys, 'iemd-make-bag: error:')
    # output exists / count too large / ROS 1 path without .bag, through a real source
    folder = _three_frame_folder(seq, tmp_path)
    for argv, text in [
        ([str(folder), str(tmp_path / 'exists')], 'exists already'),
        ([str(folder), str(tmp_path / 'o4'), '--count', '5'], 'exceeds the 3 frames'),
        ([str(folder), str(tmp_path / 'o5'), '--format', 'ros1'], 'must be a file ending in .bag'),
        (
            [str(folder), str(tmp_path / 'o6'), '--imu-csv', str(tmp_path / 'none.csv')],
            'cannot read IMU',
        ),
        ([str(folder), str(tmp_path / 'o7'), '--compress', 'gif'], "invalid choice: 'gif'"),
        (
            [str(folder), str(tmp_path / 'o8'), '--jpeg-quality', '80'],
            '--jpeg-quality applies to --compress jpeg only (got --compress off)',
        ),
        (
            [str(folder), str(tmp_path / 'o9'), '--compress', 'png', '--jpeg-quality', '80'],
            '--jpeg-quality applies to --compress jpeg only (got --compress png)',
        ),
        (
            [str(folder), str(tmp_path / 'o10'), '--compress', 'jpeg', '--jpeg-quality', '0'],
            'JPEG quality must be in [1, 100], got 0',
        ),
        (
            [
                str(folder),
                str(tmp_path / 'o11'),
                '--compress',
                'jpeg',
                '--image-topic',
                '/c/image/compressed',
            ],
            'ends in /compressed: give the raw topic',
        ),
        (
            [
                str(folder),
                str(tmp_path / 'o12'),
                '--compress',
                'png',
                '--image-topic',
                'compressed',
            ],
            'ends in /compressed: give the raw topic',
        ),
    ]:
        assert text in cli_error(main, argv, capsys)
    assert not any((tmp_path / f'o{k}').exists() for k in range(4, 13))  # no partial output
    for argv, text in [
        ([str(folder), str(tmp_path / 'o13'), '--fps', 'inf'], 'must be a finite number > 0'),
        (
            [str(folder), str(tmp_path / 'o14'), '--time-offset-ms', 'nan'],
            'must be a finite number',
        ),
    ]:
        assert text in cli_error(main, argv, capsys, 'iemd-make-bag: error:')
    # the library refuses what the command line refuses
    with pytest.raises(ValueError, match='--fps must be a finite number > 0'):
        source_from_folder(folder, fps=float('inf'))
    with pytest.raises(ValueError, match='--time-offset-ms must be a finite number'):
        source_from_folder(folder, time_offset_ms=float('inf'))


def test_cli_compress_and_quality(seq, tmp_path, capsys):
    """
    --compress jpeg --jpeg-quality: lower quality, smaller frames.

    The summary names topic and codec.
    """
    folder = _three_frame_folder(seq, tmp_path)
    sizes = {}
    for q in ('95', '50'):
        assert (
            main(
                [
                    str(folder),
                    str(tmp_path / f'q{q}'),
                    '--compress',
                    'jpeg',
                    '--jpeg-quality',
                    q,
                    '--image-topic',
                    '/cam/image_raw',
                ]
            )
            == 0
        )
        assert '3 images 320x240 bgr8 jpeg on /cam/image_raw/compressed' in capsys.readouterr().out
        msgs = by_topic(read_all(tmp_path / f'q{q}'), '/cam/image_raw/compressed')
        assert [m.format for m in msgs] == ['bgr8; jpeg compressed bgr8'] * 3
        sizes[q] = sum(len(m.data) for m in msgs)
    assert (
        main(
            [
                str(folder),
                str(tmp_path / 'qd'),
                '--compress',
                'jpeg',
                '--image-topic',
                '/cam/image_raw',
            ]
        )
        == 0
    )
    assert (
        sum(len(m.data) for m in by_topic(read_all(tmp_path / 'qd'), '/cam/image_raw/compressed'))
        == sizes['95']
    )
    assert sizes['50'] < 0.5 * sizes['95']


def test_cli_process(tmp_path):
    """The real process: exit status 2 and one line, no traceback."""
    out = run_module(
        'iemd_ros.apps.make_bag', str(tmp_path / 'missing'), str(tmp_path / 'o'), cwd=REPO
    )
    assert out.returncode == 2 and 'Traceback' not in out.stderr
    assert out.stderr.strip().count('\n') == 0 and 'is not a folder' in out.stderr
