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
Loaders for the real camera + gyro recordings in ``shared/data/imu`` (see its SOURCES.md).

* CMU gyro-aided KLT data (Hwangbo, Kim & Kanade): ``cmu_hwangbo_desk`` / ``cmu_hwangbo_aerial``.
  Frames in ``*_img.log`` order; camera stamp = the ``t_ms`` in the file name; the IMU time of a
  frame is ``t_file - 20 ms`` (the authors' ``Time_offset -20``, cross-checked against
  ``derived_frames.csv`` when present), i.e. ``time_offset_ns = -20 ms``; gyro from
  ``derived_imu_camframe.csv`` (already camera frame, rad/s, original row order: the desk clock
  steps back at 3 rows); calibration from ``derived_camera_info.yaml``; the desk ground truth
  ``gt_eagle_head.txt`` (``x,y,w,h,flag``, 1-based) becomes 0-based, NaN where absent.
* Phone sequence ``phone_gyrostab_*``: ``derived_frames.csv`` (start-of-frame stamps),
  ``derived_gyro_camframe.csv`` (camera frame), ``derived_camera.yaml`` (K, fitted time offset).

Stamps are integer nanoseconds, parsed exactly from the decimal text.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path

import cv2
from iemd_ros.datasets.otb import parse_groundtruth
from iemd_ros.gyro import CameraModel, GyroConfig, GyroPredictor
import numpy as np

__all__ = [
    'Recording',
    'load_recording',
    'load_cmu',
    'load_phone',
    'seconds_to_ns',
    'CMU_TIME_OFFSET_NS',
]

#: The authors' ``Time_offset -20`` (ms): ``t_imu = t_file - 20 ms``.
CMU_TIME_OFFSET_NS = -20_000_000


@dataclass
class Recording:
    """
    One recording; ``gyro`` is in the camera frame (so ``R_cam_imu`` is the identity).

    Parameters
    ----------
    name : str
        The recording's name.
    root : Path
        Its folder.
    frame_files : list of Path
        The frame images, in order.
    frame_stamps_ns : ndarray
        Frame stamps, camera clock, int64.
    time_offset_ns : int
        ``t_imu = t_cam + time_offset_ns``.
    imu_t_ns : ndarray
        Gyro stamps, IMU clock, int64, original row order.
    gyro : ndarray
        (M, 3) rad/s, camera frame.
    camera : CameraModel
        The calibration.
    accel : ndarray, optional
        (M, 3) accelerometer samples, where recorded.
    gt_boxes : ndarray, optional
        (N, 4) 0-based x, y, w, h; NaN where absent.
    gt_flags : ndarray, optional
        (N,) str flags of the GT.

    """

    name: str
    root: Path
    frame_files: list
    frame_stamps_ns: np.ndarray  # camera clock, int64
    time_offset_ns: int  # t_imu = t_cam + time_offset_ns
    imu_t_ns: np.ndarray  # IMU clock, int64, original row order
    gyro: np.ndarray  # (M, 3) rad/s, camera frame
    camera: CameraModel
    accel: np.ndarray | None = None
    gt_boxes: np.ndarray | None = None  # (N, 4) 0-based x, y, w, h; NaN where absent
    gt_flags: np.ndarray | None = None  # (N,) str

    def __len__(self) -> int:
        return len(self.frame_files)

    @property
    def frame_imu_ns(self) -> np.ndarray:
        """IMU-clock time of each frame."""
        return self.frame_stamps_ns + self.time_offset_ns

    def gyro_config(self, time_offset_ns: int | None = None) -> GyroConfig:
        """
        Gyro settings for this recording.

        Its time offset and a buffer that holds the whole gyro record.

        Parameters
        ----------
        time_offset_ns : int, optional
            Time offset to use instead of the recording's.

        Returns
        -------
        GyroConfig
            The settings.

        """
        offset = self.time_offset_ns if time_offset_ns is None else time_offset_ns
        return GyroConfig(time_offset_ns=offset, buffer_ns=10**13, buffer_samples=10**7)

    def gyro_predictor(self, time_offset_ns: int | None = None) -> GyroPredictor:
        """
        Return a :class:`GyroPredictor` holding the whole gyro record.

        With the recording's camera and :meth:`gyro_config`.

        Parameters
        ----------
        time_offset_ns : int, optional
            Time offset to use instead of the recording's.

        Returns
        -------
        GyroPredictor
            The predictor, fed every gyro sample.

        """
        pred = GyroPredictor(self.camera, self.gyro_config(time_offset_ns))
        pred.add_imu(self.imu_t_ns, self.gyro)
        return pred

    def load_frame(self, i: int, grey: bool = False) -> np.ndarray:
        """
        Frame ``i`` as BGR uint8 (or grey).

        Parameters
        ----------
        i : int
            Frame index, 0-based.
        grey : bool, optional
            Read it as HxW grey levels.

        Returns
        -------
        ndarray
            HxWx3 BGR or HxW grey uint8.

        Raises
        ------
        ValueError
            If the image cannot be read.

        """
        path = self.frame_files[i]
        img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE if grey else cv2.IMREAD_COLOR)
        if img is None:
            raise ValueError(f'cannot read image {path}')
        return img


def _ms_to_ns(v) -> np.ndarray:
    return np.asarray(v, dtype=np.int64) * 1_000_000


def seconds_to_ns(text: str) -> int:
    """
    Return a time in seconds, written in decimal, as integer nanoseconds.

    Parsed exactly from the text.

    Parameters
    ----------
    text : str
        The time in seconds.

    Returns
    -------
    int
        Nanoseconds.

    Raises
    ------
    ValueError
        For text that is not a number.

    """
    try:
        return int((Decimal(text.strip()) * 1_000_000_000).to_integral_value())
    except InvalidOperation as exc:
        raise ValueError(f'not a time in seconds: {text!r}') from exc


def _need(path: Path) -> Path:
    if not path.exists():
        raise ValueError(f'recording file missing: {path}')
    return path


def _rows(path: Path) -> list[list[str]]:
    """CSV rows without '#' comment lines and without the header row."""
    lines = [
        ln
        for ln in _need(path).read_text().splitlines()
        if ln.strip() and not ln.lstrip().startswith('#')
    ]
    return list(csv.reader(lines[1:]))


def load_cmu(root) -> Recording:
    """
    Load ``cmu_hwangbo_desk`` or ``cmu_hwangbo_aerial``.

    (the sequence name comes from ``*_img.log``).

    Parameters
    ----------
    root : str or path-like
        The recording's folder.

    Returns
    -------
    Recording
        With the authors' offset :data:`CMU_TIME_OFFSET_NS`, the accelerometer and, if present, the
        desk ground truth.

    Raises
    ------
    ValueError
        For missing or inconsistent files: not one ``*_img.log``, frame names not ending in
        ``_<t_ms>.jpg``, ``derived_frames.csv`` disagreeing with the log, IMU rows without 7
        columns, GT of another length.

    """
    root = Path(root)
    logs = sorted(root.glob('*_img.log'))
    if len(logs) != 1:
        raise ValueError(f'{root}: expected one *_img.log file, found {len(logs)}')
    seq = logs[0].name[: -len('_img.log')]
    lines = [ln.strip() for ln in logs[0].read_text().splitlines() if ln.strip()]
    folder, names = lines[0], lines[1:]
    try:
        t_file_ms = np.array([int(Path(n).stem.split('_')[-1]) for n in names], dtype=np.int64)
    except ValueError as exc:
        raise ValueError(f'{logs[0]}: frame names must end in _<t_ms>.jpg') from exc
    files = [root / folder / n for n in names]
    stamps = _ms_to_ns(t_file_ms)
    derived = root / 'derived_frames.csv'
    if derived.exists():
        rows = _rows(derived)
        t_imu = _ms_to_ns([int(r[3]) for r in rows])
        if len(rows) != len(names) or np.any(t_imu != stamps + CMU_TIME_OFFSET_NS):
            raise ValueError(f'{derived} disagrees with {logs[0]} and t_imu = t_file - 20 ms')
    imu = np.array([[float(v) for v in r] for r in _rows(root / 'derived_imu_camframe.csv')])
    if imu.ndim != 2 or imu.shape[1] != 7:
        raise ValueError(
            f'{root / "derived_imu_camframe.csv"}: expected 7 columns t_ms,wx,wy,wz,ax,ay,az'
        )
    camera = CameraModel.from_yaml(root / 'derived_camera_info.yaml')
    gt = flags = None
    if (root / 'gt_eagle_head.txt').exists():
        gt, flags = parse_groundtruth(root / 'gt_eagle_head.txt', with_flags=True)
        if len(gt) != len(files):
            raise ValueError(
                f'{root / "gt_eagle_head.txt"} has {len(gt)} boxes for {len(files)} frames'
            )
    return Recording(
        seq,
        root,
        files,
        stamps,
        CMU_TIME_OFFSET_NS,
        _ms_to_ns(imu[:, 0]),
        imu[:, 1:4],
        camera,
        imu[:, 4:7],
        gt,
        flags,
    )


def load_phone(root) -> Recording:
    """
    Load the phone sequence.

    Its files: ``derived_frames.csv``, ``derived_gyro_camframe.csv``, ``derived_camera.yaml``.

    Parameters
    ----------
    root : str or path-like
        The recording's folder.

    Returns
    -------
    Recording
        With the fitted time offset of ``derived_camera.yaml``.

    Raises
    ------
    ValueError
        For a missing file or a calibration that cannot be read.

    """
    import yaml

    root = Path(root)
    frames = _rows(root / 'derived_frames.csv')
    files = [root / r[0] for r in frames]
    stamps = np.array([seconds_to_ns(r[2]) for r in frames], dtype=np.int64)
    g = _rows(root / 'derived_gyro_camframe.csv')
    imu_t = np.array([seconds_to_ns(r[0]) for r in g], dtype=np.int64)
    gyro = np.array([[float(v) for v in r[1:4]] for r in g])
    path = _need(root / 'derived_camera.yaml')
    try:
        info = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ValueError(f'cannot read {path}: {exc}') from exc
    camera = CameraModel.from_camera_info(info)
    offset = int(round(float(info.get('time_offset_s', 0.0)) * 1e9))
    return Recording(root.name, root, files, stamps, offset, imu_t, gyro, camera)


def load_recording(path) -> Recording:
    """
    Load a recording folder of either kind (CMU or phone), detected from its files.

    Parameters
    ----------
    path : str or path-like
        The recording's folder.

    Returns
    -------
    Recording
        As :func:`load_cmu` or :func:`load_phone` loads it.

    Raises
    ------
    ValueError
        For a path that is not a folder of either kind, or as the loaders raise.

    """
    root = Path(path)
    if not root.is_dir():
        raise ValueError(f'not a recording folder: {root}')
    if list(root.glob('*_img.log')):
        return load_cmu(root)
    if (root / 'derived_gyro_camframe.csv').exists():
        return load_phone(root)
    raise ValueError(
        f'{root}: neither a CMU recording (*_img.log) nor the phone one '
        '(derived_gyro_camframe.csv)'
    )
