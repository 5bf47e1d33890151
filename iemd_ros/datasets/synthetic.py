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
Synthetic rotating-camera sequences with a simulated gyro and exact ground truth.

The scene is at infinity (pure rotation, as the paper's gyro model assumes): a cube map of six
procedural textures, so any orientation (a 300 deg/s pan over several turns included) renders
exactly.  Each frame is rendered with the exact pure-rotation homography ``K R_k^T R_face
K_face^-1`` (``cv2.warpPerspective``) of each visible cube face; a distinct textured square target
moves on the scene sphere (or stays put with ``target_speed_deg_s=0``) and is warped the same way.
An optional plumb_bob lens is applied by ``cv2.remap`` of a larger pinhole rendering.

The camera's body rate ``w_cam(t)`` is analytic (shake: sum of sinusoids per axis; pan: constant
rate), the orientation at the frames is its exact integral (4th-order Magnus on 0.25 ms steps), and
the gyro reports ``w_imu = R_cam_imu^T w_cam + bias + noise`` at its own rate with stamp jitter.
Clocks: true time is the IMU clock; frame stamps are ``t_true - time_offset`` so that ``t_imu =
t_cam + time_offset`` (Kalibr's convention).  Everything is deterministic from ``seed``.

Ground truth, per frame: ``gt_boxes`` (x, y, w, h), the axis-aligned box of the target's projected
outline (through the lens) in the tracker's convention (the box covers pixels x .. x+w-1, region
``[x-0.5, x+w-0.5]``); ``gt_centres``, the image of the target's centre in pixel-index coordinates
(as K; compare with :func:`iemd_ros.common.boxes.box_centre`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import cv2
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.gyro.rotation import integrate_rates, quat_mul, quat_to_rot, so3_exp
import numpy as np

__all__ = ['SyntheticConfig', 'SyntheticSequence', 'generate', 'angular_velocity']

_T_BASE_NS = 10_000_000_000   # stamps start near 10 s (non-zero, like a real clock)
_FACES = [np.eye(3)] + [so3_exp(np.array(v) * np.pi / 2) for v in
                        ([0, 1, 0], [0, 2, 0], [0, -1, 0], [1, 0, 0], [-1, 0, 0])]


@dataclass
class SyntheticConfig:
    """
    Parameters of :func:`generate` (angles in degrees, rates in deg/s unless noted).

    Parameters
    ----------
    width, height : int
        Image size, px.
    hfov_deg : float
        Horizontal field of view.
    dist : tuple of float
        The plumb_bob lens [k1 k2 p1 p2 k3].
    fps : float
        Frame rate, Hz.
    n_frames : int
        Number of frames.
    motion : {"shake", "pan", "still", "turn_away"}
        The camera's motion; ``turn_away``: still, then it turns ``turn_deg`` about ``pan_axis`` in
        ``turn_s`` from ``turn_start_s`` (a raised-cosine rate), holds ``turn_hold_s`` and turns
        back the same way.
    max_rate_deg_s : float
        Peak |w| (shake) or the constant rate (pan).
    shake_freqs_hz : tuple of float
        Per-axis sinusoid frequencies (randomised +-20 %).
    shake_axis_weights : tuple of float
        Weights of x (tilt), y (pan), z (roll).
    pan_axis : tuple of float
        Axis of the pan (and of the turn away), camera frame.
    turn_deg, turn_start_s, turn_s, turn_hold_s : float
        The turn away: its angle, start, duration of each turn, and the hold between them.
    target_size_px : float
        Side of the square target near the image centre.
    target_speed_deg_s : float
        Peak speed of the target on the scene sphere (0: it stays put).
    target_offset_deg : tuple of float
        Initial target direction (azimuth, elevation).
    gyro_rate_hz : float
        Gyro sample rate.
    gyro_noise_std : float
        White gyro noise, rad/s per sample.
    gyro_bias : tuple of float
        Gyro bias, rad/s, IMU frame.
    gyro_jitter_s : float
        Standard deviation of the gyro stamp jitter, s.
    time_offset_s : float
        ``t_imu = t_cam + time_offset``, s.
    still_start_s : float
        The camera is still this long (s) before the motion ramps in.
    R_cam_imu : ndarray
        3x3 IMU -> camera rotation.
    seed : int
        Everything is deterministic from it.
    render : bool
        False: ground truth and gyro only (``frames`` is None).

    """

    width: int = 320
    height: int = 240
    hfov_deg: float = 60.0
    dist: tuple = (0.0, 0.0, 0.0, 0.0, 0.0)       # plumb_bob [k1 k2 p1 p2 k3]
    fps: float = 30.0
    n_frames: int = 120
    motion: str = 'shake'                          # "shake" | "pan" | "still"
    max_rate_deg_s: float = 200.0                  # peak |w| (shake) or the constant rate (pan)
    # per-axis sinusoid frequencies (randomised +-20 %)
    shake_freqs_hz: tuple = (1.1, 1.9, 3.1)
    shake_axis_weights: tuple = (1.0, 1.0, 0.4)    # x (tilt), y (pan), z (roll)
    pan_axis: tuple = (0.0, 1.0, 0.0)
    turn_deg: float = 60.0
    turn_start_s: float = 1.0
    turn_s: float = 0.5
    turn_hold_s: float = 1.0
    # side of the square target near the image centre
    target_size_px: float = 48.0
    target_speed_deg_s: float = 0.0                # peak speed of the target on the scene sphere
    target_offset_deg: tuple = (0.0, 0.0)          # initial target direction (azimuth, elevation)
    gyro_rate_hz: float = 200.0
    gyro_noise_std: float = 0.0                    # rad/s per sample (white)
    gyro_bias: tuple = (0.0, 0.0, 0.0)             # rad/s, IMU frame
    gyro_jitter_s: float = 0.0                     # std of the gyro stamp jitter
    time_offset_s: float = 0.0                     # t_imu = t_cam + time_offset
    # camera still this long before the motion ramps in
    still_start_s: float = 0.0
    R_cam_imu: np.ndarray = field(default_factory=lambda: np.eye(3))
    seed: int = 0
    # False: ground truth and gyro only (frames is None)
    render: bool = True

    def validate(self) -> None:
        """
        Check the parameters.

        Raises
        ------
        ValueError
            For width or height below 16, fewer than 2 frames, fps <= 0, an unknown motion,
            hfov_deg outside [10, 120], gyro_rate_hz <= 0, negative noise, jitter or still_start_s,
            or target_size_px <= 2.

        """
        if self.width < 16 or self.height < 16 or self.n_frames < 2 or self.fps <= 0:
            raise ValueError(
                f'need width, height >= 16, n_frames >= 2 and fps > 0, got '
                f'{self.width}x{self.height}, {self.n_frames} frames at {self.fps} fps'
            )
        if self.motion not in ('shake', 'pan', 'still', 'turn_away'):
            raise ValueError(
                f"motion must be 'shake', 'pan', 'still' or 'turn_away', got {self.motion!r}"
            )
        if self.motion == 'turn_away' and not (
            self.turn_s > 0 and self.turn_hold_s >= 0 and self.turn_start_s >= 0
        ):
            raise ValueError('turn_away needs turn_s > 0, turn_hold_s >= 0 and turn_start_s >= 0')
        if not 10 <= self.hfov_deg <= 120:
            raise ValueError(f'hfov_deg must be in [10, 120], got {self.hfov_deg}')
        if (
            self.gyro_rate_hz <= 0
            or self.gyro_noise_std < 0
            or self.gyro_jitter_s < 0
            or self.still_start_s < 0
        ):
            raise ValueError(
                'gyro_rate_hz must be > 0; noise, jitter and still_start_s must be >= 0'
            )
        if not self.target_size_px > 2:
            raise ValueError(f'target_size_px must be > 2, got {self.target_size_px}')


@dataclass
class SyntheticSequence:
    """
    Output of :func:`generate`; stamps in ns, gyro in the IMU frame (rad/s).

    Parameters
    ----------
    frames : ndarray or None
        (N, H, W, 3) BGR uint8 (None when config.render is False).
    frame_stamps_ns : ndarray
        (N,) int64, camera clock.
    gyro_t_ns : ndarray
        (M,) int64, IMU clock.
    gyro : ndarray
        (M, 3) rad/s, IMU frame.
    K : ndarray
        3x3 camera matrix.
    dist : ndarray
        The (5,) plumb_bob coefficients.
    R_cam_imu : ndarray
        3x3 IMU -> camera rotation.
    time_offset_ns : int
        ``t_imu = t_cam + time_offset_ns``.
    gyro_bias : ndarray
        (3,) rad/s, IMU frame.
    orientations : ndarray
        (N, 3, 3) camera k in the world (camera 0) frame.
    gt_boxes : ndarray
        (N, 4) x, y, w, h (tracker box convention).
    gt_centres : ndarray
        (N, 2) image of the target centre (pixel-index coordinates).
    visible : ndarray
        (N,) target outline fully inside the image and in front.
    config : SyntheticConfig
        The parameters it was generated with.

    """

    frames: np.ndarray | None  # (N, H, W, 3) BGR uint8 (None when config.render is False)
    frame_stamps_ns: np.ndarray  # (N,) int64, camera clock
    gyro_t_ns: np.ndarray  # (M,) int64, IMU clock
    gyro: np.ndarray  # (M, 3) rad/s, IMU frame
    K: np.ndarray
    dist: np.ndarray
    R_cam_imu: np.ndarray
    time_offset_ns: int
    gyro_bias: np.ndarray
    orientations: np.ndarray  # (N, 3, 3) camera k in the world (camera 0) frame
    gt_boxes: np.ndarray  # (N, 4) x, y, w, h (tracker box convention)
    gt_centres: np.ndarray  # (N, 2) image of the target centre (pixel-index coordinates)
    visible: np.ndarray  # (N,) target outline fully inside the image and in front
    config: SyntheticConfig

    @cached_property
    def camera(self) -> CameraModel:
        """Return the camera model of the sequence (K, lens and image size)."""
        return CameraModel(self.K, self.dist, self.config.width, self.config.height, 'synthetic')

    def relative_rotation(self, k: int) -> np.ndarray:
        """
        Return True rotation of camera k in camera k-1.

        Parameters
        ----------
        k : int
            Frame index, >= 1.

        Returns
        -------
        ndarray
            3x3 rotation.

        """
        return self.orientations[k - 1].T @ self.orientations[k]


def _rate_function(cfg: SyntheticConfig):
    """
    Return the true camera-frame body rate ``t -> w_cam(t)`` (rad/s) of ``cfg``.

    (frame 0 at t = 0).
    """
    rng = np.random.default_rng([cfg.seed, 1])
    if cfg.motion == 'still':
        base = lambda t: np.zeros(t.shape + (3,))  # noqa: E731
    elif cfg.motion == 'turn_away':
        base = _turn_away_rate(cfg)
    elif cfg.motion == 'pan':
        axis = np.asarray(cfg.pan_axis, float)
        w0 = axis / np.linalg.norm(axis) * np.radians(cfg.max_rate_deg_s)
        base = lambda t: np.broadcast_to(w0, t.shape + (3,)).copy()  # noqa: E731
    else:
        freqs = np.asarray(cfg.shake_freqs_hz, float)
        f = freqs[None, :] * rng.uniform(0.8, 1.2, (3, len(freqs)))  # (axis, component)
        ph = rng.uniform(0, 2 * np.pi, (3, len(freqs)))
        amp = (
            rng.uniform(0.5, 1.0, (3, len(freqs)))
            * np.asarray(cfg.shake_axis_weights, float)[:, None]
        )

        def raw(t):
            return (amp * np.sin(2 * np.pi * f * t[..., None, None] + ph)).sum(-1)

        # scale so that the peak |w| over the frames is max_rate_deg_s
        scale = (
            np.radians(cfg.max_rate_deg_s)
            / np.linalg.norm(raw(np.linspace(0, cfg.n_frames / cfg.fps, 4000)), axis=1).max()
        )
        base = lambda t: raw(t) * scale  # noqa: E731
    if cfg.still_start_s <= 0:
        return base

    def ramped(t):
        s = np.clip((t + 0.2) / 0.2, 0.0, 1.0)
        return base(t) * (s * s * (3 - 2 * s))[..., None]

    return ramped


def _turn_away_rate(cfg: SyntheticConfig):
    """
    Return the turn away and back.

    A raised-cosine rate bump about ``pan_axis`` whose integral is ``turn_deg``, then the hold,
    then the same bump reversed.
    """
    axis = np.asarray(cfg.pan_axis, float)
    axis = axis / np.linalg.norm(axis)
    # (1 - cos) averages 1: the bump's integral is turn_deg
    peak = 2 * np.radians(cfg.turn_deg) / cfg.turn_s
    back = cfg.turn_start_s + cfg.turn_s + cfg.turn_hold_s

    def bump(t, start):
        u = (t - start) / cfg.turn_s
        return np.where((u >= 0) & (u <= 1), 0.5 * peak * (1 - np.cos(2 * np.pi * u)), 0.0)

    return lambda t: (bump(t, cfg.turn_start_s) - bump(t, back))[..., None] * axis


def angular_velocity(cfg: SyntheticConfig, t_s) -> np.ndarray:
    """
    Return True camera-frame body rate at true times ``t_s`` (frame 0 at t = 0).

    Parameters
    ----------
    cfg : SyntheticConfig
        The sequence's parameters.
    t_s : array_like
        True times, s.

    Returns
    -------
    ndarray
        (..., 3) rates, rad/s.

    """
    return _rate_function(cfg)(np.asarray(t_s, dtype=float))


def _orientations(rate, t_frames: np.ndarray) -> np.ndarray:
    """
    Exact camera orientations at the frame times.

    (camera 0 = world) for the body rate ``rate``.
    """
    q = np.array([1.0, 0, 0, 0])
    out = [np.eye(3)]
    for a, b in zip(t_frames[:-1], t_frames[1:]):
        n = max(2, int(np.ceil((b - a) / 2.5e-4)) + 1)
        tk = np.linspace(a, b, n)
        q = quat_mul(q, integrate_rates(tk, rate(tk)))
        out.append(quat_to_rot(q))
    return np.array(out)


def _texture(rng, size: int) -> np.ndarray:
    """Multi-octave colour noise plus random shapes (BGR uint8, size x size)."""
    acc = np.zeros((size, size, 3), np.float32)
    n = 4
    while n <= size // 2:
        acc += (
            cv2.resize(
                rng.random((n, n, 3), dtype=np.float32),
                (size, size),
                interpolation=cv2.INTER_CUBIC,
            )
            * n**-0.35
        )
        n *= 2
    acc = (acc - acc.min()) / (np.ptp(acc) + 1e-9)
    img = (acc * 200 + 20).astype(np.uint8)
    for _ in range(size // 10):
        c = tuple(int(v) for v in rng.integers(0, 256, 3))
        p = rng.integers(0, size, 2)
        r = int(rng.integers(size // 100 + 2, size // 16 + 4))
        if rng.random() < 0.5:
            cv2.circle(img, (int(p[0]), int(p[1])), r, c, -1, cv2.LINE_AA)
        else:
            cv2.rectangle(
                img,
                (int(p[0]) - r, int(p[1]) - r // 2),
                (int(p[0]) + r, int(p[1]) + r // 2),
                c,
                -1,
            )
    return img


def _target_texture(rng, size: int) -> np.ndarray:
    """
    Return a distinct high-contrast pattern.

    Saturated checker with a dark cross and a bright disc.
    """
    yy, xx = np.mgrid[0:size, 0:size]
    cells = max(2, size // 8)
    chk = ((xx // cells + yy // cells) % 2).astype(bool)
    c1 = np.array([30, 200, 255], np.uint8)[rng.permutation(3)]
    c2 = np.array([200, 40, 40], np.uint8)[rng.permutation(3)]
    img = np.where(chk[..., None], c1, c2).astype(np.uint8)
    m = size // 2
    cv2.line(img, (2, 2), (size - 3, size - 3), (10, 10, 10), max(1, size // 16))
    cv2.circle(img, (m + size // 5, m - size // 5), max(2, size // 8), (250, 250, 250), -1)
    return img


def _translate(dx: float, dy: float) -> np.ndarray:
    return np.array([[1.0, 0, dx], [0, 1.0, dy], [0, 0, 1.0]])


def _rot_towards(az: float, el: float) -> np.ndarray:
    """
    Rotation taking +z to the direction of azimuth ``az`` (about y) and elevation ``el``.

    (about -x).
    """
    return so3_exp(np.array([0.0, az, 0.0])) @ so3_exp(np.array([-el, 0.0, 0.0]))


class _Renderer:
    """
    Pinhole canvas (covering the undistorted extent of the raw image).

    cube-map scene and target.
    """

    def __init__(
        self, cfg: SyntheticConfig, cam: CameraModel, target_tex: np.ndarray, Kt_inv: np.ndarray
    ):
        W, H = cfg.width, cfg.height
        K = cam.K
        self.cfg = cfg
        if cam.has_distortion:
            n = 200
            border = np.concatenate(
                [np.stack([np.linspace(0, W - 1, n), np.full(n, y)], 1) for y in (0, H - 1)]
                + [np.stack([np.full(n, x), np.linspace(0, H - 1, n)], 1) for x in (0, W - 1)]
            )
            und = cam.undistort_points(border)
            if not np.all(np.isfinite(und)):
                raise ValueError(f'lens {list(cfg.dist)} is not invertible over the {W}x{H} image')
            lo = np.minimum(np.floor(und.min(0)) - 2, 0)
            hi = np.maximum(np.ceil(und.max(0)) + 2, [W - 1, H - 1])
            uu, vv = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
            src = cam.undistort_points(np.stack([uu, vv], -1)) - lo
            self.remap = (src[..., 0].astype(np.float32), src[..., 1].astype(np.float32))
        else:
            lo, hi = np.zeros(2), np.array([W - 1.0, H - 1.0])
            self.remap = None
        self.cw, self.ch = int(hi[0] - lo[0]) + 1, int(hi[1] - lo[1]) + 1
        self.Kc = K.copy()
        self.Kc[:2, 2] -= lo
        uu, vv = np.meshgrid(
            np.arange(self.cw, dtype=np.float32), np.arange(self.ch, dtype=np.float32)
        )
        self.rays = np.stack([uu, vv, np.ones_like(uu)], -1) @ np.linalg.inv(self.Kc).T.astype(
            np.float32
        )
        self.face = int(2 * np.ceil(K[0, 0]))
        s = self.face
        self.Kf_inv = np.linalg.inv(
            np.array([[s / 2, 0, (s - 1) / 2], [0, s / 2, (s - 1) / 2], [0, 0, 1.0]])
        )
        self.face_axes = np.stack([Rf[:, 2] for Rf in _FACES], 1)
        # cube faces, generated when first seen (own seed each)
        self.tex: dict[int, np.ndarray] = {}
        self.ttex, self.Kt_inv = target_tex, Kt_inv
        self.tmask = np.full(target_tex.shape[:2], 255, np.uint8)

    def render(self, R: np.ndarray, Rt: np.ndarray | None) -> np.ndarray:
        """
        Frame for camera orientation ``R`` (world) with the target frame ``Rt``.

        (in the camera) or None.
        """
        cw, ch = self.cw, self.ch
        best = np.argmax(self.rays @ (R.T @ self.face_axes).astype(np.float32), axis=-1).astype(
            np.uint8
        )
        canvas = np.zeros((ch, cw, 3), np.uint8)
        for i in np.nonzero(np.bincount(best.ravel(), minlength=6))[0]:
            if i not in self.tex:
                self.tex[i] = _texture(
                    np.random.default_rng([self.cfg.seed, 10 + int(i)]), self.face
                )
            m = (best == i).view(np.uint8)
            x0, y0, rw, rh = cv2.boundingRect(m)
            Hf = _translate(-x0, -y0) @ self.Kc @ R.T @ _FACES[i] @ self.Kf_inv
            roi = cv2.warpPerspective(
                self.tex[i], Hf, (rw, rh), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
            )
            cv2.copyTo(roi, m[y0: y0 + rh, x0: x0 + rw], canvas[y0: y0 + rh, x0: x0 + rw])
        if Rt is not None:
            # target texture -> canvas
            Ht = self.Kc @ Rt @ self.Kt_inv
            P = self.ttex.shape[0]
            corners = (
                np.array(
                    [
                        [-0.5, -0.5, 1],
                        [P - 0.5, -0.5, 1],
                        [P - 0.5, P - 0.5, 1],
                        [-0.5, P - 0.5, 1],
                    ]
                )
                @ Ht.T
            )
            cpix = corners[:, :2] / corners[:, 2:]
            x0, y0 = np.maximum(np.floor(cpix.min(0)).astype(int) - 2, 0)
            x1, y1 = np.minimum(np.ceil(cpix.max(0)).astype(int) + 3, [cw, ch])
            if x1 > x0 and y1 > y0:
                Htp = _translate(-x0, -y0) @ Ht
                size = (int(x1 - x0), int(y1 - y0))
                wt = cv2.warpPerspective(
                    self.ttex, Htp, size, flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT
                )
                mt = (
                    cv2.warpPerspective(
                        self.tmask,
                        Htp,
                        size,
                        flags=cv2.INTER_LINEAR,
                        borderMode=cv2.BORDER_CONSTANT,
                    ).astype(np.float32)[..., None]
                    / 255
                )
                sub = canvas[y0:y1, x0:x1]
                sub[:] = (sub * (1 - mt) + wt * mt + 0.5).astype(np.uint8)
        if self.remap is None:
            return canvas
        return cv2.remap(canvas, *self.remap, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


def generate(config: SyntheticConfig | None = None, **overrides) -> SyntheticSequence:
    """
    Render a synthetic sequence.

    Parameters
    ----------
    config : SyntheticConfig, optional
        Default ``SyntheticConfig()``.
    **overrides
        Keyword overrides replace fields of ``config``.

    Returns
    -------
    SyntheticSequence
        Frames, gyro and ground truth.

    Raises
    ------
    ValueError
        For invalid parameters (:meth:`SyntheticConfig.validate`) or a lens that is not invertible
        over the image.

    """
    cfg = SyntheticConfig() if config is None else config
    if overrides:
        cfg = SyntheticConfig(**{**cfg.__dict__, **overrides})
    cfg.validate()
    W, H, N = cfg.width, cfg.height, cfg.n_frames
    f = (W / 2) / np.tan(np.radians(cfg.hfov_deg) / 2)
    K = np.array([[f, 0, (W - 1) / 2], [0, f, (H - 1) / 2], [0, 0, 1.0]])
    cam = CameraModel(K, cfg.dist, W, H, 'synthetic')

    # target: a P x P texture on a plane at infinity, angular side target_size_px / f
    P = 64
    ft = P / (2 * np.tan(cfg.target_size_px / f / 2))
    Kt_inv = np.linalg.inv(np.array([[ft, 0, (P - 1) / 2], [0, ft, (P - 1) / 2], [0, 0, 1.0]]))
    edge = np.linspace(-0.5, P - 0.5, 17)
    outline = np.concatenate(
        [
            np.stack([edge, np.full(17, -0.5)], 1),
            np.stack([np.full(17, P - 0.5), edge], 1),
            np.stack([edge[::-1], np.full(17, P - 0.5)], 1),
            np.stack([np.full(17, -0.5), edge[::-1]], 1),
            [[(P - 1) / 2, (P - 1) / 2]],
        ]
    )
    outline_rays = np.hstack([outline, np.ones((len(outline), 1))]) @ Kt_inv.T

    t_frames = np.arange(N) / cfg.fps
    rate = _rate_function(cfg)
    Rk = _orientations(rate, t_frames)
    trng = np.random.default_rng([cfg.seed, 2])
    tf = trng.uniform(0.3, 0.6, 2)
    tph = trng.uniform(0, 2 * np.pi, 2)
    tamp = np.radians(cfg.target_speed_deg_s) / (2 * np.pi * tf) / np.sqrt(2)
    az = np.radians(cfg.target_offset_deg[0]) + tamp[0] * (
        np.sin(2 * np.pi * tf[0] * t_frames + tph[0]) - np.sin(tph[0])
    )
    el = np.radians(cfg.target_offset_deg[1]) + tamp[1] * (
        np.sin(2 * np.pi * tf[1] * t_frames + tph[1]) - np.sin(tph[1])
    )

    renderer = (
        _Renderer(cfg, cam, _target_texture(np.random.default_rng([cfg.seed, 0]), P), Kt_inv)
        if cfg.render
        else None
    )
    frames = np.empty((N, H, W, 3), np.uint8) if cfg.render else None
    boxes = np.full((N, 4), np.nan)
    centres = np.full((N, 2), np.nan)
    visible = np.zeros(N, bool)
    for k in range(N):
        Rt = Rk[k].T @ _rot_towards(az[k], el[k])  # target frame in camera k
        pts = outline_rays @ Rt.T
        in_front = bool(np.all(pts[:, 2] > 1e-6))
        if in_front:
            pix = cam.distort_points((pts[:, :2] / pts[:, 2:]) @ K[:2, :2].T + K[:2, 2])
            (x0, y0), (x1, y1) = pix[:-1].min(0), pix[:-1].max(0)
            # region [x0, x1] -> box convention
            boxes[k] = [x0 + 0.5, y0 + 0.5, x1 - x0, y1 - y0]
            centres[k] = pix[-1]
            visible[k] = x0 >= -0.5 and y0 >= -0.5 and x1 <= W - 0.5 and y1 <= H - 0.5
        if renderer is not None:
            frames[k] = renderer.render(Rk[k], Rt if in_front else None)

    # simulated gyro on the IMU clock (= true time)
    grng = np.random.default_rng([cfg.seed, 3])
    tg = np.arange(-0.2 - cfg.still_start_s, t_frames[-1] + 0.2, 1.0 / cfg.gyro_rate_hz)
    R_ci = np.asarray(cfg.R_cam_imu, float)
    bias = np.asarray(cfg.gyro_bias, float)
    w_imu = rate(tg) @ R_ci + bias + grng.normal(0, 1, (len(tg), 3)) * cfg.gyro_noise_std
    t_stamp = tg + grng.normal(0, 1, tg.shape) * cfg.gyro_jitter_s
    gyro_t_ns = _T_BASE_NS + np.round(t_stamp * 1e9).astype(np.int64)
    frame_ns = _T_BASE_NS + np.round((t_frames - cfg.time_offset_s) * 1e9).astype(np.int64)
    return SyntheticSequence(
        frames,
        frame_ns,
        gyro_t_ns,
        w_imu,
        K,
        cam.D.copy(),
        R_ci,
        int(round(cfg.time_offset_s * 1e9)),
        bias,
        Rk,
        boxes,
        centres,
        visible,
        cfg,
    )
