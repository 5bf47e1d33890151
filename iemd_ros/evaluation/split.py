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
The fixed split of ``../shared/data`` into a training and a validation part.

(``split.json`` beside this module).

Tracker choices are tuned on the training part and confirmed on the validation part, never tuned
on.
"""
from __future__ import annotations

from functools import cache
import hashlib
import json
from pathlib import Path

from iemd_ros.datasets.otb import derives_from

__all__ = ['in_part', 'PARTS', 'split', 'split_names', 'hash_split']

PARTS = ('train', 'validation')
_FILE = Path(__file__).with_name('split.json')


@cache
def split() -> dict:
    """``{part: {group: [sequence names]}}`` from ``split.json``."""
    return json.loads(_FILE.read_text())


def split_names(part: str, groups=('otb', 'uav')) -> list[str]:
    """
    Return the sequence names of ``part`` (``train`` or ``validation``) in the given groups.

    Raises
    ------
    ValueError
        For an unknown part.

    """
    if part not in PARTS:
        raise ValueError(f"unknown split part {part!r} (choose from {', '.join(PARTS)})")
    return [name for group in groups for name in split()[part].get(group, [])]


def in_part(name: str, part: list[str]) -> bool:
    """
    Whether the sequence ``name`` belongs to ``part`` (names from :func:`split_names`).

    It does when it is one of them or made from one (:func:`~iemd_ros.datasets.otb.derives_from`).
    """
    return any(derives_from(name, source) for source in part)


def hash_split(names) -> tuple[list[str], list[str]]:
    """
    Return the rule that made the split.

    (train, validation) of one folder's names, ordered by the SHA-256 of the name, the first half
    (rounded up) training.
    """
    ordered = sorted(names, key=lambda n: hashlib.sha256(n.encode()).hexdigest())
    k = (len(ordered) + 1) // 2
    return ordered[:k], ordered[k:]
