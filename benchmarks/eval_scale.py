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
``iemd-eval`` serially, on N local processes and on a local Dask cluster of N workers, in one run.

The wall time of each and the digest of its ``results.json`` without the wall-clock fields (the
three must be equal).

    python benchmarks/eval_scale.py [--workers 2] [--out DIR] [-- iemd-eval arguments ...]

Each run is the command ``python -m iemd_ros.apps.eval ARGS --out DIR/<run> (--jobs 1 | --jobs N |
--cluster A)`` in its own process, timed from its start to its end.  The cluster is a
``distributed.LocalCluster`` of N single-thread worker processes on 127.0.0.1, started by this
script before its run (its start-up is printed apart) and closed after it; its workers start as the
README advises (``DASK_WORKER_CONFIG``; ``--dask-defaults``: with Dask's defaults).  Beside the
wall time: the CPU seconds of each run (the command's and its workers', the cluster's start and
stop included) and the machine's load average, since other jobs share the cores.  Without iemd-eval
arguments every sequence of ../shared/data/otb and uav runs with the default trackers.  Prints the
commands, then one row per run: wall time, speed-up over the serial run, load, CPU seconds, digest
(:func:`iemd_ros.evaluation.ope.results_digest`).
"""
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import resource
import subprocess
import sys
import tempfile
import time

from iemd_ros.common.parallel import DASK_WORKER_CONFIG
from iemd_ros.evaluation.ope import results_digest, WALL_CLOCK_FIELDS


def _cpu_s() -> float:
    """CPU seconds (user + system) of this process and of its children waited for."""
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def _run(name: str, args: list[str], where: list[str], out: Path) -> tuple[float, float, str]:
    """Wall time, the load average over the last minute at the end, and the digest of one run."""
    cmd = [sys.executable, '-m', 'iemd_ros.apps.eval', *args, '--out', str(out / name), *where]
    print(f"[{name}] {' '.join(cmd)}", flush=True)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(
            f'eval_scale: the {name} run failed ({proc.returncode}): {proc.stderr.strip()[-500:]}'
        )
    return (
        wall,
        os.getloadavg()[0],
        results_digest(json.loads((out / name / 'results.json').read_text())),
    )


def _timed(run) -> tuple[float, float, str, float]:
    """Return ``run()``'s figures and the CPU seconds this process and its children spent."""
    cpu = _cpu_s()
    figures = run()
    return (*figures, _cpu_s() - cpu)


def _on_cluster(
    workers: int, args: list[str], out: Path, trim_off: bool
) -> tuple[float, float, str]:
    """
    Return the run on a LocalCluster started (its start-up printed) and closed here; ``trim_off``.

    Its workers started with :data:`~iemd_ros.common.parallel.DASK_WORKER_CONFIG`.
    """
    import dask
    from distributed import LocalCluster

    t0 = time.perf_counter()
    with (
        dask.config.set(DASK_WORKER_CONFIG if trim_off else {}),
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host='127.0.0.1',
            scheduler_port=0,
            dashboard_address='127.0.0.1:0',
        ) as cluster,
    ):
        print(
            f'[cluster] LocalCluster of {workers} workers at {cluster.scheduler_address}, up in '
            f'{time.perf_counter() - t0:.1f} s'
        )
        return _run('cluster', args, ['--cluster', cluster.scheduler_address], out)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument(
        '--workers', type=int, default=2, help='local processes and cluster workers (default 2)'
    )
    p.add_argument(
        '--out',
        type=Path,
        default=None,
        help='where the three runs write (default: a temporary folder)',
    )
    p.add_argument(
        '--dask-defaults',
        action='store_true',
        help="start the cluster's workers with Dask's defaults (MALLOC_TRIM_THRESHOLD_ set), not "
        'as the '
        'README advises (DASK_WORKER_CONFIG)',
    )
    p.add_argument('eval_args', nargs=argparse.REMAINDER, help='arguments of iemd-eval, after --')
    a = p.parse_args()
    args = [x for x in a.eval_args if x != '--']
    out = a.out or Path(tempfile.mkdtemp(prefix='eval_scale_'))
    rows = [
        ('serial', *_timed(lambda: _run('serial', args, ['--jobs', '1'], out))),
        (
            f'{a.workers} processes',
            *_timed(lambda: _run('local', args, ['--jobs', str(a.workers)], out)),
        ),
    ]
    rows.append(
        (
            f'Dask, {a.workers} workers',
            *_timed(lambda: _on_cluster(a.workers, args, out, not a.dask_defaults)),
        )
    )
    serial = rows[0][1]
    print(
        f'\nresults in {out}; digest of results.json without {", ".join(WALL_CLOCK_FIELDS)}; '
        "load: the machine's "
        '1-minute load average at the end of the run; cpu s: of the command and its workers (the '
        "cluster's "
        'included)'
    )
    print(f'{"run":<18} {"wall s":>8} {"speed-up":>9} {"load":>5} {"cpu s":>7}  digest')
    for name, wall, load, digest, cpu in rows:
        print(f'{name:<18} {wall:8.1f} {serial / wall:8.2f}x {load:5.1f} {cpu:7.1f}  {digest}')
    same = len({row[3] for row in rows}) == 1
    print('identical results' if same else 'RESULTS DIFFER')
    return 0 if same else 1


if __name__ == '__main__':
    sys.exit(main())
