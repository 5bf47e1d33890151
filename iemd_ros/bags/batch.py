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
Batch replay: many bags through :class:`~iemd_ros.bags.replay.Replay`.

One job per bag (``iemd-replay --out-dir``).

The bags are given one by one or as folders holding them (:func:`find_bags`: rosbag2 folders and
ROS 1 ``.bag`` files, in name order).  Each bag is one :class:`ReplayJob` of
:func:`run_replay_job`, run by :func:`iemd_ros.common.parallel.run_jobs` (in this process, on local
processes or on a Dask cluster): it writes ``<out_dir>/<bag>.csv`` and, when asked, the rosbag2
``<out_dir>/<bag>_result``.  A replay depends on its bag only, so each CSV is the one a replay of
that bag alone writes, byte for byte, whichever workers ran it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from iemd_ros.bags.io import bag_path
from iemd_ros.bags.replay import parse_box, replay, ReplayResult
from iemd_ros.common.cli import one_line
from iemd_ros.common.parallel import run_jobs, Workers

__all__ = [
    'ReplayJob',
    'bag_name',
    'bags_in',
    'find_bags',
    'replay_batch',
    'replay_jobs',
    'run_replay_job',
]

RESULT_BAG_SUFFIX = '_result'


def bags_in(folder: Path) -> list[Path]:
    """
    Return the bags a folder holds (its rosbag2 folders and ``.bag`` files, in name order).

    [] for a bag itself.

    Parameters
    ----------
    folder : Path
        A folder (anything else holds no bag).

    Returns
    -------
    list of Path
        The bags.

    """
    if not folder.is_dir() or (folder / 'metadata.yaml').exists():
        return []
    return sorted(
        p
        for p in folder.iterdir()
        if (p.is_file() and p.suffix == '.bag') or (p.is_dir() and (p / 'metadata.yaml').is_file())
    )


def find_bags(inputs) -> list[Path]:
    """
    Return the bags named by ``inputs``.

    Each a bag (as :func:`~iemd_ros.bags.io.open_bag` takes it) or a folder of bags (its rosbag2
    folders and ``.bag`` files, in name order; a folder of bare ``.mcap`` files is not one).

    Parameters
    ----------
    inputs : iterable of str or path-like
        Bags and folders of bags.

    Returns
    -------
    list of Path
        The bags, in the order given (a bag named twice once).

    Raises
    ------
    BagError
        For an input that does not exist, or a folder that is neither a bag nor holds one
        (:func:`~iemd_ros.bags.io.bag_path`).

    """
    found: list[Path] = []
    for item in inputs:
        path = Path(item)
        bags = bags_in(path) or [bag_path(path)]
        found.extend(b for b in bags if b not in found)
    return found


def bag_name(bag: Path) -> str:
    """
    Return a bag's name in the output folder.

    The rosbag2 folder's name, or the ``.bag`` or ``.mcap`` file's stem.

    Parameters
    ----------
    bag : Path
        A bag, as :func:`find_bags` gives it.

    Returns
    -------
    str
        The name.

    """
    return bag.stem if bag.is_file() and bag.suffix in ('.bag', '.mcap') else bag.name


@dataclass(frozen=True)
class ReplayJob:
    """
    One bag of a batch: where it is, its target and where its outputs go.

    Parameters
    ----------
    bag : Path
        The bag.
    init_box : tuple of float
        The target on its first decodable image.
    csv_path : Path
        The CSV written.
    out_bag : Path or None
        The rosbag2 of the detections and diagnostics written (None: none).
    options : dict
        The other keyword arguments of :class:`~iemd_ros.bags.replay.Replay` (topics, config,
        use_gyro, camera).

    """

    bag: Path
    init_box: tuple
    csv_path: Path
    out_bag: Path | None = None
    options: dict = field(default_factory=dict)


def _no_warning(text: str) -> None:
    """
    Keep a replay job's warnings in its result, for the command to print.

    They go to ``ReplayResult.warnings``.
    """


def run_replay_job(job: ReplayJob) -> ReplayResult:
    """
    Replay the job's bag, writing its CSV (and its result bag).

    No progress bar, warnings in the result.

    Parameters
    ----------
    job : ReplayJob
        The bag and its outputs.

    Returns
    -------
    ReplayResult
        What :func:`~iemd_ros.bags.replay.replay` returns.

    Raises
    ------
    ValueError
        The replay's error, after the bag's name.

    """
    try:
        return replay(
            job.bag,
            job.init_box,
            csv_path=job.csv_path,
            out_bag=job.out_bag,
            progress=False,
            warn=_no_warning,
            **job.options,
        )
    except ValueError as exc:
        raise ValueError(f'{bag_name(job.bag)}: {one_line(exc)}') from None


def replay_jobs(
    bags: list[Path], init_boxes: list, out_dir, *, out_bags: bool = False, **options
) -> list[ReplayJob]:
    """
    Return the jobs of a batch, checked before any runs.

    Parameters
    ----------
    bags : list of Path
        The bags (:func:`find_bags`).
    init_boxes : list
        One init box for every bag, or one per bag (:func:`~iemd_ros.bags.replay.parse_box` forms).
    out_dir : str or path-like
        The output folder.
    out_bags : bool, optional
        Write each bag's result bag too.
    **options
        The other keyword arguments of :class:`~iemd_ros.bags.replay.Replay`.

    Returns
    -------
    list of ReplayJob
        One per bag, in order.

    Raises
    ------
    ValueError
        For a number of init boxes that is neither 1 nor the number of bags, a bad box, two bags of
        one name, or a result bag that exists already.

    """
    if len(init_boxes) not in (1, len(bags)):
        raise ValueError(
            f'--init: give one box for every bag or one per bag ({len(bags)}), got '
            f'{len(init_boxes)}'
        )
    boxes = [parse_box(b) for b in init_boxes] * (len(bags) if len(init_boxes) == 1 else 1)
    out_dir = Path(out_dir)
    names: dict[str, Path] = {}
    jobs = []
    for bag, box in zip(bags, boxes):
        name = bag_name(bag)
        if name in names:
            raise ValueError(
                f'two bags are named {name!r} ({names[name]}, {bag}): their outputs would collide '
                'in the output folder'
            )
        names[name] = bag
        result_bag = out_dir / f'{name}{RESULT_BAG_SUFFIX}' if out_bags else None
        if result_bag is not None and result_bag.exists():
            raise ValueError(f'{result_bag} exists already; choose a new output folder')
        jobs.append(ReplayJob(bag, box, out_dir / f'{name}.csv', result_bag, dict(options)))
    return jobs


def replay_batch(
    jobs: list[ReplayJob],
    workers: Workers = Workers(),
    *,
    progress: bool | None = None,
    report=None,
    log=print,
) -> list[ReplayResult]:
    """
    Run the jobs of a batch (:func:`replay_jobs`) on ``workers``.

    Parameters
    ----------
    jobs : list of ReplayJob
        The bags and their outputs.
    workers : Workers, optional
        Where the jobs run (default: a process per local core).
    progress : bool, optional
        A progress bar over the bags on stderr (default: when stderr is a terminal).
    report, log : callable, optional
        As :func:`~iemd_ros.common.parallel.run_jobs` takes them.

    Returns
    -------
    list of ReplayResult
        One per job, in order.

    Raises
    ------
    ValueError
        The first bad bag's error (:class:`~iemd_ros.bags.io.BagError`), after the jobs not yet
        started are cancelled.

    """
    return run_jobs(
        run_replay_job,
        jobs,
        workers,
        label='iemd-replay',
        progress=progress,
        report=report,
        log=log,
    )
