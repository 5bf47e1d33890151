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
Loading of OTB-layout sequences (Wu, Lim & Yang 2013), the benchmark of the paper's evaluation.

Layout: ``<root>/<Seq>/img/<frame number>.jpg`` (``0001.jpg``, ``000001.jpg``, ``img000001.jpg``:
the number ends the name) and ``<root>/<Seq>/groundtruth_rect.txt``.  GT lines are ``x, y, w, h``
with 1-based pixel coordinates, separated by commas, tabs or spaces (CRLF and a missing final
newline occur); blank lines are ignored; a line of ``NaN`` values marks a frame where the target is
absent.  Boxes are returned 0-based (``x - 1, y - 1``).

* Line *i* of the GT belongs to the *i*-th image in frame-number order; frame numbers come from the
  file names (David starts at 0300, as in the OTB toolkit's ``configSeqs``).
* A folder with ``groundtruth_rect.<k>.txt`` files (Jogging) holds one target per file; the targets
  are the sequences ``<Seq>-<k>`` (Jogging-1, Jogging-2), sharing the images.
* Every image is evaluated (e.g. all 597 frames of Woman).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
import re
from typing import Iterator

import cv2
import numpy as np

GT_NAME = 'groundtruth_rect.txt'
_MULTI_GT = re.compile(r'^groundtruth_rect\.(\d+)\.txt$')
_TARGET_NAME = re.compile(r'^(.+)-(\d+)$')
_SPLIT = re.compile(r'[,\s]+')
_FRAME_NUMBER = re.compile(r'(\d+)$')  # the digits that end an image's name
IMAGE_SUFFIXES = ('.jpg', '.jpeg', '.png')


@dataclass(frozen=True)
class Sequence:
    """
    One OTB target: its frames (in order) and 0-based ``(x, y, w, h)`` GT boxes.

    Parameters
    ----------
    name : str
        The target's name (``Jogging-1`` for one target of a multi-target folder).
    frame_paths : tuple of Path
        Its images, in frame-number order.
    gt_boxes : ndarray
        (N, 4) GT boxes, all NaN where the target is absent.
    frame_numbers : tuple of int, optional
        Frame numbers, from the file names.
    group : str, optional
        The folder of sequences it comes from (``otb``, ``uav``): means are taken per group.
    frame_rate : float, optional
        Frames per second, when known (the OTB layout does not record it).

    """

    name: str
    frame_paths: tuple[Path, ...]
    gt_boxes: np.ndarray
    frame_numbers: tuple[int, ...] = ()
    group: str = ''
    frame_rate: float | None = None

    def __len__(self) -> int:
        return len(self.frame_paths)

    def head(self, n: int) -> 'Sequence':
        """
        Return the first ``n`` frames (all of them when ``n`` >= len).

        Parameters
        ----------
        n : int
            Number of frames, >= 1.

        Returns
        -------
        Sequence
            The shortened sequence.

        Raises
        ------
        ValueError
            For ``n`` < 1.

        """
        if n < 1:
            raise ValueError(f'{self.name}: number of frames must be >= 1, got {n}')
        return dataclasses.replace(
            self,
            frame_paths=self.frame_paths[:n],
            gt_boxes=self.gt_boxes[:n],
            frame_numbers=self.frame_numbers[:n],
        )

    def frames(self) -> Iterator[np.ndarray]:
        """
        Yield the frames as BGR uint8 arrays (grayscale JPEGs come back 3-channel).

        Yields
        ------
        ndarray
            HxWx3 uint8 frames, in order.

        Raises
        ------
        ValueError
            For an image that cannot be decoded.

        """
        for path in self.frame_paths:
            yield read_frame(path)


def read_frame(path: str | Path) -> np.ndarray:
    """
    Read one image with OpenCV.

    Parameters
    ----------
    path : str or Path
        The image file.

    Returns
    -------
    ndarray
        BGR uint8, HxWx3.

    Raises
    ------
    ValueError
        If it cannot be decoded.

    """
    img = cv2.imread(str(path))
    if img is None:
        raise ValueError(f'cannot read image {path}')
    return img


def parse_groundtruth(path: str | Path, with_flags: bool = False):
    r"""
    Parse a GT file into 0-based ``(x, y, w, h)`` boxes.

    Each non-empty line is split on ``[,\s]+`` and must hold exactly four numbers; a box with a
    non-finite value ("NaN") marks an absent target and becomes all NaN.

    Parameters
    ----------
    path : str or Path
        The GT file, 1-based boxes.
    with_flags : bool, optional
        A line may carry a 5th flag column (default "ok"; "absent" also gives a NaN box), and the
        flags are returned.

    Returns
    -------
    boxes : ndarray
        (N, 4) float boxes.
    flags : ndarray
        (N,) str array; only with ``with_flags``.

    Raises
    ------
    ValueError
        For a file that cannot be read, has no box, or a line that is not four numbers (and the
        optional flag).

    """
    path = Path(path)
    try:
        text = path.read_text(encoding='utf-8', errors='strict')
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f'cannot read ground truth {path}: {exc}') from None
    rows, flags = [], []
    for lineno, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line:
            continue
        fields = _SPLIT.split(line)
        flag = fields.pop() if with_flags and len(fields) == 5 else 'ok'
        try:
            values = [float(f) for f in fields]
        except ValueError:
            raise ValueError(f'{path}:{lineno}: not a number: bad box line {line!r}') from None
        if len(values) != 4:
            want = '4 values x,y,w,h' + (' and an optional flag' if with_flags else '')
            raise ValueError(f'{path}:{lineno}: expected {want}, got {len(fields)} in {line!r}')
        if flag == 'absent' or not np.all(np.isfinite(values)):
            values = [np.nan] * 4
        rows.append(values)
        flags.append(flag)
    if not rows:
        raise ValueError(f'{path}: ground-truth file has no boxes')
    boxes = np.asarray(rows, dtype=float)
    boxes[:, :2] -= 1.0  # 1-based -> 0-based
    return (boxes, np.array(flags)) if with_flags else boxes


def _frames_of(folder: Path) -> tuple[list[Path], list[int]]:
    img_dir = folder / 'img'
    if not img_dir.is_dir():
        raise ValueError(f'{folder} is not an OTB sequence: no img/ folder')
    paths = [p for p in img_dir.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES]
    if not paths:
        raise ValueError(f'{folder} is not an OTB sequence: img/ holds no .jpg/.png images')
    numbers = {p: _FRAME_NUMBER.search(p.stem) for p in paths}
    bad = [p.name for p, m in numbers.items() if m is None]
    if bad:
        raise ValueError(f'{img_dir}: image names must end in their frame number, got {bad[0]!r}')
    paths.sort(key=lambda p: int(numbers[p].group(1)))
    return paths, [int(numbers[p].group(1)) for p in paths]


def _gt_files(folder: Path) -> dict[str, Path]:
    """Target name -> GT file of one sequence folder (Jogging -> Jogging-1, Jogging-2)."""
    multi = sorted(
        (
            (int(m.group(1)), p)
            for p in folder.glob('groundtruth_rect.*.txt')
            if (m := _MULTI_GT.match(p.name))
        ),
    )
    if multi:
        return {f'{folder.name}-{k}': p for k, p in multi}
    single = folder / GT_NAME
    if single.is_file():
        return {folder.name: single}
    return {}


def is_sequence_folder(folder: str | Path) -> bool:
    """
    Whether ``folder`` is an OTB sequence folder.

    Parameters
    ----------
    folder : str or Path
        The folder.

    Returns
    -------
    bool
        True when it has an ``img/`` folder and a ``groundtruth_rect.txt`` (or
        ``groundtruth_rect.<k>.txt`` files).

    """
    folder = Path(folder)
    return (folder / 'img').is_dir() and bool(_gt_files(folder))


def derives_from(name: str, source: str) -> bool:
    """
    Whether the target ``name`` is ``source`` or one made from it: ``<source>-<suffix>``.

    A target of a multi-target folder (Jogging-1 of Jogging) or a cut of a sequence
    (Car4-follow40 of Car4, Jogging-1-follow15 of Jogging-1); case-insensitive.
    """
    name, source = name.lower(), source.lower()
    return name == source or name.startswith(source + '-')


def list_sequences(root: str | Path) -> list[str]:
    """
    Names of the OTB targets below ``root``, sorted (Jogging gives Jogging-1 and Jogging-2).

    Parameters
    ----------
    root : str or Path
        The OTB root folder.

    Returns
    -------
    list of str
        The target names.

    Raises
    ------
    ValueError
        If ``root`` is not a directory.

    """
    root = Path(root)
    if not root.is_dir():
        raise ValueError(f'OTB root {root} is not a directory')
    names = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        if is_sequence_folder(folder):
            names.extend(_gt_files(folder))
    return names


def shared_data() -> Path | None:
    """
    ``../shared/data`` beside the repository (or beside the working directory), if it exists.

    Returns
    -------
    Path or None
        The folder; None when neither exists.

    """
    repository = Path(__file__).resolve().parents[2]
    for base in (repository, Path.cwd()):
        cand = base.parent / 'shared' / 'data'
        if cand.is_dir():
            return cand
    return None


def default_root() -> Path | None:
    """``../shared/data/otb``, if it exists (:func:`shared_data`)."""
    data = shared_data()
    return data / 'otb' if data is not None and (data / 'otb').is_dir() else None


def default_roots() -> list[Path]:
    """Return the folders of sequences in ``../shared/data`` that exist: ``otb`` and ``uav``."""
    data = shared_data()
    return [] if data is None else [data / g for g in ('otb', 'uav') if (data / g).is_dir()]


def _resolve(path_or_name: str | Path, root: str | Path | None) -> tuple[Path, str]:
    """
    Find the folder and target name for a folder path.

    ``<folder>-<k>`` or a bare name under root.
    """
    p = Path(path_or_name)
    candidates = [p]
    if not p.is_absolute() and len(p.parts) == 1:
        bases = [Path(root)] if root is not None else default_roots()
        candidates[:0] = [base / p for base in bases]
    for cand in candidates:
        if cand.is_dir():
            return cand, cand.name
        m = _TARGET_NAME.match(cand.name)
        if m and (cand.parent / m.group(1)).is_dir():
            return cand.parent / m.group(1), cand.name
    raise ValueError(
        f'OTB sequence {path_or_name!s} not found' + (f' under {root}' if root else '')
    )


def load_sequence(path_or_name: str | Path, root: str | Path | None = None) -> Sequence:
    """
    Load one target.

    Parameters
    ----------
    path_or_name : str or Path
        A sequence folder, ``<folder>-<k>`` (one target of a multi-target folder) or a name under
        ``root``.
    root : str or Path, optional
        The OTB root of a bare name (default: :func:`default_root`).

    Returns
    -------
    Sequence
        The target's frames and GT.

    Raises
    ------
    ValueError
        When the sequence is not found or not an OTB sequence, names a target the folder does not
        hold, or has a number of GT boxes other than its number of images.

    """
    folder, name = _resolve(path_or_name, root)
    paths, numbers = _frames_of(folder)
    gts = _gt_files(folder)
    if not gts:
        raise ValueError(
            f'{folder} is not an OTB sequence: no {GT_NAME} (or groundtruth_rect.<k>.txt)'
        )
    if name not in gts:
        raise ValueError(
            f'{folder} holds the targets {", ".join(gts)}; choose one of them, not {name!r}'
        )
    boxes = parse_groundtruth(gts[name])
    if len(boxes) != len(paths):
        raise ValueError(
            f'{gts[name]}: {len(boxes)} ground-truth boxes for {len(paths)} images in '
            f'{folder / "img"}'
        )
    return Sequence(name, tuple(paths), boxes, tuple(numbers), folder.parent.name)
