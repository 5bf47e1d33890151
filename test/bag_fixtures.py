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

"""Helpers of the bag tests: small synthetic shaky-camera bags and reading bags back."""
from __future__ import annotations

from iemd_ros.bags.io import open_bag
from iemd_ros.bags.make import DEFAULT_TOPICS, source_from_synthetic, write_bag
from iemd_ros.datasets.synthetic import generate
from iemd_ros.messages.conversions import compressed_topic, stamp_ns
import numpy as np

N_FRAMES = 12
# the topics iemd-make-bag writes
IMG, INFO, IMU = DEFAULT_TOPICS['image'], DEFAULT_TOPICS['camera_info'], DEFAULT_TOPICS['imu']
IMG_COMPRESSED = compressed_topic(IMG)  # where --compress writes the frames


def shaky_sequence(n_frames: int = N_FRAMES, seed: int = 4, **over):
    """Return a strong shake (the gyro prior matters), a gyro with a 4 ms camera-IMU offset."""
    return generate(
        n_frames=n_frames, seed=seed, max_rate_deg_s=150.0, time_offset_s=0.004, **over
    )


def make_bag(seq, path, fmt: str = 'mcap', **kw) -> dict:
    return write_bag(source_from_synthetic(seq), path, fmt, **kw)


def read_all(path) -> list[tuple[str, str, int, object]]:
    """Every message as ``(topic, msgtype, log_time_ns, message)`` in the reader's order."""
    reader = open_bag(path)
    try:
        return [
            (c.topic, c.msgtype, t, reader.deserialize(raw, c.msgtype))
            for c, t, raw in reader.messages()
        ]
    finally:
        reader.close()


def by_topic(messages, topic: str):
    return [m for t, _, _, m in messages if t == topic]


def stamps(msgs) -> np.ndarray:
    return np.array([stamp_ns(m.header) for m in msgs], dtype=np.int64)
