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
Published trackers' results on the same sequences.

Printed beside a run (``iemd-eval --published``).

The file is ``../shared/anchors/published_results.json``: ``{set: {tracker: {sequence:
{avg_overlap, auc, prec20}}}}`` in percent, scored with the same one-pass protocol as
:mod:`iemd_ros.evaluation.ope`.
"""
from __future__ import annotations

import json
from pathlib import Path

from iemd_ros.datasets.otb import shared_data
from iemd_ros.evaluation.ope import MEAN

__all__ = ['default_published', 'load_published', 'published_means', 'format_published', 'DEEP']

# The anchors with deep features (the anchors' README); the others are hand-crafted.
DEEP = ('LADCF', 'MDNet', 'CFNet', 'SiamFC', 'Baseline')


def default_published() -> Path | None:
    """``../shared/anchors/published_results.json``, if it exists."""
    data = shared_data()
    path = None if data is None else data.parent / 'anchors' / 'published_results.json'
    return path if path is not None and path.is_file() else None


def load_published(path) -> dict:
    """
    Return the published results of ``path``.

    Raises
    ------
    ValueError
        For a file that cannot be read or does not have the layout ``{set: {tracker: {sequence:
        {...}}}}``.

    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f'cannot read published results {path}: {exc}') from None
    ok = isinstance(doc, dict) and all(
        isinstance(t, dict) and all(isinstance(s, dict) for s in t.values()) for t in doc.values()
    )
    if not ok:
        raise ValueError(
            f'{path}: expected {{set: {{tracker: {{sequence: {{avg_overlap, auc}}}}}}}}'
        )
    return doc


def is_hand_crafted(tracker: str) -> bool:
    """
    Whether a published tracker uses hand-crafted features.

    (``LADCF-HC`` does, ``LADCF`` does not).
    """
    return not (tracker == 'LADCF' or tracker.startswith(DEEP[1:]))


def published_means(
    published: dict, names: list[str]
) -> dict[str, tuple[list[str], dict[str, tuple[float, float]]]]:
    """
    Per set, the run's sequences it holds and every tracker's mean (AO %, AUC %) over them.

    A tracker enters a set's means only when it has every one of those sequences.
    """
    out = {}
    for group, trackers in published.items():
        held = [n for n in names if any(n in seqs for seqs in trackers.values())]
        if not held:
            continue
        means = {}
        for tracker, seqs in trackers.items():
            if all(n in seqs for n in held):
                means[tracker] = (
                    sum(seqs[n]['avg_overlap'] for n in held) / len(held),
                    sum(seqs[n]['auc'] for n in held) / len(held),
                )
        out[group] = (held, means)
    return out


def format_published(published: dict, results: dict, trackers: list[str]) -> str:
    """
    Return the run's trackers ranked among the published ones, per set, on the sequences both have.

    Parameters
    ----------
    published : dict
        :func:`load_published`'s document.
    results : dict
        Tracker -> sequence name -> figures (fractions), as
        :func:`~iemd_ros.evaluation.ope.evaluate` records them.
    trackers : list of str
        The run's trackers.

    Returns
    -------
    str
        One table per set: tracker, mean AO %, mean AUC %, hand-crafted or deep, the run's rows
        marked.

    """
    names = [n for n in next(iter(results.values())) if n != MEAN and not n.startswith(MEAN + ' ')]
    lines = []
    for group, (held, means) in published_means(published, names).items():
        rows = [
            (ao, auc, t, 'deep' if not is_hand_crafted(t) else 'hand-crafted', '')
            for t, (ao, auc) in means.items()
        ]
        for t in trackers:
            ao = 100 * sum(results[t][n]['average_overlap'] for n in held) / len(held)
            auc = 100 * sum(results[t][n]['success_auc'] for n in held) / len(held)
            rows.append((ao, auc, t, '', '<- this run'))
        lines += [
            f'published results, set {group}: {len(held)} sequence(s) of this run '
            f'({", ".join(held)})',
            f'{"tracker":<18} {"AO%":>6} {"AUC%":>6}  features',
        ]
        lines += [
            f'{t:<18} {ao:6.1f} {auc:6.1f}  {kind:<12} {mark}'.rstrip()
            for ao, auc, t, kind, mark in sorted(rows, reverse=True)
        ]
        lines.append('')
    return (
        '\n'.join(lines).rstrip()
        or "published results: none of this run's sequences are in the file"
    )
