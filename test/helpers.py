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
Plain helpers shared by several test modules (no fixtures, no ROS imports).

Imported as a top-level module (``from helpers import ...``): pytest's default ``prepend`` import
mode puts this folder, which holds conftest.py and no __init__.py, on ``sys.path``.
"""
from __future__ import annotations

import csv
import os
from pathlib import Path
import subprocess
import sys

import cv2
from iemd_ros.messages.conversions import bbox_to_box, bbox_values
import numpy as np

REPO = Path(__file__).resolve().parents[1]
PNG_SIGNATURE = b'\x89PNG\r\n\x1a\n'

# The CMU desk camera (cmu_hwangbo_desk/derived_camera_info.yaml): 640x480, a small skew,
# plumb_bob.
DESK_K_DATA = (570.246, -0.100721, 309.408, 0, 569.324, 217.996, 0, 0, 1)
DESK_D = (-0.346217, 0.128289, 0, 0, 0)
DESK_K = np.reshape(DESK_K_DATA, (3, 3))
# CameraModel keeps the array it is given: no test may change it
DESK_K.setflags(write=False)
DESK_INFO = {
    'image_width': 640,
    'image_height': 480,
    'camera_matrix': {'rows': 3, 'cols': 3, 'data': DESK_K_DATA},
    'distortion_model': 'plumb_bob',
    'distortion_coefficients': {'rows': 1, 'cols': 5, 'data': DESK_D},
}


def texture(seed=0, shape=(240, 320), blob=5):
    """
    Return a smooth random grey texture.

    Uniform noise on a grid ``blob`` times coarser, resized (cubic).
    """
    rng = np.random.default_rng(seed)
    noise = rng.uniform(0, 255, (shape[0] // blob, shape[1] // blob)).astype(np.float32)
    return np.clip(
        cv2.resize(noise, (shape[1], shape[0]), interpolation=cv2.INTER_CUBIC), 0, 255
    ).astype(np.uint8)


def warped(img, m, interpolation=cv2.INTER_CUBIC, border=cv2.BORDER_REFLECT):
    """``img`` moved by the 2x3 affine map ``m`` (image to image pixels), same size."""
    return cv2.warpAffine(
        img, m, (img.shape[1], img.shape[0]), flags=interpolation, borderMode=border
    )


def shifted(img, dx, dy, interpolation=cv2.INTER_CUBIC):
    """``img`` translated by (dx, dy) px, borders reflected."""
    return warped(img, np.float32([[1, 0, dx], [0, 1, dy]]), interpolation)


def rotated(img, center, degrees):
    """
    ``img`` turned by ``degrees`` about ``center`` (positive: from +x towards +y in the image).

    Borders reflected.
    """
    return warped(
        img, cv2.getRotationMatrix2D((float(center[0]), float(center[1])), -degrees, 1.0)
    )


def zoomed(img, center, factor):
    """
    ``img`` magnified by ``factor`` about ``center`` (a target there grows by ``factor``).

    Borders replicated.
    """
    (cx, cy), f = center, factor
    m = np.array([[f, 0.0, cx * (1 - f)], [0.0, f, cy * (1 - f)]])
    return warped(img, m, cv2.INTER_LINEAR, cv2.BORDER_REPLICATE)


def detection_box(detection) -> tuple[float, float, float, float]:
    """
    Return the tracker box ``(x, y, w, h)`` of a ``vision_msgs/Detection2D``.

    (by ``conversions.bbox_to_box``).
    """
    return bbox_to_box(*bbox_values(detection.bbox))


# ----------------------------------------------------------------------------------------------
# command lines
def cli_error(main, argv, capsys, prefix: str = '') -> str:
    """
    Run a CLI ``main(argv)``.

    It must exit with status 2 and print one stderr line (stripped) starting with ``prefix``;
    returns that line.
    """
    assert main(argv) == 2, argv
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0 and err.startswith(prefix), (argv, err)
    return err


def run_module(module: str, *args: str, timeout: float = 120, **kw) -> subprocess.CompletedProcess:
    """
    ``python -m module args...`` as its own process on the repository's sources.

    (text output captured).
    """
    return run_python('-m', module, *args, timeout=timeout, **kw)


def run_python(*args: str, timeout: float = 120, **kw) -> subprocess.CompletedProcess:
    """
    ``python args...`` (``-c code``, ``-m module``) as its own process on the repository's sources.

    (text output captured).
    """
    return subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, 'PYTHONPATH': str(REPO)},
        **kw,
    )


def node_parameter_file(path: Path, **ros_parameters) -> Path:
    """
    Write config/tracker.yaml (the node's parameter file) to ``path``, with ``ros_parameters``.

    They are set in its node section.
    """
    import yaml  # noqa: PLC0415 - only the parameter-file tests need it

    params = yaml.safe_load((REPO / 'config' / 'tracker.yaml').read_text())
    params[next(iter(params))]['ros__parameters'].update(ros_parameters)
    path.write_text(yaml.safe_dump(params))
    return path


def read_csv_rows(path) -> list[list[str]]:
    with open(path, newline='') as f:
        return list(csv.reader(f))


def csv_boxes(path) -> np.ndarray:
    """
    Return the boxes (columns 1-4, x y w h) of an iemd-replay CSV.

    One row per image below the header.
    """
    return np.array([[float(v) for v in r[1:5]] for r in read_csv_rows(path)[1:]])
