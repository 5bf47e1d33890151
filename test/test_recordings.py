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

"""Loaders of the real recordings (CMU desk/aerial, phone)."""
from iemd_ros.datasets.recordings import CMU_TIME_OFFSET_NS, load_recording
import numpy as np
import pytest


def test_cmu_desk(imu_root):
    rec = load_recording(imu_root / 'cmu_hwangbo_desk')
    assert rec.name == 'desk' and len(rec) == 825
    assert rec.frame_files[0].name == 'desk_00001891_00069317.jpg' and rec.frame_files[0].exists()
    assert rec.frame_stamps_ns[0] == 69_317_000_000 and rec.time_offset_ns == CMU_TIME_OFFSET_NS
    assert rec.frame_imu_ns[0] == 69_297_000_000
    assert np.all(np.diff(rec.frame_stamps_ns) > 0)
    assert rec.gyro.shape == (9233, 3) and rec.accel.shape == (9233, 3)
    assert np.sum(np.diff(rec.imu_t_ns) < 0) == 3                  # original row order kept
    assert rec.camera.width == 640 and rec.camera.D[0] == pytest.approx(-0.346217)
    # GT: 1-based "282,285,42.1,51,ok" -> 0-based
    np.testing.assert_allclose(rec.gt_boxes[0], [281.0, 284.0, 42.1, 51.0])
    assert rec.gt_boxes.shape == (825, 4) and np.isfinite(rec.gt_boxes).all()
    assert (rec.gt_flags == 'ok').sum() == 699 and (rec.gt_flags == 'blur').sum() == 126
    assert rec.load_frame(0).shape == (480, 640, 3) and rec.load_frame(0, grey=True).ndim == 2


def test_cmu_aerial_and_phone(imu_root):
    aerial = load_recording(imu_root / 'cmu_hwangbo_aerial')
    assert len(aerial) == 441 and aerial.gt_boxes is None and aerial.camera.width == 320
    phone = load_recording(imu_root / 'phone_gyrostab_20200109_145447')
    assert len(phone) == 103 and phone.frame_files[0].name == 'RE_frame-99.jpg'
    assert phone.frame_stamps_ns[0] == 4_328_043_690_897_000         # exact decimal parse
    assert phone.imu_t_ns[0] == 4_328_040_426_741_000
    assert phone.time_offset_ns == 13_000_000 and not phone.camera.has_distortion
    assert phone.gyro.shape == (29466, 3)


def test_bad_folder(tmp_path):
    with pytest.raises(ValueError, match='not a recording folder'):
        load_recording(tmp_path / 'missing')
    with pytest.raises(ValueError, match='neither a CMU recording'):
        load_recording(tmp_path)
    (tmp_path / 'x_img.log').write_text('x_img\nx_00000001_00000100.jpg\n')
    with pytest.raises(ValueError, match='recording file missing'):
        load_recording(tmp_path)
