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
Tracking metrics of the OTB protocol (Wu, Lim & Yang 2013) used in the paper's evaluation.

Boxes are ``(x, y, w, h)`` in 0-based continuous pixel coordinates (top-left corner + size).  The
paper's measure is the relative overlap ``|R_tr ∩ R_gt| / |R_tr ∪ R_gt|`` (Section
"Experiments", overlap equation); its tables report the average overlap, the gyro experiment also
the fraction of frames with overlap > 0 and > 40 %.  The OTB success plot / AUC and precision@20px
are added so the figures compare with the rest of the field.

All fractions are returned in [0, 1]; callers multiply by 100 for percentages.

Conventions (the same as the OTB toolkit's ``calcRectInt`` / ``perfPlot``):

* A box with a NaN coordinate or a non-positive width/height is *invalid*: its IoU with anything is
  0 and its centre error is ``inf`` (a tracker failure counts as a miss at every threshold).
* A ground-truth box that is invalid marks an *absent* frame; :func:`score_sequence` excludes such
  frames (OTB keeps only frames whose four annotation values are > 0 / finite).
* The success curve counts ``overlap > t`` (strict), the precision counts ``error <= t`` px.
* The OTB pixel-inclusive convention (``right = x + w - 1``, ``width = right - left + 1``) gives
  the same intersection as the continuous one used here.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

#: The 21 overlap thresholds of the OTB success plot (0, 0.05, ..., 1).
OTB_THRESHOLDS = np.linspace(0.0, 1.0, 21)
#: The OTB precision threshold in pixels.
PRECISION_THRESHOLD = 20.0


def _as_boxes(boxes, name: str) -> np.ndarray:
    arr = np.asarray(boxes, dtype=float)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise ValueError(
            f'{name} must be (x, y, w, h) or an (N, 4) array of boxes, got shape {np.shape(boxes)}'
        )
    return arr


def _pair(boxes_a, boxes_b) -> tuple[np.ndarray, np.ndarray]:
    a = _as_boxes(boxes_a, 'boxes_a')
    b = _as_boxes(boxes_b, 'boxes_b')
    if len(a) != len(b) and len(a) != 1 and len(b) != 1:
        raise ValueError(f'boxes_a and boxes_b have different lengths: {len(a)} vs {len(b)}')
    return a, b


def valid_boxes(boxes) -> np.ndarray:
    """
    Boolean mask of boxes that are finite and have positive width and height.

    Parameters
    ----------
    boxes : array_like
        (x, y, w, h) or (N, 4) boxes.

    Returns
    -------
    ndarray
        (N,) bool.

    Raises
    ------
    ValueError
        For other shapes.

    """
    b = _as_boxes(boxes, 'boxes')
    with np.errstate(invalid='ignore'):
        return np.isfinite(b).all(axis=1) & (b[:, 2] > 0) & (b[:, 3] > 0)


def iou(boxes_a, boxes_b) -> np.ndarray:
    """
    Relative overlap ``|A ∩ B| / |A ∪ B|`` of paired boxes (paper's overlap equation).

    Parameters
    ----------
    boxes_a, boxes_b : array_like
        (x, y, w, h) or (N, 4) boxes; a single box broadcasts against N boxes.

    Returns
    -------
    ndarray
        (N,) overlaps; invalid boxes (NaN, w <= 0 or h <= 0) give 0.

    Raises
    ------
    ValueError
        For other shapes, or different numbers of boxes.

    """
    a, b = _pair(boxes_a, boxes_b)
    ok = valid_boxes(a) & valid_boxes(b)
    with np.errstate(invalid='ignore'):
        iw = np.minimum(a[:, 0] + a[:, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, 0], b[:, 0])
        ih = np.minimum(a[:, 1] + a[:, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, 1], b[:, 1])
        inter = np.clip(iw, 0.0, None) * np.clip(ih, 0.0, None)
        union = a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter
        out = np.where(ok, inter / np.where(ok, union, 1.0), 0.0)
    return out


def center_error(boxes_a, boxes_b) -> np.ndarray:
    """
    Euclidean distance in pixels between box centres.

    Parameters
    ----------
    boxes_a, boxes_b : array_like
        (x, y, w, h) or (N, 4) boxes; a single box broadcasts against N boxes.

    Returns
    -------
    ndarray
        (N,) distances; ``inf`` where a box is invalid.

    Raises
    ------
    ValueError
        For other shapes, or different numbers of boxes.

    """
    a, b = _pair(boxes_a, boxes_b)
    ok = valid_boxes(a) & valid_boxes(b)
    ca = a[:, :2] + a[:, 2:] / 2.0
    cb = b[:, :2] + b[:, 2:] / 2.0
    with np.errstate(invalid='ignore'):
        d = np.hypot(*(ca - cb).T)
    return np.where(ok, d, np.inf)


def _as_values(values, name: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size == 0:
        raise ValueError(f'{name} is empty: no frames to score')
    if np.isnan(arr).any():
        raise ValueError(
            f'{name} contains NaN (use iou()/center_error(), which map invalid boxes to 0/inf)'
        )
    return arr


def fraction_above(ious, thr: float) -> float:
    """
    Fraction of frames whose overlap is strictly greater than ``thr`` (paper: overlap > 0, > 40 %).

    Parameters
    ----------
    ious : array_like
        Per-frame overlaps.
    thr : float
        The threshold.

    Returns
    -------
    float
        The fraction, in [0, 1].

    Raises
    ------
    ValueError
        For no values, or NaN among them.

    """
    return float(np.mean(_as_values(ious, 'ious') > thr))


def success_curve(ious, thresholds=OTB_THRESHOLDS) -> np.ndarray:
    """
    OTB success plot: for each threshold t, the fraction of frames with overlap > t.

    Parameters
    ----------
    ious : array_like
        Per-frame overlaps.
    thresholds : array_like, optional
        The thresholds (default: the 21 of OTB).

    Returns
    -------
    ndarray
        One fraction per threshold.

    Raises
    ------
    ValueError
        For no values, or NaN among them.

    """
    v = _as_values(ious, 'ious')
    t = np.asarray(thresholds, dtype=float).ravel()
    return (v[None, :] > t[:, None]).mean(axis=1)


def success_auc(ious, thresholds=OTB_THRESHOLDS) -> float:
    """
    OTB area under the success curve: the mean of the curve over the (21) thresholds.

    Parameters
    ----------
    ious : array_like
        Per-frame overlaps.
    thresholds : array_like, optional
        The thresholds (default: the 21 of OTB).

    Returns
    -------
    float
        The area, in [0, 1].

    Raises
    ------
    ValueError
        For no values, or NaN among them.

    """
    return float(success_curve(ious, thresholds).mean())


def precision_at(center_errors, thr: float = PRECISION_THRESHOLD) -> float:
    """
    OTB precision: fraction of frames whose centre error is <= ``thr`` pixels.

    Parameters
    ----------
    center_errors : array_like
        Per-frame centre errors, px.
    thr : float, optional
        The threshold, px (default 20).

    Returns
    -------
    float
        The fraction, in [0, 1].

    Raises
    ------
    ValueError
        For no values, or NaN among them.

    """
    return float(np.mean(_as_values(center_errors, 'center_errors') <= thr))


def average_overlap(ious) -> float:
    """
    Return the paper's table metric: mean relative overlap over all (scored) frames.

    Parameters
    ----------
    ious : array_like
        Per-frame overlaps.

    Returns
    -------
    float
        The mean, in [0, 1].

    Raises
    ------
    ValueError
        For no values, or NaN among them.

    """
    return float(np.mean(_as_values(ious, 'ious')))


@dataclass
class SequenceScores:
    """
    All per-sequence figures of one tracker run (fractions in [0, 1]; ``fps`` may be None).

    Parameters
    ----------
    name : str
        The sequence's name.
    n_frames : int
        Frames scored (GT present).
    n_absent : int
        Frames excluded because the GT box is invalid / NaN.
    average_overlap : float
        The paper's table metric.
    success_auc : float
        OTB area under the success curve.
    precision_20 : float
        OTB precision at 20 px.
    overlap_gt_0, overlap_gt_04 : float
        Fractions of frames with overlap > 0 and > 0.4.
    recall : float
        The average overlap with the frames the tracker did not report the target on counted as 0
        (VOT's long-term tracking recall): what its reports (published detections) are worth.
        Equal to ``average_overlap`` for a tracker that reports every frame.
    fps : float or None, optional
        The run's speed.
    success_curve : list of float, optional
        The success curve at :data:`OTB_THRESHOLDS`.

    """

    name: str
    n_frames: int  # frames scored (GT present)
    n_absent: int  # frames excluded because the GT box is invalid / NaN
    average_overlap: float
    success_auc: float
    precision_20: float
    overlap_gt_0: float
    overlap_gt_04: float
    recall: float
    fps: float | None = None
    success_curve: list[float] = field(default_factory=list)

    def to_dict(self) -> dict:
        """
        Return the figures as a dict.

        Returns
        -------
        dict
            Field name -> value (``dataclasses.asdict``).

        """
        return asdict(self)


def score_sequence(
    pred_boxes, gt_boxes, name: str = '', fps: float | None = None, reported=None
) -> SequenceScores:
    """
    Score predicted boxes against ground truth over the frames where the GT box is valid.

    Parameters
    ----------
    pred_boxes, gt_boxes : array_like
        (N, 4) predicted and GT boxes.
    name : str, optional
        The sequence's name.
    fps : float, optional
        The run's speed, recorded as it is.
    reported : array_like of bool, optional
        (N,) whether the tracker reported the target on each frame (not lost); None: every frame.

    Returns
    -------
    SequenceScores
        The figures.

    Raises
    ------
    ValueError
        For boxes of other shapes or of different numbers, report flags of another number, or
        no valid GT box.

    """
    pred = _as_boxes(pred_boxes, 'pred_boxes')
    gt = _as_boxes(gt_boxes, 'gt_boxes')
    if len(pred) != len(gt):
        raise ValueError(
            f'{name or "sequence"}: {len(pred)} predicted boxes for {len(gt)} ground-truth boxes'
        )
    rep = np.ones(len(gt), bool) if reported is None else np.asarray(reported, bool).ravel()
    if len(rep) != len(gt):
        raise ValueError(
            f'{name or "sequence"}: {len(rep)} report flags for {len(gt)} ground-truth boxes'
        )
    present = valid_boxes(gt)
    if not present.any():
        raise ValueError(f'{name or "sequence"}: no frame has a valid ground-truth box')
    ov = iou(pred[present], gt[present])
    ce = center_error(pred[present], gt[present])
    curve = success_curve(ov)
    return SequenceScores(
        name=name,
        n_frames=int(present.sum()),
        n_absent=int((~present).sum()),
        average_overlap=average_overlap(ov),
        success_auc=float(curve.mean()),
        precision_20=precision_at(ce, PRECISION_THRESHOLD),
        overlap_gt_0=fraction_above(ov, 0.0),
        overlap_gt_04=fraction_above(ov, 0.4),
        recall=average_overlap(np.where(rep[present], ov, 0.0)),
        fps=fps,
        success_curve=[float(c) for c in curve],
    )


#: A return counts as re-acquired once a reported box overlaps the target by at least this IoU.
REACQUIRED_IOU = 0.3
#: ... within this many frames of the target's return (the issue's "back on the target within 30
#: frames").
REACQUIRE_WITHIN = 30


@dataclass
class LongTermScores:
    """
    Figures of a run on a sequence where the target leaves the view (VOT's long-term measures).

    Attributes
    ----------
    precision : float
        Mean IoU over the frames where the tracker reports the target (a report on an absent target
        scores 0).
    recall : float
        Mean IoU over the frames where the target is present (a frame without report scores 0).
    f_score : float
        2 precision recall / (precision + recall).
    absent_frames : int
        Frames whose GT box is invalid (the target out of view).
    false_report_rate : float
        Share of the absent frames on which the tracker reported a box.
    returns : int
        Times the target came back into view (absent -> present).
    reacquired : int
        Returns after which a reported box reached :data:`REACQUIRED_IOU` within
        :data:`REACQUIRE_WITHIN` frames.
    delays : list of int
        Per return, frames from the return to the first such report (-1: never).

    """

    precision: float
    recall: float
    f_score: float
    absent_frames: int
    false_report_rate: float
    returns: int
    reacquired: int
    delays: list[int] = field(default_factory=list)

    def to_dict(self) -> dict:
        return asdict(self)


def long_term_scores(pred_boxes, reported, gt_boxes) -> LongTermScores:
    """
    VOT long-term precision, recall and F-score of a run.

    With the false reports and the re-acquisitions.

    Parameters
    ----------
    pred_boxes : array_like
        (N, 4) the tracker's boxes (ignored where ``reported`` is False).
    reported : array_like of bool
        (N,) whether the tracker reported the target on each frame.
    gt_boxes : array_like
        (N, 4) GT boxes, invalid (NaN) where the target is absent.

    Returns
    -------
    LongTermScores

    Raises
    ------
    ValueError
        For arrays of different lengths, or no present and no reported frame.

    """
    pred = _as_boxes(pred_boxes, 'pred_boxes')
    gt = _as_boxes(gt_boxes, 'gt_boxes')
    rep = np.asarray(reported, dtype=bool).ravel()
    if not len(pred) == len(gt) == len(rep):
        raise ValueError(
            f'{len(pred)} boxes, {len(rep)} report flags and {len(gt)} GT boxes: lengths differ'
        )
    rep = rep & valid_boxes(pred)
    present = valid_boxes(gt)
    ov = np.where(rep & present, iou(pred, gt), 0.0)
    if not present.any() and not rep.any():
        raise ValueError('no frame where the target is present or reported: nothing to score')
    precision = float(ov[rep].mean()) if rep.any() else 0.0
    recall = float(ov[present].mean()) if present.any() else 0.0
    f = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    absent = ~present
    delays = []
    for start in np.flatnonzero(present[1:] & absent[:-1]) + 1:
        window = np.flatnonzero(ov[start: start + REACQUIRE_WITHIN] >= REACQUIRED_IOU)
        delays.append(int(window[0]) if window.size else -1)
    return LongTermScores(
        precision=precision,
        recall=recall,
        f_score=f,
        absent_frames=int(absent.sum()),
        false_report_rate=float(rep[absent].mean()) if absent.any() else 0.0,
        returns=len(delays),
        reacquired=sum(d >= 0 for d in delays),
        delays=delays,
    )


@dataclass
class PairedDifference:
    """How one tracker's runs differ from another's on the same sequences and starts."""

    mean: float  # mean of the per-run differences (ours - reference)
    low: float  # 2.5th percentile of the mean over sequences resampled with replacement
    high: float  # 97.5th percentile of that mean
    better: int  # runs where ours is higher
    worse: int  # runs where ours is lower
    equal: int  # runs with the same value
    per_sequence: tuple[float, ...]  # mean difference of each sequence's runs, in input order
    per_start: tuple[float, ...]  # mean difference of each start over the sequences, input order


def paired_difference(ours, reference, resamples: int = 10000, seed: int = 0) -> PairedDifference:
    """
    Compare two trackers run by run, with a confidence interval that respects the sequences.

    The starts of one sequence are not independent runs (one hard sequence moves all of them), so
    the interval is a cluster bootstrap: whole sequences are drawn with replacement and the mean
    difference of the drawn rows is taken, ``resamples`` times (Field & Welsh, "Bootstrapping
    clustered data", JRSS B 2007).

    Parameters
    ----------
    ours, reference : array_like
        (sequences, starts) scores of the same runs (e.g. average overlap per start).
    resamples : int, optional
        Bootstrap draws (>= 1).
    seed : int, optional
        Seed of the draws: the same inputs give the same interval.

    Returns
    -------
    PairedDifference
        The mean difference, its 95 % interval, the runs better, worse and equal, and the mean
        difference per sequence and per start.

    Raises
    ------
    ValueError
        For arrays that are not 2-D of the same shape, empty, or not finite, or ``resamples`` < 1.

    """
    a = np.asarray(ours, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.ndim != 2 or a.shape != b.shape or a.size == 0:
        raise ValueError(
            f'ours and reference must be (sequences, starts) arrays of one shape, got {a.shape} '
            f'and {b.shape}'
        )
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError('ours and reference must be finite')
    if resamples < 1:
        raise ValueError(f'resamples must be >= 1, got {resamples}')
    diff = a - b
    # every sequence has as many starts: a draw's mean is the mean of its sequences' means
    per_sequence = diff.mean(axis=1)
    rows = np.random.default_rng(seed).integers(0, len(diff), size=(resamples, len(diff)))
    means = per_sequence[rows].mean(axis=1)
    low, high = np.percentile(means, [2.5, 97.5])
    return PairedDifference(
        mean=float(diff.mean()),
        low=float(low),
        high=float(high),
        better=int((diff > 0).sum()),
        worse=int((diff < 0).sum()),
        equal=int((diff == 0).sum()),
        per_sequence=tuple(float(v) for v in per_sequence),
        per_start=tuple(float(v) for v in diff.mean(axis=0)),
    )
