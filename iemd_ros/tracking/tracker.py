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
The iEMD tracker.

Algorithm 1 with the extensions of sections 5.1 and 6.1 and discriminative models around it.

OpenCV-style API: ``init(frame, box)`` then ``update(frame, prior=None)``.

Per frame: where the translation filter's response is of high confidence by LMCF's test (its peak
and APCE both near their means over the frames that learned), the filter's peak is the only start;
otherwise the starts (the prediction, the optical flow's, the translation filter's and the colour
model's windows) are compared by the EMD between their sparse-coding histograms and the target's
and by the search's score; with ``n_iter`` > 0 the best by EMD and the best by score are descended
(Algorithm 1: move against the EMD's gradient while it decreases; the ``paper`` preset descends,
the default does not: docs/decisions.md#descent-off); the window of lower score is kept,
preferring one the occlusion check accepts; then the scale is estimated at it, on a tracked colour
frame the window moves by ``colour_merge`` of its mean-shift step on the colour model's beta, and
the models learn unless the frame is held or lost: after ``update`` has returned, on a thread of
their own.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
import dataclasses
from dataclasses import dataclass
import enum
import functools

import cv2
from iemd_ros.common.boxes import box_centre, centre_box, check_box
from iemd_ros.common.limits import TARGET_SIDE
from iemd_ros.common.parallel import InlineExecutor
from iemd_ros.tracking.appearance import (
    grey_levels,
    ImagePyramid,
    PatchLayout,
    window_axes,
)
from iemd_ros.tracking.candidate import CandidateModel, SearchContext, TargetModel
from iemd_ros.tracking.colour_model import ColourModel
from iemd_ros.tracking.config import ScaleEstimator, TrackerConfig
from iemd_ros.tracking.flow import window_flow
from iemd_ros.tracking.memory import running_average
from iemd_ros.tracking.scale_filter import ScaleFilter
from iemd_ros.tracking.template import TemplateDictionary
from iemd_ros.tracking.translation_filter import TranslationFilter
import numpy as np

__all__ = ['IemdTracker', 'TrackResult', 'Cause', 'warm_up']

# the scale search never shrinks a window's shorter side below this (image pixels)
MIN_SIDE_PX = 4.0
# learning rate of the running mean that update_confidence compares the response with
CONFIDENCE_RATE = 0.1
WORKERS = 2  # threads the independent models of a frame run on, beside the caller's
# lost frames searched only around the prediction before the whole frame is searched too
FRAME_SEARCH_AFTER = 5
# re-detection's other sizes, relative to the lost window's, one per lost frame in turn: TLD's
# scanning grid steps the size by 1.2 (Kalal et al., TPAMI 2012, section 5.3)
REDETECT_SIZES = (1.2**-2, 1.2**-1, 1.2, 1.2**2)
# LMCF's high-confidence test (Wang et al., CVPR 2017, section 3.3): the filter's peak and its APCE
# at least these fractions of their means over the frames that learned (its beta_1 and beta_2)
CONFIDENT_PEAK = 0.7
CONFIDENT_APCE = 0.45
# a constant-false-alarm-rate level for re-detection (Finn and Johnson, RCA Review 1968): the best
# peaks of this many lost frames measure the background, a peak this many of their standard
# deviations above their mean stands out from it
BACKGROUND_PEAKS_MIN = 20
BACKGROUND_PEAK_STDS = 4.0


class Cause(enum.Enum):
    """
    Why a frame was lost or held (TrackResult.cause).

    TrackResult.reason words it with the figures.
    """

    # too little of the window inside the image
    OUT_OF_VIEW = 'out of view'
    # the window no longer looks like the target
    EMD_ABOVE_BACKGROUND = "EMD above the background's"
    # held: the occlusion check
    LOW_RESPONSE = 'low filter response'
    # the filter's peak far below its running mean
    NO_PEAK = 'no filter peak'
    # found again while lost (not learned from)
    REDETECTED = 're-detected'


@dataclass
class TrackResult:
    """What :meth:`IemdTracker.update` found on one frame."""

    box: tuple[float, float, float, float]  # x, y, w, h (0-based, top-left + size)
    emd: float  # of the window the search converged to (with the scale filter: before its resize)
    iterations: int  # descent iterations of the chosen start
    lost: bool
    scale: float = 1.0  # relative scale change chosen this frame
    # orientation of the tracked window (radians, from the priors); box is its bounding box
    angle: float = 0.0
    # starting points searched (the prediction, the flow, filter and colour starts, the particles)
    starts: int = 1
    codings: int = 0  # candidate models built (windows sampled and sparse-coded) this frame
    solver_warnings: int = 0  # EMD solves that did not end optimal
    predicted_box: tuple[float, float, float, float] | None = None
    # why the window counts as lost, or why the models did not learn (held), with the figures
    reason: str = ''
    # tracked, but the models did not learn and the size did not change (the occlusion check, or
    # the EMD above the background's while the filter's peak does not say lost)
    held: bool = False
    cause: Cause | None = None  # the reason's kind (None: tracked and learned)


@dataclass
class _Found:
    """What re-detection found on a lost frame (:meth:`IemdTracker._redetection_search`)."""

    wanted: float  # the peak a re-detection needs (_found_level)
    level: str  # how that level was set, for the reason
    centre: np.ndarray | None = None  # the best peak's window centre
    peak: float = -np.inf  # the filter's response there
    searched: int = 0  # regions searched
    parts: int = 0  # the frame's strip count when a strip was searched, else 0
    background: float = 0.0  # the best peak at the lost size: one of the loss's background peaks
    other: np.ndarray | None = None  # the other size searched, if one was


@dataclass
class _Descent:
    """Outcome of a search: the window it ended at and what it cost."""

    model: CandidateModel  # the window it ended at
    emd: float
    iterations: int = 0
    # candidate models built (_descend: its trial steps; _search adds the starts')
    codings: int = 0
    # EMD solves that did not end optimal (likewise: the trials', the starts' by _search)
    warnings: int = 0
    # the filter's response at the window (set by _search: _confidence_check)
    confidence: float | None = None
    held_reason: str = ''

    @property
    def center(self) -> np.ndarray:
        """Window centre, image pixels."""
        return self.model.center


class IemdTracker:
    """
    iEMD visual tracker (Yao & Dani): sparse-coding histograms, the EMD, its gradient descent.

    Parameters
    ----------
    config : TrackerConfig, optional
        The tracker's parameters (default: ``TrackerConfig()``, the ``default`` preset).
    threads : bool, optional
        Learn from a frame after :meth:`update` has returned, and run a frame's independent models
        side by side, on threads shared by the process's trackers (default): the shortest wait for
        each result, for frames that arrive live.  False runs everything in the caller's thread:
        the same results, and more frames a second when they are processed back to back
        (docs/decisions.md#offline-inline).

    Examples
    --------
    >>> tracker = IemdTracker()
    >>> tracker.init(frame, (x, y, w, h))         # doctest: +SKIP
    >>> result = tracker.update(next_frame)       # doctest: +SKIP

    """

    def __init__(self, config: TrackerConfig | None = None, *, threads: bool = True):
        self.config = config if config is not None else TrackerConfig()
        if not isinstance(self.config, TrackerConfig):
            raise ValueError('config must be a TrackerConfig')
        # where learning and a frame's independent models run
        if threads:
            self._learner, self._workers = _learner(), _workers()
        else:
            self._learner = self._workers = InlineExecutor()
        cfg = self.config
        self.layout = PatchLayout(cfg.template_size, cfg.patch_size, cfg.patch_step)
        self._center = None
        self._size = None
        self._previous = None  # grey levels of the last frame, for the flow start
        # orientation of the tracked window (radians), only ever changed by priors
        self._angle = 0.0
        self._background_emd = np.inf
        self._clock = 0.0  # time since init, in reference frames (TrackerConfig.reference_rate)
        self._lost = False
        self._confidence = None
        self._peak_apce_sums, self._peak_apce_count, self._peak_apce = np.zeros(2), 0, None
        self._learning = None  # the models' learning from the last tracked frame (a Future)

    # ------------------------------------------------------------------ API
    def init(self, frame: np.ndarray, box) -> None:
        """
        Start tracking the target in ``box`` = (x, y, w, h) of ``frame``.

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 image.
        box : sequence of 4 float
            (x, y, w, h), 0-based top-left corner and size in pixels.

        Raises
        ------
        ValueError
            For a frame that is not such an image, or a box that is not finite, empty, outside the
            image or larger than it (:data:`~iemd_ros.common.limits.TARGET_SIDE`).

        """
        _check_frame(frame)
        x, y, w, h = _check_box(box, frame.shape)
        self.wait_learned()
        cfg = self.config
        self._center = box_centre((x, y, w, h))
        self._size = np.array([w, h], dtype=np.float64)
        self._angle = 0.0
        grey, pyramid = self._take_frame(frame)
        self._previous = grey if cfg.flow_start else None
        template = pyramid.sample(self._center, self._size, cfg.template_size)
        self.dictionary = TemplateDictionary(
            self.layout, cfg.n_templates, cfg.lam, cfg.forgetting, cfg.reconstruction_lambda
        )
        self.dictionary.add(template, 0.0, 0)
        self._target_eps = self.layout.extract(template)  # epsilon_u of I_0 (Algorithm 1)
        self._refresh_target()
        self._background_emd = self._measure_background_emd(pyramid)
        self._scale_filter = None
        if cfg.scale_estimator is ScaleEstimator.FILTER and cfg.scale_step > 0:
            self._scale_filter = ScaleFilter(scale_step=1.0 + cfg.scale_step)
            self._scale_filter.init(frame, self._center, self._size)
        self._colour_model = None
        if cfg.colour_weight > 0 and _is_colour(frame):
            self._colour_model = ColourModel()
            self._colour_model.init(frame, self._center, self._size)
        self._translation_filter = None
        if cfg.translation_weight > 0:
            self._translation_filter = TranslationFilter()
            self._translation_filter.init(
                frame,
                self._center,
                self._size,
                _is_colour(frame),
                colour_model=self._colour_model,
            )
        # the colour model has estimated on this frame (not on a grey frame)
        self._colour_now = False
        self._clock = 0.0
        self._lost = False
        # running mean of the filter's response at the window over frames that learned
        self._confidence = None
        # sums of the filter's (peak, APCE) over the frames that learned, and their count
        self._peak_apce_sums, self._peak_apce_count = np.zeros(2), 0
        self._peak_apce = None  # this frame's (peak, APCE), learned from if the frame is tracked
        # the strip of the frame the next lost frame searches (TranslationFilter.frame_strip)
        self._search_part = 0
        self._lost_frames = 0  # lost frames in a row
        # lost: count, sum and sum of squares of re-detection's best peak on this loss's frames
        self._background_peaks = np.zeros(3)
        # lost: where the target was lost, moved by the priors since (re-detection looks there)
        self._anchor = None
        self._prediction = None  # this frame's predicted centre

    def update(self, frame: np.ndarray, prior=None, interval: float | None = None) -> TrackResult:
        """
        Track the target into ``frame``.

        Parameters
        ----------
        frame : ndarray
            HxW or HxWx3 (BGR) uint8 image, the next frame.  The models learn from it after this
            returns: do not write into it before the next call or :meth:`wait_learned`.
        prior : array_like (3, 3), optional
            Homography taking the previous frame's pixels to this frame's (the gyro's ``K R^T
            K^-1``, eq. 23): the prediction moves, turns and scales with it.
        interval : float, optional
            Seconds since the previous frame (from their stamps): the models learn from this frame
            as from ``interval x reference_rate`` frames (:mod:`~iemd_ros.tracking.memory`).
            None: one frame at the reference rate.

        Returns
        -------
        TrackResult
            The window found, its EMD and what the search cost; ``lost`` / ``held`` with their
            cause.

        Raises
        ------
        ValueError
            For a bad frame, prior (non-finite, singular, or mapping the window to infinity) or
            interval (not finite and positive); the tracker's state is then unchanged.

        """
        if self._center is None:
            raise RuntimeError('IemdTracker.update() called before init()')
        _check_frame(frame)
        # the reference frames this frame stands for, as its models learn from it
        frames = (
            1.0 if interval is None else _check_interval(interval) * self.config.reference_rate
        )
        center, size, angle, anchor = (
            self._center.copy(),
            self._size.copy(),
            self._angle,
            self._anchor,
        )
        # may raise ValueError: before any state changes, so a retry sees none
        if prior is not None:
            prior = _check_prior(prior)
            center, size, turn = _apply_prior(prior, center, size)
            angle = _wrap_angle(angle + turn)
            anchor = None if anchor is None else _apply_prior(prior, anchor, size)[0]
        cfg = self.config
        # a lost frame's re-detection searches on a worker beside the local search
        search = self._redetection_search(frame, anchor, size, angle) if self._lost else None
        # what needs no model (grey levels, pyramid, the filter's sample) runs while the models
        # still learn from the last frame
        grey, pyramid = self._take_frame(frame)
        visible = _visible_fraction(center, size, angle, frame.shape)
        flow = filter_move = self._peak_apce = None
        in_view = visible >= cfg.min_visible
        filtering = in_view and self._translation_filter is not None
        if filtering:
            region = self._translation_filter.sample(frame, center, size, angle)
        self.wait_learned()
        if filtering:
            filter_move = self._translation_filter.estimate(region)
            confidence = self._translation_filter.confidence
            self._peak_apce = np.array([confidence['peak'], confidence['apce']])
        confident = self._filter_confident()
        # the flow is a start of the search, which a confident filter's peak makes unneeded
        if in_view and cfg.flow_start and not confident:
            box = _box(self._center, self._size, self._angle)
            flow = self._workers.submit(
                window_flow, self._previous, grey, box, prior, cfg.flow_max_error
            )
        self._previous = grey if cfg.flow_start else None
        self._clock += frames
        self._anchor, self._prediction = anchor, center
        predicted = _box(center, size, angle)
        # the prior moved the window out of view: keep its place, search only the frame
        if not in_view:
            redetected = (
                self._redetect(frame, pyramid, size, angle, predicted, 0, 0, search)
                if self._lost
                else None
            )
            return redetected or self._lose(
                center,
                size,
                angle,
                predicted,
                Cause.OUT_OF_VIEW,
                f'only {visible:.0%} of the predicted window is inside the image',
            )
        best, searches, starts = self._search_all(
            frame, flow, filter_move, confident, pyramid, center, size, angle
        )
        # held or lost: the window keeps its size and takes no colour step
        tracked = not best.held_reason and not self._lost
        final, scale = _Descent(model=best.model, emd=best.emd), 1.0
        if tracked:
            final, scale = self._estimate_scale(
                frame, best, _scale_bounds(best.model.size, frame.shape)
            )
        emd, new_center, new_size = final.emd, final.center, best.model.size * scale
        # the colour model's position merged in as Staple merges its responses: a share of the
        # window's mean-shift step on the target's colours (docs/decisions.md#colour-mean-shift)
        if tracked and self._colour_now and cfg.colour_merge > 0:
            new_center = new_center + cfg.colour_merge * self._colour_model.mean_shift(
                frame, new_center, new_size, angle
            )
        codings = sum(s.codings for s in searches) + final.codings
        cause, reason = self._lost_reason(emd, new_center, new_size, angle, frame.shape)
        # while tracking, a window the EMD no longer takes for the target is held, not lost, as
        # long as the filter's peak does not say lost: the box is still reported
        # (docs/decisions.md#emd-held)
        emd_held = cause is Cause.EMD_ABOVE_BACKGROUND and tracked and self._filter_holds()
        if emd_held:  # the EMD's cause and reason stay the result's
            new_center, new_size = final.center, best.model.size
        elif cause is None:  # lost until the peak is back to found_response x its mean: hysteresis
            cause, reason = self._peak_check(
                cfg.found_response if self._lost else cfg.lost_response
            )
        if cause is not None and self._lost:
            redetected = self._redetect(
                frame, pyramid, size, angle, predicted, starts, codings, search
            )
            if redetected is not None:
                return redetected
        # the window follows the local search (not out of the image), without learning
        if cause is not None and not emd_held:
            kept = center if cause is Cause.OUT_OF_VIEW else new_center
            return self._lose(
                kept,
                size,
                angle,
                predicted,
                cause,
                reason,
                emd=emd,
                searched=best,
                starts=starts,
                codings=codings,
            )
        if search is not None:  # found by the local search: the caller may reuse the frame next
            search.result()
        self._lost, self._lost_frames, self._anchor = False, 0, None
        held = bool(best.held_reason) or emd_held
        self._center, self._size, self._angle = new_center, new_size, angle
        if best.held_reason:
            cause, reason = Cause.LOW_RESPONSE, best.held_reason
        elif not emd_held:
            if self._peak_apce is not None:
                self._peak_apce_sums += self._peak_apce
                self._peak_apce_count += 1
            # with threads the result goes back now and the models learn meanwhile
            self._learning = self._learner.submit(
                self._learn, frame, final, best.confidence, new_center, new_size, angle, frames
            )
        return TrackResult(
            box=_box(new_center, new_size, angle),
            emd=emd,
            iterations=best.iterations,
            lost=False,
            scale=scale,
            angle=angle,
            starts=starts,
            codings=codings,
            solver_warnings=sum(s.warnings for s in searches) + final.warnings,
            predicted_box=predicted,
            reason=reason,
            held=held,
            cause=cause,
        )

    def wait_learned(self) -> None:
        """
        Wait until the models have learned from the last frame :meth:`update` tracked.

        :meth:`update` returns its result before the models learn from the frame; they learn on a
        thread of their own, and the next :meth:`update` or :meth:`init` waits for them first.
        Call this before writing into that frame's buffer or reading the models.  An error raised
        while learning is raised here.
        """
        learning, self._learning = self._learning, None
        if learning is not None:
            learning.result()

    # ------------------------------------------------------------ internals
    def _lose(
        self,
        center,
        size,
        angle,
        predicted,
        cause: Cause,
        reason: str,
        emd: float = float('inf'),
        searched: _Descent | None = None,
        starts: int = 0,
        codings: int = 0,
    ) -> TrackResult:
        """
        Return the lost frame's result.

        The window is kept at ``center`` (the prediction, or where the local search took it), so it
        moves with the prior while lost; on the first lost frame the predicted centre becomes the
        place re-detection looks at.
        """
        if not self._lost:
            self._anchor = np.asarray(self._prediction, dtype=np.float64)
            self._background_peaks = np.zeros(3)
        self._center, self._size, self._angle, self._lost = center, size, angle, True
        self._lost_frames += 1
        return TrackResult(
            box=_box(center, size, angle),
            emd=emd,
            iterations=searched.iterations if searched else 0,
            lost=True,
            angle=angle,
            starts=starts,
            codings=codings,
            predicted_box=predicted,
            reason=reason,
            cause=cause,
        )

    def _peak_check(self, threshold: float) -> tuple[Cause | None, str]:
        """
        (NO_PEAK, reason) when the translation filter's peak near the prediction is too low.

        Too low: below ``threshold`` times the running mean of its response on learned frames
        (LCT's re-detection trigger).  Else (None, "").
        """
        if self._translation_filter is None or self._confidence is None:
            return None, ''
        peak = self._translation_filter.response_peak
        if peak >= threshold * self._confidence:
            return None, ''
        return (
            Cause.NO_PEAK,
            f'filter peak {peak:.3f} < {threshold} x its running mean {self._confidence:.3f}',
        )

    def _filter_holds(self) -> bool:
        """
        Whether the translation filter's peak near the prediction does not say lost.

        Not below ``lost_response`` times its running mean (before any frame learned it cannot say
        so); False without the filter.
        """
        return (
            self._translation_filter is not None
            and self._peak_check(self.config.lost_response)[0] is None
        )

    def _redetect(
        self, frame, pyramid, size, angle, predicted, starts: int, codings: int, search
    ) -> TrackResult | None:
        """
        Re-detect the target on a lost frame the local search did not confirm.

        ``search`` is :meth:`_redetection_search`'s Future (None: no frame learned yet, no response
        to compare a candidate with).  The result when the best peak it found reaches the level of
        :func:`_found_level` and its window's EMD is below the lost limit, else None; a window
        found at another size keeps the lost size unless its EMD is lower at the other (the
        paper's scale rule, section 6.1).  Nothing learns from the frame; its best peak at the
        lost size joins the loss's background peaks.
        """
        if search is None:
            return None
        found = search.result()
        if found.parts:
            self._search_part = (self._search_part + 1) % found.parts
        if found.searched:
            peak = found.background
            self._background_peaks += (1.0, peak, peak * peak)
        if found.peak < found.wanted:
            return None
        centre, other = found.centre, found.other
        model = CandidateModel(self._context(pyramid, angle), centre, size)
        emd, resized = model.emd()[0], False
        if other is not None:  # the scale variant at the same centre
            emd_other = model.at(centre, other).emd()[0]
            if emd_other < emd:
                emd, size, resized = emd_other, other, True
        if self._lost_reason(emd, centre, size, angle, frame.shape)[0] is not None:
            return None
        self._center, self._size, self._angle, self._lost, self._lost_frames = (
            centre,
            size,
            angle,
            False,
            0,
        )
        self._anchor = None
        return TrackResult(
            box=_box(centre, size, angle),
            emd=emd,
            iterations=0,
            lost=False,
            angle=angle,
            starts=starts + found.searched,
            codings=codings + (1 if other is None else 2),
            predicted_box=predicted,
            cause=Cause.REDETECTED,
            reason=(
                f're-detected: filter peak {found.peak:.3f} >= {found.level}'
                + (f', at {size[0]:.0f}x{size[1]:.0f} px (another size)' if resized else '')
            ),
        )

    def _redetection_search(self, frame, anchor, size, angle):
        """
        Return a Future of where the translation filter finds the target on this lost frame.

        The filter searches where the target was lost (``anchor``: that place moved by the priors
        since), then, lost for ``FRAME_SEARCH_AFTER`` frames (a short loss is found again near
        where it happened), one strip of the whole frame (the frame is scanned over lost frames)
        refined by a search at its peak.  Where no peak reaches the level of :func:`_found_level`,
        the highest, if more than a cell from the centre of the region it was found in, is
        searched again in a region centred on it (the cosine window weakens a peak off the
        centre); then, still short, the filter searches its place at one other size of
        ``REDETECT_SIZES`` (a target may come back nearer or farther).  None without the filter or
        before any frame learned.  The search runs on a worker beside the local search: it keeps
        nothing, and the models it reads do not learn while the target is lost.
        """
        tf, cfg = self._translation_filter, self.config
        if tf is None or self._confidence is None:
            return None
        wanted, level = _found_level(
            self._confidence, self._background_peaks, cfg.found_response, cfg.lost_response
        )
        in_view = _visible_fraction(anchor, size, angle, frame.shape) >= cfg.min_visible
        scan = self._lost_frames >= FRAME_SEARCH_AFTER
        part, factor = self._search_part, _redetect_factor(self._lost_frames, size, frame.shape)

        def peak_at(at, window) -> tuple[np.ndarray, float]:
            region = tf.sample(frame, at, window, angle)
            move, value = tf.locate(region)
            return region.center + move, value

        def search() -> _Found:
            candidates = []  # (centre, filter peak there, where its region was centred)
            parts = 0
            if in_view:
                candidates.append(peak_at(anchor, size) + (anchor,))
            if scan and not (candidates and candidates[0][1] >= wanted):
                strip = tf.frame_strip(frame, size, part)
                coarse, parts = tf.search_frame(strip)[0], strip.parts
                candidates.append(peak_at(coarse, size) + (coarse,))
            if not candidates:
                return _Found(wanted, level)
            (centre, peak, at), searched = max(candidates, key=lambda c: c[1]), len(candidates)
            # the cosine window weakens a peak off the region's centre: search again centred on it
            if peak < wanted and np.hypot(*(centre - at)) > tf.cell_size(size):
                centre, peak = peak_at(centre, size)
                searched += 1
            found = _Found(wanted, level, centre, peak, searched, parts, background=peak)
            if peak >= wanted or factor == 1.0:
                return found
            other = size * factor
            if _visible_fraction(centre, other, angle, frame.shape) < cfg.min_visible:
                return dataclasses.replace(found, centre=None, peak=-np.inf, other=other)
            centre, peak = peak_at(centre, other)
            return dataclasses.replace(
                found, centre=centre, peak=peak, other=other, searched=searched + 1
            )

        return self._workers.submit(search)

    def _filter_confident(self) -> bool:
        """
        Whether this frame's translation filter estimate passes LMCF's high-confidence test.

        Its peak at least ``CONFIDENT_PEAK`` and its APCE at least ``CONFIDENT_APCE`` times their
        means over the frames that learned; not without an estimate or before any such frame.
        """
        if self._peak_apce is None or not self._peak_apce_count:
            return False
        means = self._peak_apce_sums / self._peak_apce_count
        return bool(np.all(self._peak_apce >= [CONFIDENT_PEAK, CONFIDENT_APCE] * means))

    def _search_all(self, frame, flow, filter_move, confident, pyramid, center, size, angle):
        """
        (best descent, every search run, starts searched) from the prediction ``center``.

        With the translation filter ``confident``, its peak (``center + filter_move``) alone;
        otherwise the fine starts (the flow's, a Future or None; the filter's; the colour model's)
        and, when the frame looks lost, section 6.1's particles.
        """
        cfg = self.config
        self._colour_now = self._colour_model is not None and frame.ndim == 3
        context = self._context(pyramid, angle)
        if confident:
            best = self._search([CandidateModel(context, center + filter_move, size)], center)
            return best, [best], 1
        # the colour model's window runs on a worker thread (beside the flow's)
        colour = None
        if self._colour_now:
            colour = self._workers.submit(self._colour_model.estimate, frame, center, size, angle)
        # the prediction's window is coded and solved here while the workers run
        predicted = CandidateModel(context, center, size)
        predicted.emd()
        moves = [flow.result() if flow else None, filter_move, colour.result() if colour else None]
        fine_starts = [
            center + move
            for move in moves
            if move is not None and np.linalg.norm(move) >= cfg.min_step_px
        ]
        best = self._search(
            [predicted, *(CandidateModel(context, s, size) for s in fine_starts)], center
        )
        searches, starts = [best], 1 + len(fine_starts)
        if cfg.n_particles and (
            self._lost or best.emd > cfg.particle_trigger * self._background_emd
        ):
            distance = cfg.particle_offset * (2.0 if self._lost else 1.0)
            particles = center + _particle_offsets(cfg.n_particles, distance) * size
            candidate = self._search([CandidateModel(context, p, size) for p in particles], center)
            starts += cfg.n_particles
            searches.append(candidate)
            if candidate.emd < best.emd:
                best = candidate
        return best, searches, starts

    def _estimate_scale(self, frame, best: _Descent, bounds) -> tuple[_Descent, float]:
        """
        (window, relative scale) at the converged window.

        The scale filter's estimate, the window not solved again at the new size
        (docs/decisions.md#scale-no-resolve), or the paper's EMD variants.
        """
        if self._scale_filter is not None:
            scale = self._scale_filter.estimate(
                frame, best.center, best.model.size, best.model.angle, bounds
            )
            return _Descent(model=best.model, emd=best.emd), scale
        return self._search_scale(best, bounds)

    def _learn(self, frame, final: _Descent, confidence, center, size, angle, frames) -> None:
        """
        Every model learns the window of a tracked frame, as ``frames`` reference frames.

        The response's running mean, both filters, the colour histograms and the template
        dictionary (Algorithm 2).
        """
        if confidence is not None:
            self._confidence = (
                confidence
                if self._confidence is None
                else running_average(self._confidence, confidence, CONFIDENCE_RATE, frames)
            )
        # The scale filter and the colour model learn on the workers beside the filter.
        learners = [self._scale_filter.update] if self._scale_filter is not None else []
        learners += [self._colour_model.update] if self._colour_now else []
        jobs = [
            self._workers.submit(learn, frame, center, size, angle, frames) for learn in learners
        ]
        if self._translation_filter is not None:
            self._translation_filter.update(frame, center, size, angle, frames)
        if self.config.update_templates and self.dictionary.observe(
            final.model.template, final.emd, self._clock
        ):
            self._refresh_target()
        for job in jobs:
            job.result()

    def _context(self, pyramid: ImagePyramid, angle: float = 0.0) -> SearchContext:
        """
        Return the search context of windows turned by ``angle`` on ``pyramid``'s frame.

        It holds the current target model and dictionary.
        """
        cfg = self.config
        return SearchContext(
            pyramid,
            self.layout,
            self._target,
            self.dictionary,
            cfg.alpha,
            cfg.kernel_bandwidth,
            angle=angle,
        )

    def _take_frame(self, frame: np.ndarray):
        """
        (``frame``'s grey levels, its pyramid).

        With the flow start the grey levels are a copy, kept for the next frame (the caller may
        reuse its buffer).
        """
        grey = grey_levels(frame, copy=self.config.flow_start)
        return grey, ImagePyramid(grey)

    def _confidence_check(self, center) -> tuple[float | None, str]:
        """
        Return (the filter's response at the window centre ``center``, why the frame is held).

        The filter is the translation filter; the reason is "" when the frame learns.  Held: the
        response is below ``update_confidence`` times its running mean over the frames that learned
        (docs/decisions.md#occlusion-check).  (None, "") without the filter or the check.
        """
        threshold = self.config.update_confidence
        if self._translation_filter is None or threshold == 0:
            return None, ''
        confidence = self._translation_filter.response_at(center)
        if self._confidence is None or confidence >= threshold * self._confidence:
            return confidence, ''
        return confidence, (
            f'models not updated: filter response {confidence:.3f} < {threshold} x its running '
            f'mean {self._confidence:.3f} (occlusion?)'
        )

    def _lost_reason(
        self, emd: float, center, size, angle: float, shape
    ) -> tuple[Cause | None, str]:
        """
        (cause, reason) when the window (``center``, ``size``, ``angle``) counts as lost.

        ``emd`` is the window's EMD; (None, "") when the window does not count as lost.
        """
        cfg = self.config
        visible = _visible_fraction(center, size, angle, shape)
        if visible < cfg.min_visible:
            return Cause.OUT_OF_VIEW, f'only {visible:.0%} of the window is inside the image'
        if not np.isfinite(emd) or emd > cfg.lost_factor * self._background_emd:
            return (
                Cause.EMD_ABOVE_BACKGROUND,
                f'EMD {emd:.4f} > {cfg.lost_factor} x background EMD {self._background_emd:.4f}',
            )
        return None, ''

    def _measure_background_emd(self, pyramid: ImagePyramid) -> float:
        """
        Median EMD between the target and the four windows one window size away in I_0.

        The reference for "this no longer looks like the target" of the particles and the lost
        state (docs/decisions.md#background-emd).
        """
        context = self._context(pyramid)
        values = [
            CandidateModel(context, self._center + offset * self._size, self._size).emd()[0]
            for offset in _particle_offsets(4, 1.0)
        ]
        finite = [v for v in values if np.isfinite(v)]
        return float(np.median(finite)) if finite else np.inf

    def _refresh_target(self) -> None:
        """
        Target model of eq. (sparse target model) against the current dictionary.

        The appearance vectors stay those of I_0, as in Algorithm 1, and are only recoded
        (docs/decisions.md#target-appearance).
        """
        pooled = self.dictionary.code_weights(self._target_eps)
        self._target = TargetModel.from_patches(
            self.layout.positions(), self._target_eps, pooled, self.config.kernel_bandwidth
        )

    def _search(self, models: list[CandidateModel], prediction) -> _Descent:
        """
        Algorithm 1 from the starts' windows ``models`` (of one size and turn).

        The start of lowest EMD is descended, and with the translation filter or the colour model
        also the start of lowest :meth:`_score`; the descended window of lowest score is kept,
        among those the occlusion check would not hold when there are any
        (:meth:`_confidence_check`).  ``prediction`` is the predicted centre, from which the
        score's motion prior measures a window's displacement.  The descent's capture range is a
        few pixels (docs/decisions.md#capture-range): the other starts are what reach farther.
        """
        size = models[0].size
        # each model caches its EMD
        warnings = sum(_not_optimal(model.emd()[1]) for model in models)
        chosen = [min(models, key=lambda model: model.emd()[0])]
        if self._discriminative:
            checked = min(
                models,
                key=lambda model: self._score(model.emd()[0], model.center, prediction, size),
            )
            chosen += [checked] if checked is not chosen[0] else []
        descents = [self._descend(model) for model in chosen]
        for state in descents:
            state.confidence, state.held_reason = self._confidence_check(state.center)
        confident = [state for state in descents if not state.held_reason]
        best = min(
            confident or descents,
            key=lambda state: self._score(state.emd, state.center, prediction, size),
        )
        best.codings = len(models) + sum(state.codings for state in descents)
        best.warnings = warnings + sum(state.warnings for state in descents)
        return best

    @property
    def _discriminative(self) -> bool:
        """
        Whether this frame's score has terms besides the EMD.

        Those are the translation filter's and the colour model's.
        """
        return self._translation_filter is not None or self._colour_now

    def _score(self, emd: float, center, prediction, size) -> float:
        """
        Return what the search minimizes.

        The EMD, and with the translation filter or the colour model the EMD relative to the
        background EMD less ``translation_weight`` times the filter's response and
        ``colour_weight`` times the colour model's mean at the window centre ``center``, plus
        ``motion_weight`` times the squared displacement from ``prediction`` over the window's area
        (``size`` (w, h)).
        """
        if not self._discriminative:
            return emd
        background = self._background_emd if np.isfinite(self._background_emd) else 1.0
        score = emd / background
        if self._translation_filter is not None:
            score -= self.config.translation_weight * self._translation_filter.response_at(center)
        if self._colour_now:
            score -= self.config.colour_weight * self._colour_model.score_at(center)
        displacement = np.asarray(center, dtype=np.float64) - prediction
        return score + self.config.motion_weight * float(displacement @ displacement) / float(
            size[0] * size[1]
        )

    def _descend(self, model: CandidateModel) -> _Descent:
        """
        Algorithm 1 from the window of ``model``: move against dEMD/dy while the EMD decreases.

        The first step is ``step_px``, halved on an increase until it falls below ``min_step_px``:
        the paper's stopping rule (the EMD no longer decreases at the finest step) with sub-pixel
        moves (docs/decisions.md#descent-step).
        """
        cfg = self.config
        half = model.size / 2.0
        axes = window_axes(model.angle)
        # its solve (cached for _search's winners) is counted by the caller, with its coding
        state = _Descent(model=model, emd=model.emd()[0])
        step, min_step = cfg.step_px, cfg.min_step_px
        grad = None  # dEMD/dy at the current window, computed when a step needs it
        while state.iterations < cfg.n_iter and step >= min_step and np.isfinite(state.emd):
            if grad is None:
                grad = state.model.gradient(cfg.gradient)
            g_px = axes @ (grad / half)  # gradient with respect to image pixels
            norm = np.linalg.norm(g_px)
            if not np.isfinite(norm) or norm == 0:
                break
            state.iterations += 1
            trial = state.model.at(state.center - step * g_px / norm)
            e_try, s_try = trial.emd()
            state.codings += 1
            state.warnings += _not_optimal(s_try)
            if e_try < state.emd:  # the next step needs the gradient at the accepted window
                state.model, state.emd, grad = trial, e_try, None
            else:
                step *= 0.5
        return state

    def _search_scale(
        self, state: _Descent, bounds: tuple[float, float]
    ) -> tuple[_Descent, float]:
        """
        Search the paper's scale variants at the converged centre (section 6.1).

        The window is enlarged and shrunk by ``scale_step``, stepping on in each direction while
        the EMD decreases, up to ``scale_range``, never leaving ``bounds`` (:func:`_scale_bounds`).
        Each variant is the window resampled at s * size, so its patch layout is the target's and
        its EMD compares with the EMD at scale 1.  Returns the chosen window (its ``codings`` and
        ``warnings`` those of the variants) and its relative scale.
        """
        cfg = self.config
        chosen = _Descent(model=state.model, emd=state.emd)
        best_scale = 1.0
        if cfg.scale_step == 0:
            return chosen, best_scale
        n_steps = int(np.floor(cfg.scale_range / cfg.scale_step + 1e-9))
        for direction in (-1.0, 1.0):
            for n in range(1, n_steps + 1):
                scale = 1.0 + direction * n * cfg.scale_step
                if not bounds[0] <= scale <= bounds[1]:
                    break
                model = state.model.at(state.center, state.model.size * scale)
                emd, sol = model.emd()
                chosen.codings += 1
                chosen.warnings += _not_optimal(sol)
                if emd >= chosen.emd:
                    break
                chosen.model, chosen.emd, best_scale = model, emd, scale
        return chosen, best_scale


def warm_up() -> None:
    """
    Compile the tracker's numba kernels now (or load them from numba's on-disk cache).

    Then the first frames of a node or a replay are not spent compiling.
    """
    # a grey frame and a colour one (the colour model runs on colour frames only)
    colour = (np.random.default_rng(0).random((64, 64, 3)) * 255).astype(np.uint8)
    for frame in (np.ascontiguousarray(colour[..., 0]), colour):
        # in this thread: warming starts no thread pool an offline process would not use
        tracker = IemdTracker(threads=False)
        tracker.init(frame, (16, 16, 32, 32))
        tracker.update(frame)


# ---------------------------------------------------------------- helpers
@functools.cache
def _learner() -> ThreadPoolExecutor:
    """
    Return the thread the models learn on after :meth:`IemdTracker.update` has returned.

    It is shared by every tracker of the process: one tracker's learning runs beside the next
    tracker's search.
    """
    return ThreadPoolExecutor(max_workers=1, thread_name_prefix='iemd-learn')


@functools.cache
def _workers() -> ThreadPoolExecutor:
    """
    Return the threads the models of one frame run on side by side.

    They are shared by every tracker of the process.
    """
    return ThreadPoolExecutor(max_workers=WORKERS, thread_name_prefix='iemd-tracker')


def _box(center, size, angle: float = 0.0):
    """Axis-aligned box (x, y, w, h) around the window, rotated by ``angle`` about its centre."""
    c, s = abs(np.cos(angle)), abs(np.sin(angle))
    w, h = c * size[0] + s * size[1], s * size[0] + c * size[1]
    return tuple(float(v) for v in centre_box(center, (w, h)))


def _scale_bounds(size, shape) -> tuple[float, float]:
    """
    (lowest, highest) relative scale of the window of ``size`` (w, h).

    Its shorter side stays at least MIN_SIDE_PX and its area at most the image's (``shape``),
    DSST's bounds on the scale factor, by area so that they hold for a turned window too.  A window
    already outside them may not move further out (docs/decisions.md#scale-bounds).
    """
    lower = MIN_SIDE_PX / float(min(size))
    upper = float(np.sqrt(shape[0] * shape[1] / (size[0] * size[1])))
    return min(lower, 1.0), max(upper, 1.0)


def _redetect_factor(lost_frames: int, size, shape) -> float:
    """
    Return the other size re-detection searches on a loss's ``lost_frames``-th frame.

    A factor on the lost size: ``REDETECT_SIZES`` in turn, held within the scale search's bounds
    (:func:`_scale_bounds`); 1.0 where the lost size is already at the bound.
    """
    factor = REDETECT_SIZES[lost_frames % len(REDETECT_SIZES)]
    return float(np.clip(factor, *_scale_bounds(size, shape)))


def _found_level(confidence: float, background, found: float, lost: float) -> tuple[float, str]:
    """
    Return the filter peak a re-detection must reach, and how it was set.

    Parameters
    ----------
    confidence : float
        The running mean of the filter's response on learned frames.
    background : array_like
        (count, sum, sum of squares) of re-detection's best peak on the earlier frames of this
        loss.
    found, lost : float
        ``found_response`` and ``lost_response``.

    Returns
    -------
    level : float
        ``found`` times ``confidence``; from ``BACKGROUND_PEAKS_MIN`` background peaks on, no
        higher than ``BACKGROUND_PEAK_STDS`` standard deviations above their mean (a target that
        comes back changed stands out from the background the loss has seen, a constant false
        alarm rate's level), and never below ``lost`` times ``confidence`` (a window that would
        be lost at once is not taken).
    how : str
        The level and its rule, for the result's reason.

    """
    level = found * confidence
    n, total, squares = background
    if n >= BACKGROUND_PEAKS_MIN:
        mean = total / n
        sd = np.sqrt(max(squares / n - mean * mean, 0.0))
        above = max(mean + BACKGROUND_PEAK_STDS * sd, lost * confidence)
        if above < level:
            return above, (
                f'{above:.3f}: {BACKGROUND_PEAK_STDS:g} sd above the best peaks of {n:.0f} '
                f'lost frames, at least {lost} x its running mean'
            )
    return level, f'{level:.3f} = {found} x its running mean'


def _not_optimal(solution) -> int:
    """
    1 if an EMD solve ended without an optimal flow, else 0.

    Counted in TrackResult.solver_warnings.
    """
    return int(solution is not None and not solution.optimal)


def _wrap_angle(angle: float) -> float:
    return float((angle + np.pi) % (2.0 * np.pi) - np.pi)


def _particle_offsets(n: int, distance: float) -> np.ndarray:
    """Return n starting offsets (in window sizes) evenly around the prediction."""
    angles = 2.0 * np.pi * np.arange(n) / max(n, 1)
    return distance * np.column_stack([np.cos(angles), np.sin(angles)])


def _visible_fraction(center, size, angle: float, shape) -> float:
    """
    Share of the window's area inside the image, the window turned by ``angle`` about its centre.

    In pixel-edge coordinates the image spans [0, W] x [0, H] and the window is
    centred at ``center + 0.5`` (pixel centres at integers, as ``centre_box``).
    """
    h_img, w_img = shape[:2]
    if angle == 0.0:  # the overlap of two axis-aligned rectangles
        lo = np.asarray(center, dtype=np.float64) + 0.5 - np.asarray(size) / 2.0
        hi = lo + np.asarray(size)
        overlap = np.clip(np.minimum(hi, (w_img, h_img)) - np.maximum(lo, 0.0), 0.0, None)
        return float(overlap[0] * overlap[1]) / float(size[0] * size[1])
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) * (
        np.asarray(size) / 2.0
    )
    window = corners @ window_axes(angle).T + np.asarray(center) + 0.5
    image = np.array([[0.0, 0.0], [w_img, 0.0], [w_img, h_img], [0.0, h_img]], dtype=np.float32)
    area = cv2.intersectConvexConvex(window.astype(np.float32), image)[0]
    return max(float(area), 0.0) / float(size[0] * size[1])


def _apply_prior(H: np.ndarray, center, size):
    """
    Move the window by the homography.

    Returns the centre mapped, the size scaled by sqrt|det J| of H there, and the turn (radians) of
    J's rotation part, which the window's orientation follows.

    The turn is what keeps a camera roll from misaligning the window with the
    target (the CMU desk sequence rolls the eagle's head by up to 180 degrees).
    """
    p = H @ np.array([center[0], center[1], 1.0])
    new_center = p[:2] / p[2]
    # Jacobian of the projective map at the centre.
    J = (H[:2, :2] - np.outer(new_center, H[2, :2])) / p[2]
    scale = float(np.sqrt(abs(np.linalg.det(J))))
    if not np.all(np.isfinite(new_center)) or not np.isfinite(scale) or scale <= 0:
        raise ValueError('prior homography maps the target centre to infinity')
    turn = float(np.arctan2(J[1, 0] - J[0, 1], J[0, 0] + J[1, 1]))
    return new_center, size * scale, turn


def _is_colour(frame: np.ndarray) -> bool:
    """
    Whether ``frame`` has colour.

    Colour: three channels that are not all equal (grey sequences are often stored as BGR images
    with three equal channels).
    """
    return frame.ndim == 3 and not (
        np.array_equal(frame[..., 0], frame[..., 1])
        and np.array_equal(frame[..., 1], frame[..., 2])
    )


def _check_frame(frame) -> None:
    if not isinstance(frame, np.ndarray):
        raise ValueError(f'frame must be a numpy array, got {type(frame).__name__}')
    if frame.dtype != np.uint8:
        raise ValueError(f'frame must be uint8, got {frame.dtype}')
    if frame.ndim not in (2, 3) or (frame.ndim == 3 and frame.shape[2] != 3):
        raise ValueError(f'frame must be HxW or HxWx3 (BGR), got shape {frame.shape}')
    if frame.shape[0] < 2 or frame.shape[1] < 2:
        raise ValueError(f'frame is empty (shape {frame.shape})')


def _check_box(box, shape):
    x, y, w, h = check_box(box)
    if x + w <= 0 or y + h <= 0 or x >= shape[1] or y >= shape[0]:
        raise ValueError(f'box {box!r} lies outside the {shape[1]}x{shape[0]} image')
    TARGET_SIDE.check('box w', w, shape[1])
    TARGET_SIDE.check('box h', h, shape[0])
    return x, y, w, h


def _check_interval(interval) -> float:
    """Return ``interval`` (s) as a float; ValueError unless it is finite and positive."""
    value = float(interval)
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f'interval must be a finite number of seconds > 0, got {interval!r}')
    return value


def _check_prior(prior) -> np.ndarray:
    H = np.asarray(prior, dtype=np.float64)
    if H.shape != (3, 3):
        raise ValueError(f'prior must be a 3x3 homography, got shape {H.shape}')
    if not np.all(np.isfinite(H)):
        raise ValueError('prior homography has non-finite values')
    if abs(np.linalg.det(H)) < 1e-12:
        raise ValueError('prior homography is singular')
    return H
