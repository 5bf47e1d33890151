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
One-pass evaluation (OPE) of trackers on OTB-layout sequences.

As the paper and the field do (``iemd-eval``).

Protocol (Wu, Lim & Yang 2013; paper, Section "Experiments"): each tracker is initialised with the
GT box of the first frame and then updated on every later frame without re-initialisation.  The
first frame counts as tracked with the GT box.  Scores are those of
:mod:`iemd_ros.evaluation.metrics` (average overlap = the paper's table metric, OTB success AUC,
precision@20px, overlap > 0 / > 0.4, and the recall ``R``: the average overlap with the frames a
tracker reported failed, iEMD's lost frames, as 0).  The mean over sequences is the plain mean
of the per-sequence figures (OTB averages the per-sequence success curves), fps included.

Speed: only the ``init``/``update`` calls are timed (image decoding is not); fps = frames / (init
time + sum of update times).  A job is one tracker on one sequence, run in one process; the jobs
run one after the other (``--jobs 1``) or at the same time on several workers, where they share the
cores: fps and the other :data:`WALL_CLOCK_FIELDS` are those of the run that measured them, and
:func:`results_digest` leaves them out.

Tracker failures: OTB has no notion of failure, every tracker reports its current estimate on every
frame.  Each frame is scored with the box the tracker returns; when that box is empty/invalid
(OpenCV's CSRT/KCF return ``(False, (0, 0, 0, 0))`` when their confidence test fails) the previous
box is kept.  That is OpenCV's internal state: on a failed test both trackers return before moving
or updating their model, and resume from that position (test_evaluation checks it for KCF).  The
rule is the same for every tracker (iEMD always returns a box; ``result.lost`` is only counted).
The per-frame ``ok`` flags and the count ``failures`` are in ``results.json``, so the failed frames
can be rescored as misses (docs/decisions.md#evaluation-failures).
"""
from __future__ import annotations

from dataclasses import dataclass
import hashlib
import json
from pathlib import Path
import time
from typing import Callable, Protocol

import cv2
from iemd_ros.common.parallel import run_jobs, Workers
from iemd_ros.datasets.otb import (
    default_roots,
    derives_from,
    is_sequence_folder,
    list_sequences,
    load_sequence,
    Sequence,
)
from iemd_ros.evaluation.metrics import (
    long_term_scores,
    OTB_THRESHOLDS,
    PRECISION_THRESHOLD,
    score_sequence,
    SequenceScores,
    valid_boxes,
)
from iemd_ros.tracking import IemdTracker, TrackerConfig
import numpy as np

DEFAULT_TRACKERS = ('iemd', 'csrt', 'kcf')
DEFAULT_OUT = Path('out') / 'eval'
MEAN = 'mean'
#: the fields of a run's entry (and of a mean) in ``results.json`` that are wall-clock measurements
WALL_CLOCK_FIELDS = ('fps', 'init_ms', 'update_ms_median', 'update_ms_p95')


class TrackerAdapter(Protocol):
    """What the evaluation needs from a tracker: init on a box, then one box per frame."""

    def init(self, frame: np.ndarray, box: np.ndarray) -> None:
        """
        Start tracking the target ``box`` on ``frame``.

        Parameters
        ----------
        frame : ndarray
            The first frame, BGR uint8.
        box : ndarray
            (x, y, w, h), float.

        """
        ...

    def update(self, frame: np.ndarray, interval: float | None = None) -> tuple[np.ndarray, bool]:
        """
        Track into the next frame.

        Parameters
        ----------
        frame : ndarray
            The frame, BGR uint8.
        interval : float, optional
            Seconds since the previous frame, when known.

        Returns
        -------
        box : ndarray
            (x, y, w, h), float.
        ok : bool
            False when the tracker reports a failure.

        """


class OpenCVTracker:
    """
    Adapter for OpenCV's ``cv2.Tracker`` (integer boxes, ``update`` -> ``(ok, box)``).

    Parameters
    ----------
    create : callable
        Returns a new ``cv2.Tracker``; called by every :meth:`init`.

    """

    def __init__(self, create: Callable[[], 'cv2.Tracker']):
        self._create = create
        self._tracker = None

    def init(self, frame: np.ndarray, box: np.ndarray) -> None:
        """
        Start a new OpenCV tracker on ``box``, rounded to integers (width and height at least 1).

        Parameters
        ----------
        frame : ndarray
            The first frame, BGR uint8.
        box : ndarray
            (x, y, w, h), float.

        """
        self._tracker = self._create()
        x, y, w, h = (int(round(v)) for v in box)
        self._tracker.init(frame, (x, y, max(w, 1), max(h, 1)))

    def update(self, frame: np.ndarray, interval: float | None = None) -> tuple[np.ndarray, bool]:
        """
        Track into the next frame.

        Parameters
        ----------
        frame : ndarray
            The frame, BGR uint8.
        interval : float, optional
            Seconds since the previous frame, when known.

        Returns
        -------
        box : ndarray
            (x, y, w, h), float.
        ok : bool
            False when the tracker reports a failure.

        """
        ok, box = self._tracker.update(frame)  # OpenCV's trackers learn per frame
        return np.asarray(box, dtype=float), bool(ok)


class IemdAdapter:
    """
    Adapter for :class:`iemd_ros.IemdTracker`; no gyro prior in OTB.

    Parameters
    ----------
    config : TrackerConfig, optional
        The tracker's :class:`~iemd_ros.TrackerConfig` (None: the defaults).

    """

    def __init__(self, config=None):
        self._tracker = IemdTracker(config)

    def init(self, frame: np.ndarray, box: np.ndarray) -> None:
        """
        Start tracking the target ``box`` on ``frame``.

        Parameters
        ----------
        frame : ndarray
            The first frame, BGR uint8.
        box : ndarray
            (x, y, w, h), float.

        """
        self._tracker.init(frame, tuple(float(v) for v in box))

    def update(self, frame: np.ndarray, interval: float | None = None) -> tuple[np.ndarray, bool]:
        """
        Track into the next frame.

        Parameters
        ----------
        frame : ndarray
            The frame, BGR uint8.
        interval : float, optional
            Seconds since the previous frame, when known.

        Returns
        -------
        box : ndarray
            (x, y, w, h), float.
        ok : bool
            False when the tracker reports the target lost.

        """
        result = self._tracker.update(frame, interval=interval)
        return np.asarray(result.box, dtype=float), not bool(result.lost)


def _opencv_factory(kind: str) -> Callable[..., OpenCVTracker]:
    """
    CSRT/KCF: OpenCV 5 contrib has ``cv2.TrackerCSRT.create``.

    Older builds ``cv2.TrackerCSRT_create``. They run with OpenCV's defaults: a configuration is
    refused.
    """

    def factory(config=None) -> OpenCVTracker:
        if config is not None:
            raise ValueError(
                f"OpenCV's {kind} tracker runs with its defaults; it takes no configuration"
            )
        cls = getattr(cv2, f'Tracker{kind}', None)
        create = getattr(cls, 'create', None) or getattr(cv2, f'Tracker{kind}_create', None)
        if create is None:
            raise ValueError(
                f'this OpenCV build ({cv2.__version__}) has no Tracker{kind}: install '
                'opencv-contrib'
            )
        return OpenCVTracker(create)

    return factory


#: name -> factory returning a fresh :class:`TrackerAdapter` with its defaults, or with
#: ``factory(config)`` for a tracker that has a configuration (iEMD: a TrackerConfig).
TRACKERS: dict[str, Callable[..., TrackerAdapter]] = {
    'iemd': IemdAdapter,
    'csrt': _opencv_factory('CSRT'),
    'kcf': _opencv_factory('KCF'),
}


def make_tracker(name: str, config=None) -> TrackerAdapter:
    """
    Build a tracker adapter by name.

    Parameters
    ----------
    name : str
        A name in :data:`TRACKERS`.
    config : optional
        The tracker's configuration (None: the tracker's defaults).

    Returns
    -------
    TrackerAdapter
        A fresh adapter.

    Raises
    ------
    ValueError
        For an unknown or unavailable tracker, or a configuration given to one that takes none.

    """
    if name not in TRACKERS:
        raise ValueError(f'unknown tracker {name!r} (known: {", ".join(TRACKERS)})')
    return TRACKERS[name]() if config is None else TRACKERS[name](config)


@dataclass
class RunResult:
    """
    Boxes, failure flags and timings of one tracker on one sequence.

    Parameters
    ----------
    boxes : ndarray
        (N, 4), frame 0 = GT.
    ok : ndarray
        (N,) bool, frame 0 = True.
    init_seconds : float
        Time of the ``init`` call.
    update_seconds : ndarray
        (N - 1,) times of the ``update`` calls.

    """

    boxes: np.ndarray  # (N, 4), frame 0 = GT
    ok: np.ndarray  # (N,) bool, frame 0 = True
    init_seconds: float
    update_seconds: np.ndarray  # (N - 1,)

    @property
    def fps(self) -> float:
        """Frames per second: frames / (init time + sum of update times)."""
        total = self.init_seconds + float(self.update_seconds.sum())
        return len(self.boxes) / total if total > 0 else float('inf')


def run_tracker(tracker: TrackerAdapter, frames, init_box, interval=None) -> RunResult:
    """
    One-pass run: init on the first frame with ``init_box``, update on each later frame (timed).

    An invalid returned box (empty, NaN) is replaced by the previous box (see module docstring).

    Parameters
    ----------
    tracker : TrackerAdapter
        A fresh tracker.
    frames : iterable of ndarray
        The sequence's frames.
    init_box : array_like
        (x, y, w, h) on the first frame.
    interval : float, optional
        Seconds between frames, when known (:meth:`TrackerAdapter.update`).

    Returns
    -------
    RunResult
        The boxes, the trackers' ok flags and the timings.

    Raises
    ------
    ValueError
        When there is no frame.

    """
    it = iter(frames)
    try:
        first = next(it)
    except StopIteration:
        raise ValueError('no frames to track') from None
    init_box = np.asarray(init_box, dtype=float)
    t0 = time.perf_counter()
    tracker.init(first, init_box)
    init_s = time.perf_counter() - t0
    boxes, oks, times = [init_box], [True], []
    for frame in it:
        t0 = time.perf_counter()
        box, ok = tracker.update(frame, interval)
        times.append(time.perf_counter() - t0)
        box = np.asarray(box, dtype=float).reshape(4)
        # no box returned: keep the last one
        boxes.append(box if valid_boxes(box)[0] else boxes[-1])
        oks.append(ok)
    return RunResult(np.vstack(boxes), np.asarray(oks, dtype=bool), init_s, np.asarray(times))


def evaluate_sequence(seq: Sequence, tracker: TrackerAdapter) -> tuple[SequenceScores, RunResult]:
    """
    One-pass run of a fresh ``tracker`` on ``seq`` and its scores.

    Parameters
    ----------
    seq : Sequence
        The sequence, initialised with its first GT box; its frame rate, when known, gives the
        tracker the frames' interval.
    tracker : TrackerAdapter
        A fresh tracker.

    Returns
    -------
    scores : SequenceScores
        The run's figures, fps included.
    run : RunResult
        The run.

    """
    interval = None if seq.frame_rate is None else 1.0 / seq.frame_rate
    run = run_tracker(tracker, seq.frames(), seq.gt_boxes[0], interval)
    return score_sequence(run.boxes, seq.gt_boxes, seq.name, fps=run.fps, reported=run.ok), run


@dataclass(frozen=True)
class EvalJob:
    """
    One job of :func:`evaluate`: a tracker on a sequence.

    Parameters
    ----------
    sequence : Sequence
        The sequence (its frames are read by the job).
    tracker : str
        A name in :data:`TRACKERS`.
    config : optional
        The tracker's configuration (None: its defaults).

    """

    sequence: Sequence
    tracker: str
    config: object = None


def run_job(job: EvalJob) -> tuple[SequenceScores, dict]:
    """
    Run a fresh tracker of ``job`` on its sequence.

    The scores and the sequence's entry of ``results.json``.

    Parameters
    ----------
    job : EvalJob
        The tracker and the sequence.

    Returns
    -------
    scores : SequenceScores
        The run's figures, fps included.
    entry : dict
        The figures, the failures, the timings, the boxes and the ok flags.

    """
    scores, run = evaluate_sequence(job.sequence, make_tracker(job.tracker, job.config))
    entry = scores.to_dict()
    entry.update(
        failures=int((~run.ok).sum()),
        init_ms=1e3 * run.init_seconds,
        update_ms_median=1e3 * float(np.median(run.update_seconds))
        if run.update_seconds.size
        else None,
        update_ms_p95=1e3 * float(np.percentile(run.update_seconds, 95))
        if run.update_seconds.size
        else None,
        boxes=run.boxes.tolist(),
        ok=run.ok.tolist(),
    )
    # the target leaves the view: VOT's long-term measures too
    if not valid_boxes(job.sequence.gt_boxes).all():
        entry['long_term'] = long_term_scores(run.boxes, run.ok, job.sequence.gt_boxes).to_dict()
    return scores, entry


def mean_scores(scores: list[SequenceScores]) -> dict:
    """
    Mean over sequences of every per-sequence figure (OTB's overall plot averages the curves).

    Parameters
    ----------
    scores : list of SequenceScores
        One tracker's scores on the sequences.

    Returns
    -------
    dict
        The mean figures and success curve, ``n_sequences`` and the total ``n_frames``.

    """
    keys = (
        'average_overlap',
        'success_auc',
        'precision_20',
        'overlap_gt_0',
        'overlap_gt_04',
        'recall',
        'fps',
    )
    out = {k: float(np.mean([getattr(s, k) for s in scores])) for k in keys}
    out['success_curve'] = np.mean([s.success_curve for s in scores], axis=0).tolist()
    out['n_sequences'] = len(scores)
    out['n_frames'] = int(sum(s.n_frames for s in scores))
    return out


def mean_long_term(entries: list[dict]) -> dict | None:
    """
    Mean long-term figures over sequences (re-acquisitions summed); None without any.

    Parameters
    ----------
    entries : list of dict
        :class:`~iemd_ros.evaluation.metrics.LongTermScores` as dicts.

    Returns
    -------
    dict or None

    """
    if not entries:
        return None
    keys = ('precision', 'recall', 'f_score', 'false_report_rate')
    out = {k: float(np.mean([e[k] for e in entries])) for k in keys}
    out.update(
        returns=sum(e['returns'] for e in entries),
        reacquired=sum(e['reacquired'] for e in entries),
        n_sequences=len(entries),
    )
    return out


def format_long_term(doc: dict) -> str:
    """
    Return the long-term measures of the sequences where the target leaves the view.

    And their means ("" if none).
    """
    trackers = doc['trackers']
    names = [n for n in doc['sequences'] if 'long_term' in doc['results'][trackers[0]][n]]
    if not names:
        return ''
    header = (f'{"sequence":<14} {"tracker":<7} {"P%":>6} {"R%":>6} {"F%":>6} '
              f'{"reports on absent%":>19} {"back":>6}')
    lines = ['long-term measures (the target leaves the view):', header, '-' * len(header)]

    def row(label: str, trk: str, s: dict) -> str:
        return (
            f'{label:<14} {trk:<7} {_pct(s["precision"])} {_pct(s["recall"])} '
            f'{_pct(s["f_score"])} '
            f'{100 * s["false_report_rate"]:19.1f} {s["reacquired"]:>3d}/{s["returns"]:<2d}'
        )

    for name in names:
        for trk in trackers:
            lines.append(row(name, trk, doc['results'][trk][name]['long_term']))
    lines.append('-' * len(header))
    for trk in trackers:
        lines.append(row(f'MEAN ({len(names)})', trk, doc['long_term'][trk]))
    return '\n'.join(lines)


def plot_success(curves: dict[str, list[float]], title: str, path: Path) -> None:
    """
    OTB-style success plot: one curve per tracker, legend ``name [AUC]`` sorted by AUC.

    Parameters
    ----------
    curves : dict
        Tracker name -> success curve at :data:`~iemd_ros.evaluation.metrics.OTB_THRESHOLDS`.
    title : str
        The plot's title.
    path : Path
        The PNG file written.

    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4), dpi=100)
    for name, curve in sorted(curves.items(), key=lambda kv: -float(np.mean(kv[1]))):
        ax.plot(OTB_THRESHOLDS, curve, linewidth=2, label=f'{name} [{np.mean(curve):.3f}]')
    ax.set(
        xlim=(0, 1), ylim=(0, 1.02), xlabel='Overlap threshold', ylabel='Success rate', title=title
    )
    ax.grid(True, alpha=0.3)
    ax.legend(loc='lower left')
    fig.tight_layout()
    fig.savefig(path, format='png')
    plt.close(fig)


def _pct(v: float) -> str:
    return f'{100 * v:6.1f}'


def format_table(results: dict, trackers: list[str], names: list[str]) -> str:
    """
    Return the results as a text table.

    One row per sequence and tracker, then one per tracker's mean.

    Parameters
    ----------
    results : dict
        Tracker -> sequence name (and ``mean``) -> figures, as :func:`evaluate` records them.
    trackers : list of str
        The trackers' names.
    names : list of str
        The sequences' names.

    Returns
    -------
    str
        The table, fractions in percent.

    """
    header = (f'{"sequence":<14} {"tracker":<7} {"frames":>6} {"AO%":>6} {"AUC%":>6} {"P@20%":>6} '
              f'{">0%":>6} {">40%":>6} {"R%":>6} {"fps":>8}')
    lines = [header, '-' * len(header)]

    def row(label: str, trk: str, s: dict, n: int) -> str:
        return (
            f'{label:<14} {trk:<7} {n:>6d} {_pct(s["average_overlap"])} {_pct(s["success_auc"])} '
            f'{_pct(s["precision_20"])} {_pct(s["overlap_gt_0"])} {_pct(s["overlap_gt_04"])} '
            f'{_pct(s["recall"])} {s["fps"]:8.1f}'
        )

    for name in names:
        for trk in trackers:
            s = results[trk][name]
            lines.append(row(name, trk, s, s['n_frames']))
    lines.append('-' * len(header))
    means = [key for key in next(iter(results.values())) if key.startswith(MEAN + ' ')] + [MEAN]
    for key in means:
        for trk in trackers:
            m = results[trk][key]
            label = key.upper().replace(MEAN.upper() + ' ', 'MEAN ')[:9]
            lines.append(row(f'{label} ({m["n_sequences"]})', trk, m, m['n_frames']))
    return '\n'.join(lines)


def group_mean_key(group: str) -> str:
    """Return the results' key of the mean over one group of sequences (``mean otb``)."""
    return f'{MEAN} {group}'


def _groups(sequences: list[Sequence]) -> dict[str, list[str]]:
    """
    Group -> its sequences' names, when the sequences come from more than one group.

    (else empty).
    """
    groups: dict[str, list[str]] = {}
    for s in sequences:
        groups.setdefault(s.group, []).append(s.name)
    return groups if len(groups) > 1 else {}


def collect_sequences(inputs: list[str], wanted: list[str] | None) -> list[Sequence]:
    """
    Load the sequences named by the CLI inputs.

    Parameters
    ----------
    inputs : list of str
        OTB roots, sequence folders or ``<folder>-<k>`` targets (none: ``../shared/data/otb``).
    wanted : list of str or None
        The targets kept (case-insensitive; ``Jogging`` selects Jogging-1 and -2); None: all.

    Returns
    -------
    list of Sequence
        The targets, in order.

    Raises
    ------
    ValueError
        For an input that is neither an OTB root nor a sequence, an unknown wanted name, or no root
        at all.

    """
    return [load_sequence(name, root) for name, root in _select_targets(inputs, wanted).items()]


def _select_targets(inputs: list[str], wanted: list[str] | None) -> dict[str, Path]:
    """
    Return the targets :func:`collect_sequences` loads, in order.

    Name -> the root folder it lives in.
    """
    if not inputs:
        inputs = [str(root) for root in default_roots()]
        if not inputs:
            raise ValueError(
                'no folder of sequences given, and ../shared/data has neither otb/ nor uav/'
            )
    found: dict[str, Path] = {}  # target name -> root folder it lives in
    for item in inputs:
        path = Path(item)
        if is_sequence_folder(path) or (
            not path.exists() and is_sequence_folder(path.parent / path.name.rsplit('-', 1)[0])
        ):
            base = path.name if path.exists() else path.name.rsplit('-', 1)[0]
            names = [
                n
                for n in list_sequences(path.parent)
                if n == path.name or (path.exists() and n.startswith(base + '-'))
            ]
            if not names:
                raise ValueError(f'{path} is not an OTB sequence')
        elif path.is_dir():
            names = list_sequences(path)
            if not names:
                raise ValueError(
                    f'{path} holds no OTB sequence (expected <seq>/img and groundtruth_rect.txt)'
                )
            path = path / '_'  # so that path.parent is the root
        else:
            raise ValueError(f'{path} is neither an OTB root nor a sequence folder')
        for n in names:
            found.setdefault(n, path.parent)
    selected = list(found)
    if wanted is not None:
        selected = []
        for w in wanted:
            key = w.lower()
            hits = [n for n in found if n.lower() == key] or [
                n for n in found if derives_from(n, key)
            ]
            if not hits:
                raise ValueError(f'unknown sequence {w!r} (available: {", ".join(found)})')
            selected.extend(h for h in hits if h not in selected)
    return {name: found[name] for name in selected}


def sequence_names(wanted: str | None) -> list[str]:
    """
    Names of the targets in ``../shared/data/otb`` chosen by a comma-separated list.

    For scripts whose workers load them by name.

    Parameters
    ----------
    wanted : str or None
        Comma-separated names, as :func:`collect_sequences` takes them; empty or None: all.

    Returns
    -------
    list of str
        The target names.

    """
    return list(_select_targets([], wanted.split(',') if wanted else None))


def evaluate(
    sequences: list[Sequence],
    trackers: list[str],
    out: Path,
    log=print,
    configs=None,
    workers: Workers = Workers(1),
    progress: bool | None = None,
) -> dict:
    """
    Run every tracker on every sequence, write ``results.json`` and success plots into ``out``.

    Each (sequence, tracker) pair is one :class:`EvalJob` of :func:`run_job`, run by ``workers``
    (:func:`iemd_ros.common.parallel.run_jobs`); the document is built from the jobs' results in
    the order of the sequences and trackers, so it is the same on any workers but for its
    wall-clock fields (:data:`WALL_CLOCK_FIELDS`, :func:`results_digest`).  The iEMD configuration
    is recorded in ``results.json`` when iEMD runs.

    Parameters
    ----------
    sequences : list of Sequence
        The sequences.
    trackers : list of str
        Names in :data:`TRACKERS`.
    out : Path
        The output folder, created if needed.
    log : callable, optional
        Receives one line per sequence and tracker, in the order the jobs finish.
    configs : dict, optional
        Tracker name -> its configuration (:func:`make_tracker`; absent: the defaults).
    workers : Workers, optional
        Where the jobs run (default: in this process, one after the other).
    progress : bool, optional
        Show a progress bar over the jobs on stderr (default: when stderr is a terminal).

    Returns
    -------
    dict
        The document written to ``results.json``.

    """
    configs = configs or {}
    out.mkdir(parents=True, exist_ok=True)
    jobs = [EvalJob(seq, trk, configs.get(trk)) for seq in sequences for trk in trackers]

    def report(index: int, done: tuple[SequenceScores, dict]) -> str:
        scores, job = done[0], jobs[index]
        return (
            f'  {job.sequence.name:<14} {job.tracker:<5} AO {_pct(scores.average_overlap)}%  '
            f'AUC {_pct(scores.success_auc)}%  P@20 {_pct(scores.precision_20)}%  '
            f'{scores.fps:7.1f} fps'
        )

    outcomes = run_jobs(
        run_job, jobs, workers, label='iemd-eval', progress=progress, report=report, log=log
    )
    results: dict[str, dict] = {t: {} for t in trackers}
    per_seq_scores: dict[str, list[SequenceScores]] = {t: [] for t in trackers}
    for job, (scores, entry) in zip(jobs, outcomes):
        per_seq_scores[job.tracker].append(scores)
        results[job.tracker][job.sequence.name] = entry
    for seq in sequences:
        plot_success(
            {t: results[t][seq.name]['success_curve'] for t in trackers},
            f'Success plot of OPE - {seq.name}',
            out / f'success_{seq.name}.png',
        )
    for trk in trackers:
        results[trk][MEAN] = mean_scores(per_seq_scores[trk])
        for group, members in _groups(sequences).items():
            results[trk][group_mean_key(group)] = mean_scores(
                [s for s, seq in zip(per_seq_scores[trk], sequences) if seq.group == group]
            )
    plot_success(
        {t: results[t][MEAN]['success_curve'] for t in trackers},
        f'Success plots of OPE ({len(sequences)} sequences)',
        out / 'success_overall.png',
    )
    doc = {
        'protocol': {
            'name': 'OTB one-pass evaluation',
            'boxes': 'x,y,w,h 0-based pixels; frame 0 = GT box',
            'success_thresholds': OTB_THRESHOLDS.tolist(),
            'precision_threshold_px': PRECISION_THRESHOLD,
            'fractions': 'all scores in [0, 1]; fps = frames / (init + update seconds)',
            'failures': 'frames where the tracker reported failure (ok false); an empty/invalid '
            'returned '
            'box is replaced by the previous box',
        },
        'opencv_version': cv2.__version__,
        'trackers': trackers,
        **(
            {'iemd_config': configs.get('iemd', TrackerConfig()).to_dict()}
            if 'iemd' in trackers
            else {}
        ),
        'sequences': [s.name for s in sequences],
        'groups': {s.name: s.group for s in sequences},
        'frame_rates': {s.name: s.frame_rate for s in sequences},  # Hz; None: unknown
        'ground_truth': {
            s.name: [[None if np.isnan(v) else v for v in box] for box in s.gt_boxes.tolist()]
            for s in sequences
        },
        'long_term': {
            trk: mean_long_term(
                [
                    results[trk][s.name]['long_term']
                    for s in sequences
                    if 'long_term' in results[trk][s.name]
                ]
            )
            for trk in trackers
        },
        'frame_numbers': {s.name: list(s.frame_numbers) for s in sequences},
        'results': results,
    }
    (out / 'results.json').write_text(_dumps(doc))
    return doc


def results_digest(doc: dict) -> str:
    """
    SHA-256 of a results document as ``results.json`` holds it.

    Less the wall-clock fields of its results.

    Everything else a run writes is computed from the frames by deterministic trackers, so two runs
    of the same trackers on the same sequences have the same digest, whichever workers ran them.

    Parameters
    ----------
    doc : dict
        The document :func:`evaluate` returns, or ``results.json`` read back.

    Returns
    -------
    str
        The hexadecimal digest.

    """
    results = {
        trk: {
            key: {k: v for k, v in entry.items() if k not in WALL_CLOCK_FIELDS}
            for key, entry in per_sequence.items()
        }
        for trk, per_sequence in doc['results'].items()
    }
    return hashlib.sha256(_dumps({**doc, 'results': results}).encode()).hexdigest()


def _dumps(doc: dict) -> str:
    return json.dumps(doc, indent=1, allow_nan=False, default=_json_default)


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f'not JSON serialisable: {type(obj).__name__}')
