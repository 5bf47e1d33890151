"""The fixed split of ``../shared/data`` into a training and a validation part (``split.json`` beside this module).

Tracker choices are tuned on the training part and confirmed on the validation part, never tuned on.
"""
from __future__ import annotations

import hashlib
import json
from functools import cache
from pathlib import Path

__all__ = ["PARTS", "split", "split_names", "hash_split"]

PARTS = ("train", "validation")
_FILE = Path(__file__).with_name("split.json")


@cache
def split() -> dict:
    """``{part: {group: [sequence names]}}`` from ``split.json``."""
    return json.loads(_FILE.read_text())


def split_names(part: str, groups=("otb", "uav")) -> list[str]:
    """The sequence names of ``part`` (``train`` or ``validation``) in the given groups.

    Raises
    ------
    ValueError
        For an unknown part.
    """
    if part not in PARTS:
        raise ValueError(f"unknown split part {part!r} (choose from {', '.join(PARTS)})")
    return [name for group in groups for name in split()[part].get(group, [])]


def hash_split(names) -> tuple[list[str], list[str]]:
    """The rule that made the split: (train, validation) of one folder's names, ordered by the SHA-256 of the name,
    the first half (rounded up) training."""
    ordered = sorted(names, key=lambda n: hashlib.sha256(n.encode()).hexdigest())
    k = (len(ordered) + 1) // 2
    return ordered[:k], ordered[k:]
