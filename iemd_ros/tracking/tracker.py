"""The iEMD tracker (Algorithm 1 with the extensions of sections 5.1 and 6.1).

OpenCV-style API: ``init(frame, box)`` then ``update(frame, prior=None)``.

Per frame and starting point: build the candidate model at the window
(resample, cut into patches, sparse-code them), solve the EMD, move the window against the EMD gradient, and repeat
while the EMD decreases (backtracking the step when it does not); then estimate
the scale at the converged window (the scale filter, or the paper's EMD scale variants).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import cv2
import numpy as np

from iemd_ros.tracking.appearance import ImagePyramid, PatchLayout, grey_levels, to_gray, window_axes
from iemd_ros.common.boxes import box_centre, centre_box, check_box
from iemd_ros.tracking.candidate import CandidateModel, SearchContext, TargetModel
from iemd_ros.tracking.colour_model import ColourModel
from iemd_ros.tracking.flow import window_flow
from iemd_ros.tracking.scale_filter import ScaleFilter
from iemd_ros.tracking.translation_filter import TranslationFilter
from iemd_ros.tracking.template import TemplateDictionary


@dataclass
class TrackerConfig:
    """Parameters of the tracker; defaults follow the paper where it gives values."""

    # (width, height) of the resampled window.  Finer templates with the same 7x7 patch grid were
    # measured over the 12 OTB sequences (README, "Grey levels and template size"): 48x48 31.2 %,
    # 64x64 27.0 %, 96x96 33.2 % (14.6 ms) against 31.9 % for the paper's 32x32.
    template_size: tuple[int, int] = (32, 32)
    patch_size: tuple[int, int] = (8, 8)  # local patch m x n
    patch_step: int = 4
    normalization: str = "patch"  # grey-level normalization of the patches: see PatchLayout.extract
    n_templates: int = 1  # L, templates in the dictionary (the paper gives no value; see IemdTracker)
    lam: float = 0.1  # lambda of eq. (lagrange): measured, see the note in sparse_coding.py
    alpha: float = 0.5  # appearance vs spatial weight of the ground distance
    kernel_bandwidth: float = 1.0  # h in normalized window units (1: ellipse inscribed in the window)
    n_iter: int = 20  # maximum descent iterations per start
    step_px: float = 2.0  # first step along the descent direction, image pixels
    min_step_px: float = 0.5  # stop when backtracking has halved the step below this
    # Descent direction of Algorithm 1: "appearance" (the derivative of the re-sampled model Algorithm 1 evaluates),
    # "envelope" or "paper" (eq. 10: the duals times dw_C/dy, patches fixed); see CandidateModel.gradient.  On a
    # frame shifted by a known offset, descents from up to 3 px off end within 0.5 px of it in 73.6 % of the
    # starts with "appearance", 17.4 % with "paper" or "envelope" (benchmarks/gradient_compare.py, 144 starts).
    # In tracking they tie: 12 OTB sequences x 5 starts (the ground truth and 10 % off along the diagonals)
    # 38.6 / 39.1 / 35.8 %, 4 more starts 10 % off along the axes 37.6 / 37.0 % (envelope not run); "paper" needs
    # no patch Jacobian and takes fewer steps (median update 9.69 against 10.34 ms, 7.2 against 7.8 candidate
    # models per frame on 150 frames of Car4, Bolt2, Woman, DragonBaby and David, interleaved runs).
    gradient: str = "appearance"
    # First descend from the prediction on the next pyramid level (a wider convergence region; see _search).  Off by
    # default since the translation filter's start: 12 OTB sequences x 5 starts 38.6 % without the coarse stage
    # against 38.1 % with it, and median updates 20-30 % shorter (Woman, Bolt2, David: 10.7 / 11.8 / 10.0 ms
    # against 14.7 / 16.5 / 13.1 ms in one run; 10.8 / 13.5 / 11.7 ms for the coarse stage without the filter).
    coarse_to_fine: bool = False
    # Scale at the converged position.  "filter": the DSST scale filter (iemd_ros/scale_filter.py), 33 scales
    # (1 + scale_step)**k, +-37 % per frame; "emd": the paper's EMD of the window scaled by 1 +- scale_step, stepping
    # on while the EMD decreases up to scale_range.  The EMD hardly sees scale (benchmarks/scale_curve.py); 12 OTB
    # sequences x 5 starts, mean average overlap: filter 34.4 % against 32.5 % for the EMD variants (in the loop
    # with an oracle translation the filter's size is 13.8 % off the ground truth, the EMD variants' 17.7 %, no
    # scale search 20.2 %); from the ground truth Car4 87.3 % against 36.7 %; CMU desk with the gyro 83.8 % against
    # 79.3 % (the EMD variants at scale_range 0.1; both 83.7-83.9 % once flow_max_error went to 2 px).  Clipping the
    # filter's estimate to +-2 % per frame, or taking its square root, scored 34.4 / 35.2 % against 35.8 % (the
    # same 60 runs, flow_max_error 2); keeping the size on frames whose EMD exceeds 0.85 / 0.75 x the background
    # EMD 34.0 / 33.1 %.  scale_step 0 keeps the window's size with either estimator.
    scale_estimator: str = "filter"
    scale_step: float = 0.02
    scale_range: float = 0.02  # "emd": largest relative scale change per frame, in scale_step steps (gyro run: 0.1)
    # Section 6.1's extra starts.  First the window's median optical flow (iemd_ros/flow.py), refined at full
    # resolution only.  Measured over the 12 OTB sequences from the ground truth and from it shifted by 10 % along
    # the 4 diagonals (60 runs), with the defaults of the time (particles off, EMD scale variants, the backward
    # Lucas-Kanade pass seeded at the points): mean average overlap 34.1 % against 20.8 % without it.  The
    # figures that follow were measured with the particles on: 26.1 % against 22.2 % without (per start
    # 30.5/27.0/24.0/23.7/25.5 vs 31.9/19.2/23.5/13.5/22.9 %).  Through the coarse stage too it scored 28.7 %
    # (28.0 % with a 15x15 Lucas-Kanade window, 25.7 % at flow_max_error 2 px) but took the pooled
    # median update of benchmarks/bench_speed.py from 8.3 to 10.2 ms.  As the only start (none at the
    # prediction) a prototype scored 27.0 % vs 35.4 % from the ground truth: the flow follows occluders too,
    # the EMD has to choose.  (Particles off: the flow start alone 30.2 %, through the coarse stage 31.4 %.)
    flow_start: bool = True
    # Forward-backward error (px) above which a flow point is dropped.  With the backward pass seeded where the prior
    # takes the points back (flow.py), 60 runs as above with the scale filter: 0.5 / 1 / 2 / 3 / 5 px scored
    # 33.9 / 34.4 / 35.8 / 34.2 / 32.6 %; with the EMD scale variants 1 / 2 px scored 32.5 / 33.1 %.
    flow_max_error: float = 2.0
    # The discriminative check of the starts (iemd_ros/translation_filter.py).  A correlation filter trained on the
    # target against its surroundings adds a start where its response peaks.  The start of lowest EMD is descended
    # (Algorithm 1), and so is the start of lowest score = EMD / background EMD - translation_weight x the filter's
    # response there, when that is another one; the window of lower score is kept.  0: no filter.  12 OTB
    # sequences x 5 starts (as for flow_start), mean average overlap: 38.1 % against 35.8 % without (CSRT 41.8 %),
    # 8.2-9.6 candidate models per frame against 6.7-7.4 (Woman, Bolt2, David).  Weights 0.7 / 1.5 scored 39.0 /
    # 37.2 %, within the spread of such runs; with the colour model 0.5 / 1.5 scored 41.4 / 41.1 % against 42.8 %.
    # Not updating the template and the two filters on frames whose response at the kept window is below 0.2 / 0.35
    # (against learning an occluder) scored 34.4 / 33.2 %; relative to the response's running mean, and keeping the
    # size too, it is update_confidence below.  The response divided by that running mean (about 1 on the target in
    # every sequence; raw, 0.1-0.2 on Woman and 0.3-0.4 on Jogging-2) at weights 0.35 / 0.5 / 0.7 scored 43.4 / 44.5 /
    # 42.0 % over the 5 starts against 47.6 % unscaled (59.3 % from the ground truth alone at 0.5, against 53.5 %).
    translation_weight: float = 1.0
    # Colour evidence (iemd_ros/colour_model.py, Staple's foreground/background colour histograms), on colour frames
    # only: the window of highest mean colour score is one more start, and colour_weight x that mean at a window is
    # subtracted from the score above.  0: no colour model.  12 OTB sequences x 5 starts (as above), mean average
    # overlap: 42.8 % against 38.6 % without (CSRT 41.8 %); 4 more starts 10 % off along the axes 41.7 % against
    # 37.6 %.  Weights 0.5 / 1 / 1.5 / 2 scored 39.4 / 41.1 / 39.7 / 38.7 % over the 5 starts (1: 42.2 % with a first
    # prototype), 40.7 % at 1 over the axis starts.  Without its start (the colour only in the score), from the ground
    # truth, 43.6 / 41.3 / 44.0 % at 0.5 / 1 / 2 against 44.2 % (Jogging stays lost: the runner is not among the
    # starts).  On grey frames a grey-level histogram in its place took Freeman1 from 62.6 to 26-27 %.
    colour_weight: float = 0.75
    # A motion prior in the same score: motion_weight x |y - prediction|^2 / (w h) is added to it, the negative
    # log of an isotropic Gaussian on the window's displacement from the prediction (in units of sqrt(w h), the
    # window's mean side; 0.05: sigma about 3 mean sides).  Broad by design: it does not hold the window back, it
    # stops a start a window height or more away from winning on a small edge in the other terms (Jogging-1, frame
    # 69: the colour start 105 px below the runner, on the road, won by 0.06 and the tracker never came back).
    # With neither the filter nor the colour model the search is the EMD's alone and the prior is not used.  12 OTB
    # sequences, mean average overlap: 5 starts (as for flow_start) 43.2 % against 42.8 % without; 4 starts 10 % off
    # along the axes 44.6 % against 41.7 %; 4 starts with the box scaled by 0.8 / 0.9 / 1.1 / 1.2 about its centre
    # 39.9 % against 36.0 % (benchmarks/perturbed_starts.py --starts sre runs all 13).  Weights 0.025 / 0.1 scored
    # 43.5 / 41.6 % over the 5 starts and 42.5 / 43.4 % over the axis starts; the displacement in window sizes per
    # axis instead of sqrt(w h) (tall windows then pay more for a sideways move) scored 41.9 / 41.4 % at 0.05 / 0.1
    # over the 5 starts.  Jogging-1 gains most (15.2 to 37.5 % over the 5 starts), Woman loses (55.5 to 49.8 %: when
    # a car hides her legs, about frame 120, far starts are also what brought the window back).
    motion_weight: float = 0.05
    # Occlusion check before learning (LMCF's, Wang et al. CVPR 2017; MOSSE's peak-to-sidelobe check): a frame on
    # which the translation filter's response at the tracked window is below update_confidence x its running mean
    # over the frames that learned counts as the target hidden ("held", TrackResult.held): the window moves, but
    # its size and every model (template, translation and scale filters, colour histograms) stay as they were.
    # 0, or no translation filter: every tracked frame learns.  Why (Jogging-2, from the ground truth): the runner
    # passes behind a post over frames 45-60, the response at the window falls from 0.3-0.4 to 0.14, the scale
    # filter widens the window 1.3x over the post while every model learns the post, and the window rides the post
    # out of the image (14.3 %).  12 OTB sequences, mean average overlap: 5 starts (as for flow_start) 47.6 %
    # against 43.2 % without; 4 axis starts 47.9 against 44.6 %; 4 scaled starts 45.0 against 39.9 %.  0.5 / 0.7
    # / 0.8 scored 44.3 / 46.4 / 39.1 % over the 5 starts (0.7: 46.4 / 44.5 % over the axis / scaled starts).
    # Letting held frames change the size (46.0 %), a running mean over every tracked frame (43.5 %), a slower
    # mean (rate 0.03: 44.4 %) and learning anyway after 10 / 30 held frames in a row (46.7 / 46.2 %) scored lower.
    # Bolt2 loses (30.2 to 21.1 % over the 5 starts): a sprinter's fast change of pose also lowers the response.
    # The search also prefers a descended window that the check would not hold to one it would (_search): Woman,
    # frame 125, a car hiding her legs: the EMD pulled the window 20 px down, where the response was 0.02 (0.11 on
    # her), and she was lost (17.3 %; 73.1 % with the preference).  With it 48.2 / 49.3 / 44.8 % over the 5 / axis
    # / scaled starts, against 47.6 / 47.9 / 45.0 % without.
    update_confidence: float = 0.6
    # Descend every start and keep the window of lowest score: 40.0 % over the same 60 runs, at 14.2-18.8 models
    # per frame (about 1.8x the update time).  With it, weights 0.5 / 2 scored 37.4 / 35.7 %, keeping the lowest
    # EMD instead of the lowest score 34.9 % (these three with a prototype that also took the filter's start within
    # min_step_px of the prediction), and a minimum step of 1 px (fewer backtracking solves) 38.3 %.  With the
    # defaults of 2026-11-23 (the scale filter's window not solved again, the faster lasso) it scored 36.6 %
    # against 38.6 % for the default.
    descend_all_starts: bool = False
    # Then section 6.1's particles, n_particles windows particle_offset window sizes around the prediction.  Off
    # by default: with the flow start they lower the mean average overlap over the same 60 runs from 34.1 % to
    # 26.1 % (per start 40.5/32.0/38.7/30.0/29.5 % without them), 30.5-31.0 % when they run only on lost frames
    # (trigger 100 or 1.0).  A window half a window off, on part of the target, often has a lower EMD than the
    # target under a change of appearance: on Woman (frame 116) and Bolt2 (frame 20) the particles took such a
    # jump and the tracker never came back.  (Before the flow start, one run from the ground truth: 26.7 %
    # without, 27.0 % at offset 0.25.)
    n_particles: int = 0
    particle_offset: float = 0.5  # their distance from the prediction, in window sizes
    # Thresholds relative to the background EMD; measured EMD/background while tracking
    # (IoU > 0.5): Car4 0.51, Woman 0.64, Bolt2 0.77; Bolt2 drifting (IoU < 0.3): 0.85.
    particle_trigger: float = 0.85  # run them when EMD > trigger x background EMD (0: always)
    lost_factor: float = 1.0  # lost when EMD > factor x background EMD (see _measure_background_emd)
    min_visible: float = 0.25  # lost when less of the window than this is inside the image
    update_templates: bool = True  # Algorithm 2
    forgetting: float = 0.95  # gamma_0 of eq. (template update)
    reconstruction_lambda: float = 0.1  # lambda of eq. (reconstructed template)

    def __post_init__(self):
        self.template_size = tuple(int(v) for v in self.template_size)
        self.patch_size = tuple(int(v) for v in self.patch_size)
        checks = [
            (min(self.template_size) >= 8, "template_size must be at least 8x8"),
            (self.n_templates >= 1, "n_templates must be >= 1"),
            (self.lam > 0, "lam must be > 0"),
            (0.0 < self.alpha < 1.0, "alpha must be in (0, 1)"),
            (self.kernel_bandwidth > 0, "kernel_bandwidth must be > 0"),
            (self.n_iter >= 0, "n_iter must be >= 0"),
            (0 < self.min_step_px <= self.step_px, "need 0 < min_step_px <= step_px"),
            (self.gradient in ("appearance", "envelope", "paper"),
             "gradient must be 'appearance', 'envelope' or 'paper'"),
            (0 <= self.scale_step < 0.5, "scale_step must be in [0, 0.5)"),
            (self.scale_step <= self.scale_range < 0.5, "scale_range must be in [scale_step, 0.5)"),
            (self.scale_estimator in ("emd", "filter"), "scale_estimator must be 'emd' or 'filter'"),
            (self.flow_max_error > 0, "flow_max_error must be > 0"),
            (self.translation_weight >= 0, "translation_weight must be >= 0"),
            (self.colour_weight >= 0, "colour_weight must be >= 0"),
            (self.motion_weight >= 0, "motion_weight must be >= 0"),
            (0 <= self.update_confidence < 1, "update_confidence must be in [0, 1)"),
            (self.n_particles >= 0 and self.particle_offset >= 0, "particles must be >= 0"),
            (self.particle_trigger >= 0 and self.lost_factor > 0, "need particle_trigger >= 0, lost_factor > 0"),
            (0 <= self.min_visible <= 1, "min_visible must be in [0, 1]"),
            (0 < self.forgetting <= 1, "forgetting must be in (0, 1]"),
            (self.reconstruction_lambda > 0, "reconstruction_lambda must be > 0"),
        ]
        for ok, message in checks:
            if not ok:
                raise ValueError(f"invalid tracker config: {message}")
        PatchLayout(self.template_size, self.patch_size, self.patch_step, self.normalization)  # raises if invalid

    @classmethod
    def from_dict(cls, values: dict) -> "TrackerConfig":
        known = {f.name for f in fields(cls)}
        unknown = set(values) - known
        if unknown:
            raise ValueError(f"unknown tracker parameters: {', '.join(sorted(unknown))}")
        return cls(**values)

    def to_dict(self) -> dict:
        return asdict(self)


_COARSE_LEVELS = 1  # pyramid levels above the fine one at which the coarse stage samples
MIN_SIDE_PX = 4.0  # the scale search never shrinks a window's shorter side below this (image pixels)
CONFIDENCE_RATE = 0.1  # learning rate of the running mean that update_confidence compares the response with


@dataclass
class TrackResult:
    box: tuple[float, float, float, float]  # x, y, w, h (0-based, top-left + size)
    emd: float  # of the window the search converged to (with the scale filter: before its resize)
    iterations: int  # descent iterations of the chosen start
    lost: bool
    scale: float = 1.0  # relative scale change chosen this frame
    angle: float = 0.0  # orientation of the tracked window (radians, from the priors); box is its bounding box
    starts: int = 1  # starting points searched (the prediction, the flow, filter and colour starts, the particles)
    codings: int = 0  # candidate models built (windows sampled and sparse-coded) this frame
    solver_warnings: int = 0  # EMD solves that did not end optimal
    predicted_box: tuple[float, float, float, float] | None = None
    reason: str = ""  # why the window counts as lost, or why the models did not learn (held)
    held: bool = False  # tracked, but the models did not learn and the size was kept (TrackerConfig.update_confidence)


@dataclass
class _Descent:
    """Outcome of a search: the window it ended at and what it cost."""

    model: CandidateModel  # the window it ended at
    emd: float
    iterations: int = 0
    codings: int = 0  # candidate models built (_descend: its trial steps; _search adds the starts')
    warnings: int = 0  # EMD solves that did not end optimal (likewise: the trials', the starts' by _search)
    confidence: float | None = None  # the occlusion check at the window (set by _search: _confidence_check)
    held_reason: str = ""

    @property
    def center(self) -> np.ndarray:
        """Window centre, image pixels."""
        return self.model.center


class IemdTracker:
    """iEMD visual tracker (Yao & Dani): sparse-coding histograms + EMD gradient descent.

    Dictionary size L (``n_templates``; the paper gives no value): L = 1, the
    template kept up to date by Algorithm 2, measured (benchmarks/tune_tracker.py,
    all 12 OTB sequences, mean average overlap) 31.9 % against 27.3 % for L = 3,
    CMU desk with gyro 80.0 % against 74.8 %, and it codes 3x fewer atoms
    (median update 11.3 vs 13.9 ms in the same run).  Per-sequence figures swing
    by tens of points with small changes (a tracker that loses the target early
    scores near zero), so only the 12-sequence mean is used for such choices.

    Algorithm 2 (``update_templates``) neither helps nor hurts that mean: 31.9 % with it, 32.0 %
    without.  Runs end by drifting, not by losing the target: Woman, David and Car4 sit on
    background for 457, 268 and 320 frames with an EMD still below the lost threshold.
    """

    def __init__(self, config: TrackerConfig | None = None):
        self.config = config if config is not None else TrackerConfig()
        if not isinstance(self.config, TrackerConfig):
            raise ValueError("config must be a TrackerConfig")
        cfg = self.config
        self.layout = PatchLayout(cfg.template_size, cfg.patch_size, cfg.patch_step, cfg.normalization)
        self._center = None
        self._size = None
        self._previous = None  # grey levels of the last frame, for the flow start
        self._angle = 0.0  # orientation of the tracked window (radians), only ever changed by priors
        self._background_emd = np.inf
        self._frame_index = 0
        self._lost = False
        self._confidence = None

    # ------------------------------------------------------------------ API
    def init(self, frame: np.ndarray, box) -> None:
        """Start tracking the target in ``box`` = (x, y, w, h) of ``frame``."""
        _check_frame(frame)
        x, y, w, h = _check_box(box, frame.shape)
        cfg = self.config
        self._center = box_centre((x, y, w, h))
        self._size = np.array([w, h], dtype=np.float64)
        self._angle = 0.0
        self._previous = None
        _, _, pyramid = self._take_frame(frame)
        template = pyramid.sample(self._center, self._size, cfg.template_size)
        self.dictionary = TemplateDictionary(self.layout, cfg.n_templates, cfg.lam,
                                             cfg.forgetting, cfg.reconstruction_lambda)
        self.dictionary.add(template, 0.0, 0)
        self._target_eps = self.layout.extract(template)  # epsilon_u of I_0 (Algorithm 1)
        self._refresh_target()
        self._background_emd = self._measure_background_emd(pyramid)
        self._coarse_target = None
        if cfg.coarse_to_fine:  # the coarse stage's target: the window one pyramid level smoother, kernel weights only
            coarse_eps = self.layout.extract(pyramid.sample(self._center, self._size, cfg.template_size,
                                                            coarse=_COARSE_LEVELS))
            self._coarse_target = TargetModel.from_patches(self.layout.positions(), coarse_eps,
                                                           np.ones(len(coarse_eps)), cfg.kernel_bandwidth)
        self._scale_filter = None
        if cfg.scale_estimator == "filter" and cfg.scale_step > 0:
            self._scale_filter = ScaleFilter(scale_step=1.0 + cfg.scale_step)
            self._scale_filter.init(pyramid, self._center, self._size)
        self._translation_filter = None
        if cfg.translation_weight > 0:
            self._translation_filter = TranslationFilter()
            self._translation_filter.init(pyramid, self._center, self._size)
        self._colour_model = None
        if cfg.colour_weight > 0 and _is_colour(frame):
            self._colour_model = ColourModel()
            self._colour_model.init(frame, self._center, self._size)
        self._colour_now = False  # the colour model has estimated on this frame (not on a grey frame)
        self._frame_index = 0
        self._lost = False
        self._confidence = None  # running mean of the filter's response at the window over frames that learned

    def update(self, frame: np.ndarray, prior=None) -> TrackResult:
        """Track into ``frame``; ``prior`` maps previous-frame pixels into this frame."""
        if self._center is None:
            raise RuntimeError("IemdTracker.update() called before init()")
        _check_frame(frame)
        cfg = self.config
        center, size, angle = self._center.copy(), self._size.copy(), self._angle
        if prior is not None:  # may raise ValueError: before any state changes, so a retry sees none
            prior = _check_prior(prior)
            center, size, turn = _apply_prior(prior, center, size)
            angle = _wrap_angle(angle + turn)
        self._frame_index += 1
        predicted = _box(center, size, angle)
        previous, grey, pyramid = self._take_frame(frame)

        moves = []  # where the optical flow and the translation filter take the window (closer: the prediction's own)
        if cfg.flow_start:
            moves.append(window_flow(previous, grey, _box(self._center, self._size, self._angle), prior,
                                     cfg.flow_max_error))
        if self._translation_filter is not None:
            moves.append(self._translation_filter.estimate(pyramid, center, size, angle))
        self._colour_now = self._colour_model is not None and frame.ndim == 3
        if self._colour_now:
            moves.append(self._colour_model.estimate(frame, center, size, angle))
        fine_starts = [center + move for move in moves if move is not None and np.linalg.norm(move) >= cfg.min_step_px]
        best = self._search(pyramid, center[None], size, angle, center, fine_starts)
        searches = [best]
        starts, codings = 1 + len(fine_starts), best.codings
        baseline = self._background_emd
        if cfg.n_particles and (self._lost or best.emd > cfg.particle_trigger * baseline):
            # Section 6.1: more starting points around the prediction for abrupt motion.
            distance = cfg.particle_offset * (2.0 if self._lost else 1.0)
            candidate = self._search(pyramid, center + _particle_offsets(cfg.n_particles, distance) * size, size,
                                     angle, center)
            starts, codings = starts + cfg.n_particles, codings + candidate.codings
            searches.append(candidate)
            if candidate.emd < best.emd:
                best = candidate
        confidence, held_reason = best.confidence, best.held_reason
        final, scale = _Descent(model=best.model, emd=best.emd), 1.0  # a held frame keeps the window's size
        if not held_reason:
            bounds = _scale_bounds(best.model.size, frame.shape)
            if self._scale_filter is not None:
                # The scale filter's estimate at the converged centre.  The window is not coded and solved again at
                # the new size: the EMD barely sees scale (scale_filter.py), and the template Algorithm 2 learns is
                # resampled to the template size anyway.  Solving it there changed nothing over 12 OTB sequences x 5
                # starts (38.6 % mean average overlap either way) and cost 0.5-0.8 ms per frame (one candidate
                # model); with the true centre set before each frame (benchmarks/scale_curve.py) the size error is
                # 13.1 % against 12.3 %.
                scale = self._scale_filter.estimate(pyramid, best.center, best.model.size, best.model.angle, bounds)
            else:
                final, scale = self._search_scale(best, bounds)
        emd, new_center, new_size = final.emd, final.center, best.model.size * scale
        best_box = _box(new_center, new_size, angle)
        reason = self._lost_reason(emd, new_center, new_size, angle, frame.shape)
        lost = self._lost = bool(reason)
        held = bool(held_reason) and not lost
        if not lost:
            self._center, self._size, self._angle = new_center, new_size, angle
        if not lost and not held:
            if confidence is not None:
                self._confidence = confidence if self._confidence is None else (
                    (1.0 - CONFIDENCE_RATE) * self._confidence + CONFIDENCE_RATE * confidence)
            if self._scale_filter is not None:
                self._scale_filter.update()
            if self._translation_filter is not None:
                self._translation_filter.update(pyramid, new_center, new_size, angle)
            if self._colour_now:
                self._colour_model.update(frame, new_center, new_size, angle)
            if cfg.update_templates:
                if self.dictionary.observe(final.model.template, emd, self._frame_index):
                    self._refresh_target()
        return TrackResult(
            box=best_box, emd=emd, iterations=best.iterations, lost=lost, scale=scale, angle=angle, starts=starts,
            codings=codings + final.codings, solver_warnings=sum(s.warnings for s in searches) + final.warnings,
            predicted_box=predicted, reason=reason or held_reason, held=held,
        )

    def descend(self, frame: np.ndarray, box) -> TrackResult:
        """Algorithm 1 alone on ``frame`` from the axis-aligned window ``box`` = (x, y, w, h), at that size,
        against the current target model: no other starts, no translation filter, no scale search, and the
        tracker's state (window, models, filters) is left as it is.  For analysis: the descent's capture range
        and the gradients compared (benchmarks/model_ceiling.py, gradient_compare.py)."""
        if self._center is None:
            raise RuntimeError("IemdTracker.descend() called before init()")
        _check_frame(frame)
        x, y, w, h = _check_box(box, frame.shape)
        size = np.array([w, h], dtype=np.float64)
        start = CandidateModel(self.search_context(ImagePyramid(to_gray(frame))), box_centre((x, y, w, h)), size)
        end = self._descend(start)
        return TrackResult(box=_box(end.center, size), emd=end.emd, iterations=end.iterations,
                           lost=bool(self._lost_reason(end.emd, end.center, size, 0.0, frame.shape)),
                           codings=1 + end.codings, solver_warnings=_not_optimal(start.emd()[1]) + end.warnings)

    def search_context(self, pyramid: ImagePyramid, angle: float = 0.0, coarse: bool = False) -> SearchContext:
        """The search context of windows turned by ``angle`` on ``pyramid``'s frame: the current target model
        and dictionary, or (``coarse``) the coarse stage's: one pyramid level up, its own target, no sparse
        coding (``coarse_to_fine`` only).  Also for analysis:
        ``CandidateModel(tracker.search_context(pyramid), centre, size).emd()`` scores any window against the
        target (benchmarks/model_ceiling.py, scale_curve.py)."""
        if self._center is None:
            raise RuntimeError("IemdTracker.search_context() called before init()")
        cfg = self.config
        if coarse:
            if self._coarse_target is None:
                raise RuntimeError("IemdTracker.search_context(coarse=True) needs coarse_to_fine")
            return SearchContext(pyramid, self.layout, self._coarse_target, None, cfg.alpha, cfg.kernel_bandwidth,
                                 coarse=_COARSE_LEVELS, angle=angle)
        return SearchContext(pyramid, self.layout, self._target, self.dictionary, cfg.alpha, cfg.kernel_bandwidth,
                             angle=angle)

    # ------------------------------------------------------------ internals
    def _take_frame(self, frame: np.ndarray):
        """(grey levels kept from the previous frame, ``frame``'s grey levels, its pyramid).  With the flow
        start the grey levels are kept for the next frame, copied (the caller may reuse its buffer);
        without it nothing is kept (None)."""
        keep = self.config.flow_start
        grey = grey_levels(frame, copy=keep)
        previous, self._previous = self._previous, (grey if keep else None)
        return previous, grey, ImagePyramid(to_gray(grey))

    def _confidence_check(self, center) -> tuple[float | None, str]:
        """(the translation filter's response at the window centre ``center``, why the frame is held: "" when
        it learns).  Held: the response is below ``update_confidence`` times its running mean over the frames that
        learned (TrackerConfig.update_confidence).  (None, "") without the filter or the check."""
        threshold = self.config.update_confidence
        if self._translation_filter is None or threshold == 0:
            return None, ""
        confidence = self._translation_filter.response_at(center)
        if self._confidence is None or confidence >= threshold * self._confidence:
            return confidence, ""
        return confidence, (f"models not updated: filter response {confidence:.3f} < {threshold} x its running mean "
                            f"{self._confidence:.3f} (occlusion?)")

    def _lost_reason(self, emd: float, center, size, angle: float, shape) -> str:
        """Why the window (``center``, ``size``, ``angle``) of EMD ``emd`` counts as lost; "" when it does not."""
        cfg = self.config
        visible = _visible_fraction(center, size, angle, shape)
        if visible < cfg.min_visible:
            return f"only {visible:.0%} of the window is inside the image"
        if not np.isfinite(emd) or emd > cfg.lost_factor * self._background_emd:
            return f"EMD {emd:.4f} > {cfg.lost_factor} x background EMD {self._background_emd:.4f}"
        return ""

    def _measure_background_emd(self, pyramid: ImagePyramid) -> float:
        """Median EMD between the target and the four windows one window size away in I_0.

        The reference for "this no longer looks like the target": the particles
        and the lost state compare the current EMD with it.  (A reference taken
        from the EMDs of recent tracked frames collapsed when the first frames
        were easy, after which every frame counted as lost and, lost frames not
        updating it, it never recovered: 804 of 825 CMU desk frames.)
        """
        context = self.search_context(pyramid)
        values = [CandidateModel(context, self._center + offset * self._size, self._size).emd()[0]
                  for offset in _particle_offsets(4, 1.0)]
        finite = [v for v in values if np.isfinite(v)]
        return float(np.median(finite)) if finite else np.inf

    def _refresh_target(self) -> None:
        """Target model of eq. (sparse target model) against the current dictionary.

        As in Algorithm 1 the appearance vectors are those of I_0; when Algorithm 2
        changes the dictionary they are only recoded.  Letting them follow the
        latest template instead was measured to drift (Car4/Bolt2/Woman mean
        average overlap 15.0 % vs 26.1 %, with the defaults of the time); blending the latest template into them
        at a rate of 0.01, 0.03 or 0.1 per frame gave 27.6, 28.0 and 22.9 % against
        31.9 % over the 12 OTB sequences.
        """
        pooled = self.dictionary.code_weights(self._target_eps)
        self._target = TargetModel.from_patches(self.layout.positions(), self._target_eps, pooled,
                                                self.config.kernel_bandwidth)

    def _search(self, pyramid: ImagePyramid, starts: np.ndarray, size, angle: float, prediction,
                fine_starts=()) -> _Descent:
        """Coarse-to-fine Algorithm 1 from one or more starts (N, 2).

        ``fine_starts`` skip the coarse stage: the flow start, which pyramidal Lucas-Kanade already
        placed coarse to fine, the translation filter's and the colour model's.  The start of lowest EMD is
        refined, and with the translation filter or the colour model also the start of lowest :meth:`_score` (or
        every start: ``descend_all_starts``); the refined window of lowest score is kept, among those the occlusion
        check would not hold when there are any (:meth:`_confidence_check`).  ``prediction`` is the
        predicted centre, from which the score's motion prior measures a window's displacement.

        The appearance EMD is minimal at the target, but its basin is only about
        as wide as the patches' texture is coarse (a few pixels for fine texture).
        With ``coarse_to_fine`` each start first descends on templates sampled one
        pyramid level smoother, with kernel-only weights (no sparse coding, so it
        is cheap); the full model scores where each ends, and only the best one
        gets the fine descent.  Measured (benchmarks/tune_tracker.py,
        Car4/Bolt2/Woman average overlap, with the defaults of the time): on
        36.2 %, off 34.9 % (it helps the panning Bolt2 and Woman, hurts the large
        Car4); since the translation filter it is off by default (TrackerConfig.coarse_to_fine).
        With section 6.1's extra starting points, running the whole
        coarse-to-fine search from every start gave p95 update times of
        80-100 ms (5x a normal frame).

        Capture range of the fine descent alone (benchmarks/model_ceiling.py --capture, exact model, 12 OTB
        sequences): starts 0.05 / 0.1 / 0.2 / 0.4 window sizes off end on the
        target in 100 / 20 / 4 / 3 % of cases (with the coarse stage, in an earlier
        version: 99 / 35 / 20 / 15 %); the appearance gradient points
        the right way only within about the texture's correlation length.  A
        derivative-free compass search (4 axis directions, first step 0.2 window
        sizes) was measured at 89-95 % from every distance, but tracking did not
        gain (12-sequence average overlap 31.3 vs 31.9 %: a wider basin also
        reaches distractors) and updates took 3x longer, so it was not kept.
        """
        fine = self.search_context(pyramid, angle)
        coarse = self.search_context(pyramid, angle, coarse=True) if self.config.coarse_to_fine else None
        ends, warnings = [], 0
        for start in starts:
            if coarse is not None:
                first = CandidateModel(coarse, start, size)
                stage = self._descend(first)
                start, warnings = stage.center, warnings + stage.warnings + _not_optimal(first.emd()[1])
            ends.append(start)
        models = [CandidateModel(fine, s, size) for s in (*ends, *fine_starts)]
        warnings += sum(_not_optimal(model.emd()[1]) for model in models)  # each model caches its EMD
        chosen = [min(models, key=lambda model: model.emd()[0])]
        if self._discriminative:
            if self.config.descend_all_starts:
                chosen = models
            else:
                checked = min(models, key=lambda model: self._score(model.emd()[0], model.center, prediction, size))
                chosen += [checked] if checked is not chosen[0] else []
        descents = [self._descend(model) for model in chosen]
        for state in descents:
            state.confidence, state.held_reason = self._confidence_check(state.center)
        confident = [state for state in descents if not state.held_reason]
        best = min(confident or descents, key=lambda state: self._score(state.emd, state.center, prediction, size))
        best.codings = len(models) + sum(state.codings for state in descents)
        best.warnings = warnings + sum(state.warnings for state in descents)
        return best

    @property
    def _discriminative(self) -> bool:
        """Whether this frame's score has terms besides the EMD: the translation filter's, the colour model's."""
        return self._translation_filter is not None or self._colour_now

    def _score(self, emd: float, center, prediction, size) -> float:
        """What the search minimizes: the EMD, and with the translation filter or the colour model the EMD relative
        to the background EMD less ``translation_weight`` times the filter's response and ``colour_weight`` times
        the colour model's mean at the window centre ``center``, plus ``motion_weight`` times the squared
        displacement from ``prediction`` over the window's area (``size`` (w, h))."""
        if not self._discriminative:
            return emd
        background = self._background_emd if np.isfinite(self._background_emd) else 1.0
        score = emd / background
        if self._translation_filter is not None:
            score -= self.config.translation_weight * self._translation_filter.response_at(center)
        if self._colour_now:
            score -= self.config.colour_weight * self._colour_model.score_at(center)
        displacement = np.asarray(center, dtype=np.float64) - prediction
        return score + self.config.motion_weight * float(displacement @ displacement) / float(size[0] * size[1])

    def _descend(self, model: CandidateModel) -> _Descent:
        """Algorithm 1 from the window of ``model``: move against dEMD/dy while the EMD decreases.

        The paper moves one pixel along the gradient and stops at the first EMD
        increase.  We start with ``step_px`` and halve the step on an increase,
        stopping below ``min_step_px``: the same stopping rule (the EMD no longer
        decreases, at the finest step), but it reaches sub-pixel positions and
        covers larger motions in fewer EMD solves.
        """
        cfg = self.config
        half = model.size / 2.0
        axes = window_axes(model.angle)
        emd, grad, _ = model.evaluate(cfg.gradient)  # cached for _search's winners; a coarse start's is solved here
        state = _Descent(model=model, emd=emd)  # its solve is counted by the caller, with its coding
        # A coarse stage samples ``coarse`` pyramid levels up: its steps are that much longer.
        level_scale = 2.0 ** model.coarse
        step, min_step = cfg.step_px * level_scale, cfg.min_step_px * level_scale
        while state.iterations < cfg.n_iter and step >= min_step:
            g_px = axes @ (grad / half)  # gradient with respect to image pixels
            norm = np.linalg.norm(g_px)
            if not np.isfinite(norm) or norm == 0:
                break
            state.iterations += 1
            trial = state.model.at(state.center - step * g_px / norm)
            e_try, s_try = trial.emd()
            state.codings += 1
            state.warnings += _not_optimal(s_try)
            if e_try < state.emd:  # the gradient is needed only where the step is accepted
                state.model, state.emd, grad = trial, e_try, trial.gradient(cfg.gradient)
            else:
                step *= 0.5
        return state

    def _search_scale(self, state: _Descent, bounds: tuple[float, float]) -> tuple[_Descent, float]:
        """Scale variants at the converged centre (paper: window enlarged/shrunk by 2%).

        Each variant is a candidate model of the window resampled at s * size, so it
        has exactly the target's patch layout and its EMD is comparable with the
        EMD at scale 1.  (Scaling the kernel over fixed patches instead lets more
        bins in at larger scales and biased the EMD toward growing windows:
        measured as runaway growth on Car4.)  In each direction the search keeps
        stepping by ``scale_step`` while the EMD decreases, up to ``scale_range``
        (the paper's gyro experiment searches +-10 %: a camera closing in on the
        target grows it faster than 2 % per frame).  Taking a variant only when it lowers the EMD by
        more than 1 % (against size drift from noise) was measured at 31.0 % against 31.9 %, 12 OTB
        sequences.  No variant leaves ``bounds`` (:func:`_scale_bounds`).  Returns the chosen window (its
        ``codings`` and ``warnings`` those of the variants) and its relative scale.
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


def compile_jit() -> None:
    """JIT-compile the tracker's numba kernels now (or load them from numba's on-disk cache).

    The first call in a fresh environment compiles for seconds;
    :class:`iemd_ros.pipeline.pipeline.TrackingPipeline` (node and replay) calls this, with
    :func:`iemd_ros.gyro.predictor.compile_gyro_jit`, once per process at start-up so the first frames are not
    dropped for it.
    """
    frame = (np.random.default_rng(0).random((64, 64)) * 255).astype(np.uint8)
    tracker = IemdTracker()
    tracker.init(frame, (16, 16, 32, 32))
    tracker.update(frame)


# ---------------------------------------------------------------- helpers
def _box(center, size, angle: float = 0.0):
    """Axis-aligned box (x, y, w, h) around the window, rotated by ``angle`` about its centre."""
    c, s = abs(np.cos(angle)), abs(np.sin(angle))
    w, h = c * size[0] + s * size[1], s * size[0] + c * size[1]
    return tuple(float(v) for v in centre_box(center, (w, h)))


def _scale_bounds(size, shape) -> tuple[float, float]:
    """(lowest, highest) relative scale of the window of ``size`` (w, h): its shorter side stays at least
    MIN_SIDE_PX and its area at most the image's (``shape``), DSST's bounds on the scale factor, by area so that
    they hold for a turned window too.  A window already outside them may not move further out.  Without the upper
    bound a window started 20 % too large on Car4 grew to more than the image's area by frame 195 (the scale filter
    learns the background in it as target), and 11x the target's by mid-sequence."""
    lower = MIN_SIDE_PX / float(min(size))
    upper = float(np.sqrt(shape[0] * shape[1] / (size[0] * size[1])))
    return min(lower, 1.0), max(upper, 1.0)


def _not_optimal(solution) -> int:
    """1 if an EMD solve ended without an optimal flow (counted in TrackResult.solver_warnings), else 0."""
    return int(solution is not None and not solution.optimal)


def _wrap_angle(angle: float) -> float:
    return float((angle + np.pi) % (2.0 * np.pi) - np.pi)


def _particle_offsets(n: int, distance: float) -> np.ndarray:
    """n starting offsets (in window sizes) evenly around the prediction."""
    angles = 2.0 * np.pi * np.arange(n) / max(n, 1)
    return distance * np.column_stack([np.cos(angles), np.sin(angles)])


def _visible_fraction(center, size, angle: float, shape) -> float:
    """Share of the window's area inside the image, the window turned by ``angle`` about its centre.

    In pixel-edge coordinates the image spans [0, W] x [0, H] and the window is
    centred at ``center + 0.5`` (pixel centres at integers, as ``centre_box``).
    """
    h_img, w_img = shape[:2]
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) * (np.asarray(size) / 2.0)
    window = corners @ window_axes(angle).T + np.asarray(center) + 0.5
    image = np.array([[0.0, 0.0], [w_img, 0.0], [w_img, h_img], [0.0, h_img]], dtype=np.float32)
    area = cv2.intersectConvexConvex(window.astype(np.float32), image)[0]
    return max(float(area), 0.0) / float(size[0] * size[1])


def _apply_prior(H: np.ndarray, center, size):
    """Move the window by the homography: centre mapped, size scaled by sqrt|det J| of H there,
    and the turn (radians) of J's rotation part, which the window's orientation follows.

    The turn is what keeps a camera roll from misaligning the window with the
    target (the CMU desk sequence rolls the eagle's head by up to 180 degrees).
    """
    p = H @ np.array([center[0], center[1], 1.0])
    new_center = p[:2] / p[2]
    # Jacobian of the projective map at the centre.
    J = (H[:2, :2] - np.outer(new_center, H[2, :2])) / p[2]
    scale = float(np.sqrt(abs(np.linalg.det(J))))
    if not np.all(np.isfinite(new_center)) or not np.isfinite(scale) or scale <= 0:
        raise ValueError("prior homography maps the target centre to infinity")
    turn = float(np.arctan2(J[1, 0] - J[0, 1], J[0, 0] + J[1, 1]))
    return new_center, size * scale, turn


def _is_colour(frame: np.ndarray) -> bool:
    """Whether ``frame`` has colour: three channels that are not all equal (grey sequences are often stored as
    BGR images with three equal channels)."""
    return frame.ndim == 3 and not (np.array_equal(frame[..., 0], frame[..., 1])
                                    and np.array_equal(frame[..., 1], frame[..., 2]))


def _check_frame(frame) -> None:
    if not isinstance(frame, np.ndarray):
        raise ValueError(f"frame must be a numpy array, got {type(frame).__name__}")
    if frame.dtype != np.uint8:
        raise ValueError(f"frame must be uint8, got {frame.dtype}")
    if frame.ndim not in (2, 3) or (frame.ndim == 3 and frame.shape[2] != 3):
        raise ValueError(f"frame must be HxW or HxWx3 (BGR), got shape {frame.shape}")
    if frame.shape[0] < 2 or frame.shape[1] < 2:
        raise ValueError(f"frame is empty (shape {frame.shape})")


def _check_box(box, shape):
    x, y, w, h = check_box(box)
    if x + w <= 0 or y + h <= 0 or x >= shape[1] or y >= shape[0]:
        raise ValueError(f"box {box!r} lies outside the {shape[1]}x{shape[0]} image")
    return x, y, w, h


def _check_prior(prior) -> np.ndarray:
    H = np.asarray(prior, dtype=np.float64)
    if H.shape != (3, 3):
        raise ValueError(f"prior must be a 3x3 homography, got shape {H.shape}")
    if not np.all(np.isfinite(H)):
        raise ValueError("prior homography has non-finite values")
    if abs(np.linalg.det(H)) < 1e-12:
        raise ValueError("prior homography is singular")
    return H
