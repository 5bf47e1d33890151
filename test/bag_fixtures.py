"""Helpers of the bag tests: small synthetic shaky-camera bags and reading bags back."""
from __future__ import annotations

import numpy as np

from iemd_ros.bags.io import open_bag
from iemd_ros.messages.conversions import compressed_topic, stamp_ns
from iemd_ros.bags.make import DEFAULT_TOPICS, source_from_synthetic, write_bag
from iemd_ros.datasets.synthetic import generate

N_FRAMES = 12
# the topics iemd-make-bag writes
IMG, INFO, IMU = DEFAULT_TOPICS["image"], DEFAULT_TOPICS["camera_info"], DEFAULT_TOPICS["imu"]
IMG_COMPRESSED = compressed_topic(IMG)  # where --compress writes the frames


def shaky_sequence(n_frames: int = N_FRAMES, seed: int = 4, **over):
    """A strong shake (the gyro prior matters), a gyro with a 4 ms camera-IMU offset."""
    return generate(n_frames=n_frames, seed=seed, max_rate_deg_s=150.0, time_offset_s=0.004, **over)


def make_bag(seq, path, fmt: str = "mcap", **kw) -> dict:
    return write_bag(source_from_synthetic(seq), path, fmt, **kw)


def read_all(path) -> list[tuple[str, str, int, object]]:
    """Every message as ``(topic, msgtype, log_time_ns, message)`` in the reader's order."""
    reader = open_bag(path)
    try:
        return [(c.topic, c.msgtype, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]
    finally:
        reader.close()


def by_topic(messages, topic: str):
    return [m for t, _, _, m in messages if t == topic]


def stamps(msgs) -> np.ndarray:
    return np.array([stamp_ns(m.header) for m in msgs], dtype=np.int64)
