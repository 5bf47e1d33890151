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

"""Message-field <-> numpy conversions (no ROS needed)."""
import array
from types import SimpleNamespace

import cv2
from iemd_ros.common.boxes import box_centre, centre_box, check_box
from iemd_ros.messages.conversions import (
    array_to_compressed_fields,
    array_to_image_fields,
    bbox_to_box,
    bbox_values,
    box_to_bbox,
    camera_model_from_info,
    compressed_to_array,
    detection_values,
    fill_bbox,
    fill_image_msg,
    image_from_msg,
    image_to_array,
    imu_sample,
    ns_to_stamp,
    stamp_to_ns,
)
from iemd_ros.pipeline import FrameResult, Rejection, TrackState
import numpy as np
import pytest


@pytest.fixture
def bgr():
    rng = np.random.default_rng(1)
    return rng.integers(0, 256, (5, 7, 3), dtype=np.uint8)


def _fields(pix, pad=0):
    h = pix.shape[0]
    rows = pix.reshape(h, -1).view(np.uint8).reshape(h, -1)
    padded = np.concatenate([rows, np.full((h, pad), 0xEE, np.uint8)], axis=1)
    return padded.shape[1], padded.tobytes()


@pytest.mark.parametrize('pad', [0, 3])
@pytest.mark.parametrize(
    'container', [bytes, lambda b: array.array('B', b), lambda b: np.frombuffer(b, np.uint8)]
)
def test_colour_encodings_give_bgr(bgr, pad, container):
    alpha = np.full(bgr.shape[:2] + (1,), 200, np.uint8)
    sources = {
        'bgr8': bgr,
        'rgb8': bgr[..., ::-1],
        'bgra8': np.concatenate([bgr, alpha], 2),
        'rgba8': np.concatenate([bgr[..., ::-1], alpha], 2),
    }
    for enc, pix in sources.items():
        step, data = _fields(np.ascontiguousarray(pix), pad)
        out = image_to_array(enc, 5, 7, step, container(data), False)
        assert out.shape == (5, 7, 3) and out.dtype == np.uint8
        np.testing.assert_array_equal(out, bgr, err_msg=enc)


def test_mono_encodings():
    grey = np.arange(35, dtype=np.uint8).reshape(5, 7) * 7
    step, data = _fields(grey, 1)
    np.testing.assert_array_equal(image_to_array('mono8', 5, 7, step, data), grey)
    twelve = grey.astype(np.uint16) * 16 + 3  # a 12-bit sensor: max 3811 < 4096
    for big in (False, True):
        raw = twelve.astype('>u2' if big else '<u2')
        step, data = _fields(raw)
        out = image_to_array('mono16', 5, 7, step, data, big)
        # highest used bit moved to bit 7: >> 4 here, not a fixed >> 8
        np.testing.assert_array_equal(out, (twelve >> 4).astype(np.uint8))
    full = np.full((2, 2), 65535, np.uint16)
    assert image_to_array('mono16', 2, 2, 4, full.tobytes()).max() == 255


def test_bad_images_raise_clear_errors(bgr):
    step, data = _fields(bgr)
    with pytest.raises(ValueError, match="unsupported image encoding 'yuv422'"):
        image_to_array('yuv422', 5, 7, step, data)
    with pytest.raises(
        ValueError, match='step 20 is shorter than one bgr8 row of 7 px \\(21 bytes\\)'
    ):
        image_to_array('bgr8', 5, 7, 20, data)
    with pytest.raises(ValueError, match='has 105 bytes, expected step\\*height = 24\\*5 = 120'):
        image_to_array('bgr8', 5, 7, 24, data)
    with pytest.raises(ValueError, match=r'image height = 0 px is out of \[2, 16384\] px'):
        image_to_array('mono8', 0, 7, 7, b'')
    with pytest.raises(ValueError, match='bytes-like'):
        image_to_array('mono8', 2, 2, 2, object())


def test_array_to_image_fields_round_trip(bgr):
    for enc in ('bgr8', 'rgb8'):
        f = array_to_image_fields(bgr, enc)
        assert isinstance(f['data'], bytes) and f['step'] == 21
        np.testing.assert_array_equal(image_to_array(**f), bgr)
    g = array_to_image_fields(bgr[..., 0])
    assert g['encoding'] == 'mono8'
    np.testing.assert_array_equal(image_to_array(**g), bgr[..., 0])
    with pytest.raises(ValueError, match='cannot write'):
        array_to_image_fields(bgr, 'mono8')
    with pytest.raises(ValueError, match='uint8'):
        array_to_image_fields(bgr.astype(np.float32))


def test_fill_image_msg_round_trips_through_a_real_image_message(bgr):
    Image = pytest.importorskip('sensor_msgs.msg').Image

    for frame, enc in ((bgr, 'rgb8'), (bgr[..., 1], None)):
        msg = fill_image_msg(Image(), frame, enc)
        assert msg.encoding == (enc or 'mono8') and (msg.height, msg.width) == frame.shape[:2]
        np.testing.assert_array_equal(image_from_msg(msg), frame)  # rgb8 comes back as BGR


def test_camera_model_from_info():
    k = [500.0, 0, 319.5, 0, 510.0, 239.5, 0, 0, 1]
    cam = camera_model_from_info(k, [0.1, -0.05, 0.001, 0.002, 0.0], 'plumb_bob', 640, 480)
    np.testing.assert_array_equal(cam.K, np.reshape(k, (3, 3)))
    assert cam.has_distortion and (cam.width, cam.height) == (640, 480)
    assert not camera_model_from_info(k, [], '', 0, 0).has_distortion
    with pytest.raises(ValueError, match='not calibrated'):
        camera_model_from_info([0.0] * 9, [], 'plumb_bob', 640, 480)
    with pytest.raises(ValueError, match='only plumb_bob'):
        camera_model_from_info(k, [0.1, 0.0, 0.0, 0.0], 'equidistant', 640, 480)
    with pytest.raises(ValueError, match='9 values'):
        camera_model_from_info(k[:6], [], 'plumb_bob', 640, 480)


def test_stamps():
    assert stamp_to_ns(12, 345) == 12_000_000_345
    assert ns_to_stamp(12_000_000_345) == (12, 345)
    assert ns_to_stamp(stamp_to_ns(7, 999_999_999)) == (7, 999_999_999)


def test_box_bbox_round_trip():
    # a 4 px wide box starting at pixel 10 covers pixels 10..13: centre 11.5
    assert box_to_bbox((10, 20, 4, 6)) == (11.5, 22.5, 4.0, 6.0)
    assert bbox_to_box(11.5, 22.5, 4.0, 6.0) == (10.0, 20.0, 4.0, 6.0)
    # the values sent, not derived ones
    with pytest.raises(ValueError, match=r'positive size .*got \(1, 2, 0, 5\)'):
        bbox_to_box(1, 2, 0, 5)
    with pytest.raises(ValueError, match='finite'):
        bbox_to_box(float('nan'), 1, 3, 5)


def test_bbox_message_fields_round_trip():
    BoundingBox2D = pytest.importorskip('vision_msgs.msg').BoundingBox2D
    bbox = BoundingBox2D()
    bbox.center.theta = 0.25
    fill_bbox(bbox, box_to_bbox((10, 20, 4, 6)))
    assert (bbox.center.position.x, bbox.center.position.y, bbox.size_x, bbox.size_y) == (
        11.5,
        22.5,
        4.0,
        6.0,
    )
    assert bbox.center.theta == 0.25  # the orientation is not the box's to set
    assert bbox_to_box(*bbox_values(bbox)) == (10.0, 20.0, 4.0, 6.0)


def test_detection_values_only_while_tracking():
    box = (10.0, 20.0, 4.0, 6.0)
    v = detection_values(FrameResult(stamp_ns=0, state=TrackState.TRACKING, box=box, score=0.75))
    assert v.bbox == (11.5, 22.5, 4.0, 6.0) and v.score == 0.75 and type(v.score) is float
    assert detection_values(None) is None
    assert (
        detection_values(FrameResult(stamp_ns=0, state=TrackState.LOST, box=box, lost=True))
        is None
    )
    assert (
        detection_values(
            FrameResult(
                stamp_ns=0,
                state=TrackState.TRACKING,
                box=box,
                score=0.75,
                rejection=Rejection.STAMP,
                reason='stamp repeats',
            )
        )
        is None
    )


def test_box_centre_and_centre_box_are_inverse():
    boxes = np.array([[10, 20, 4, 6], [-0.5, 3.25, 7, 1]])
    np.testing.assert_array_equal(box_centre(boxes), [[11.5, 22.5], [2.5, 3.25]])
    np.testing.assert_array_equal(centre_box(box_centre(boxes), boxes[:, 2:]), boxes)


@pytest.mark.parametrize(
    'box,message',
    [
        ((1, 2, 3), 'marker must be 4 numbers (x, y, w, h), got (1, 2, 3)'),
        ('abcd', "marker must be 4 numbers (x, y, w, h), got 'abcd'"),
        ((1, float('inf'), 3, 4), 'marker has non-finite values: (1, inf, 3, 4)'),
        ((1, 2, 0, 4), 'marker must have a positive size (w, h > 0), got (1, 2, 0, 4)'),
    ],
)
def test_check_box_names_what_is_wrong(box, message):
    with pytest.raises(ValueError) as exc:
        check_box(box, 'marker')
    assert str(exc.value) == message
    np.testing.assert_array_equal(check_box([1, 2, 3, 4]), [1.0, 2.0, 3.0, 4.0])


def _encoded(ext, img, *params):
    ok, buf = cv2.imencode(ext, img, list(params))
    assert ok
    return buf.tobytes()


def test_compressed_images_decode_to_bgr_frames():
    rng = np.random.default_rng(3)
    bgr = rng.integers(0, 256, (24, 32, 3), dtype=np.uint8)
    grey = bgr[..., 1].copy()
    # PNG is lossless: exactly the frame back, colour (BGR) and grey, and an alpha channel dropped.
    np.testing.assert_array_equal(
        compressed_to_array('bgr8; png compressed bgr8', _encoded('.png', bgr)), bgr
    )
    np.testing.assert_array_equal(compressed_to_array('png', _encoded('.png', grey)), grey)
    bgra = np.dstack([bgr, np.full(grey.shape, 7, np.uint8)])
    np.testing.assert_array_equal(
        compressed_to_array('bgra8; png compressed bgra8', _encoded('.png', bgra)), bgr
    )
    # 16-bit PNG (a 12-bit sensor): the same 8 bits as the raw mono16 message.
    mono16 = rng.integers(0, 4096, (24, 32), dtype=np.uint16)
    np.testing.assert_array_equal(
        compressed_to_array('mono16; png compressed mono16', _encoded('.png', mono16)),
        image_to_array('mono16', 24, 32, 64, mono16.tobytes()),
    )
    # JPEG: lossy, but the channel order holds (a pure blue patch stays blue).
    blue = np.zeros((32, 32, 3), np.uint8)
    blue[..., 0] = 255
    out = compressed_to_array(
        'rgb8; jpeg compressed bgr8', _encoded('.jpg', blue, cv2.IMWRITE_JPEG_QUALITY, 95)
    )
    assert out.shape == blue.shape and out[..., 0].min() > 240 and out[..., 1:].max() < 15


def _jpeg_declaring(width: int, height: int) -> bytes:
    """Return a small JPEG whose frame header (SOF0) claims ``width`` x ``height`` pixels."""
    data = bytearray(_encoded('.jpg', np.zeros((8, 8), np.uint8)))
    sof = data.find(b'\xff\xc0')
    data[sof + 5: sof + 9] = height.to_bytes(2, 'big') + width.to_bytes(2, 'big')
    return bytes(data)


@pytest.mark.parametrize(
    'fmt, data, match',
    [
        ('jpeg', b'', 'has no data'),
        (
            'jpeg',
            _jpeg_declaring(65000, 65000),
            'cannot decode the compressed image .*CV_IO_MAX_IMAGE_PIXELS',
        ),
        ('jpeg', b'\xff\xd8 not really a jpeg', 'cannot decode the compressed image'),
        ('16UC1; compressedDepth png', b'\x00' * 16, 'depth map'),
    ],
)
def test_bad_compressed_images_are_refused(fmt, data, match):
    with pytest.raises(ValueError, match=match):
        compressed_to_array(fmt, data)


def test_frames_compress_as_image_transport_writes_them():
    rng = np.random.default_rng(5)
    bgr = rng.integers(0, 256, (16, 24, 3), dtype=np.uint8)
    png = array_to_compressed_fields(bgr, 'png')
    assert png['format'] == 'bgr8; png compressed bgr8' and isinstance(png['data'], bytes)
    np.testing.assert_array_equal(compressed_to_array(png['format'], png['data']), bgr)
    grey = array_to_compressed_fields(bgr[..., 0].copy(), 'jpeg', quality=100)
    # the plugin names no target for grey
    assert grey['format'] == 'mono8; jpeg compressed '
    assert (
        np.abs(compressed_to_array(grey['format'], grey['data']).astype(int) - bgr[..., 0]).mean()
        < 2.0
    )
    small, large = (
        len(array_to_compressed_fields(bgr, 'jpeg', quality=q)['data']) for q in (10, 95)
    )
    # the quality is applied
    assert small < large
    for args, match in [
        ((bgr, 'webp'), 'codec must be'),
        ((bgr, 'jpeg', 0), 'quality must be'),
        ((bgr.astype(np.float32),), 'uint8'),
    ]:
        with pytest.raises(ValueError, match=match):
            array_to_compressed_fields(*args)


def test_compressed_image_message():
    CompressedImage = pytest.importorskip('sensor_msgs.msg').CompressedImage
    bgr = np.random.default_rng(4).integers(0, 256, (12, 20, 3), dtype=np.uint8)
    msg = CompressedImage(**array_to_compressed_fields(bgr, 'png'))
    np.testing.assert_array_equal(image_from_msg(msg), bgr)


def test_image_and_imu_messages():
    header = SimpleNamespace(stamp=SimpleNamespace(sec=3, nanosec=250))
    pix = np.arange(12, dtype=np.uint8).reshape(3, 4)
    image = SimpleNamespace(header=header, **array_to_image_fields(pix))
    np.testing.assert_array_equal(image_from_msg(image), pix)
    imu = SimpleNamespace(
        header=header,
        angular_velocity=SimpleNamespace(x=0.1, y=-0.2, z=0.3),
        angular_velocity_covariance=[0.5] + [0.0] * 8,
    )
    assert imu_sample(imu) == (3_000_000_250, (0.1, -0.2, 0.3), 0.5)
