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
Independent jobs run in this process, on local worker processes or on a Dask cluster, by one loop.

A command that has many independent jobs (``iemd-eval``: one per tracker and sequence;
``iemd-replay``: one per bag) gives :func:`run_jobs` a job function and the jobs' arguments.  Where
the jobs run is an executor (:class:`concurrent.futures.Executor`), chosen by :class:`Workers`:

* one job at a time (``--jobs 1``): :class:`InlineExecutor`, in this process, one job after the
  other;
* ``--jobs N`` (default: every core this process may use): a ``ProcessPoolExecutor`` of N processes
  started with ``spawn`` (a fresh interpreter: nothing of the parent's threads or state is
  inherited);
* ``--cluster tcp://host:8786``: the workers of the Dask distributed scheduler at that address
  (``Client.get_executor``); they must have iemd_ros installed and see the input files at the same
  paths.

The loop is the same for the three (docs/decisions.md#parallel-engine): it keeps at most a window
of jobs submitted, and puts each job's result at the job's place, so the results come back in the
order of the jobs whatever order they finish in.  A job's exception is raised again here (the other
jobs are cancelled).
"""
from __future__ import annotations

import argparse
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass
import multiprocessing
import os

from iemd_ros.common.progress import Progress

__all__ = [
    'DASK_WORKER_CONFIG',
    'InlineExecutor',
    'Workers',
    'add_worker_arguments',
    'local_cores',
    'run_jobs',
]

#: jobs kept submitted per local worker process (one running, one queued in the pool)
WINDOW_PER_WORKER = 2
#: Dask configuration for the nannies that start a cluster's workers: no ``MALLOC_TRIM_THRESHOLD_``
#: (Dask's default sets it, which turns every image-sized temporary into an mmap and its page
#: faults; docs/decisions.md#parallel-engine)
DASK_WORKER_CONFIG = {'distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_': None}


def local_cores() -> int:
    """Return the number of cores this process may run on (its CPU affinity)."""
    return len(os.sched_getaffinity(0))


@dataclass(frozen=True)
class Workers:
    """
    Where :func:`run_jobs` runs the jobs.

    Parameters
    ----------
    jobs : int, optional
        Local worker processes (None: :func:`local_cores`; 1: in this process, one job after the
        other).
    cluster : str, optional
        The address of a Dask distributed scheduler (``tcp://host:8786``); ``jobs`` is then not
        used.

    Raises
    ------
    ValueError
        For ``jobs`` < 1.

    """

    jobs: int | None = None
    cluster: str | None = None

    def __post_init__(self):
        if self.jobs is not None and self.jobs < 1:
            raise ValueError(f'--jobs must be >= 1, got {self.jobs}')

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> 'Workers':
        """
        Return the workers chosen by :func:`add_worker_arguments`' options.

        Parameters
        ----------
        args : argparse.Namespace
            The parsed arguments.

        Returns
        -------
        Workers
            ``Workers(args.jobs, args.cluster)``.

        """
        return cls(args.jobs, args.cluster)

    def processes(self, n_jobs: int) -> int:
        """
        Return the local processes that run ``n_jobs`` jobs (1: this process; 0 on a cluster).

        Parameters
        ----------
        n_jobs : int
            The number of jobs.

        Returns
        -------
        int
            ``min(jobs, n_jobs)``, at least 1, or 0 with a cluster.

        """
        return 0 if self.cluster is not None else max(min(self.jobs or local_cores(), n_jobs), 1)

    def describe(self, n_jobs: int) -> str:
        """
        Where ``n_jobs`` jobs run (:meth:`processes`), in words for the commands' first line.

        Parameters
        ----------
        n_jobs : int
            As :meth:`processes` takes it.

        Returns
        -------
        str
            ``in this process``, ``on N local processes`` or ``on the Dask cluster at ADDRESS``.

        """
        n = self.processes(n_jobs)
        if self.cluster is not None:
            return f'on the Dask cluster at {self.cluster}'
        return 'in this process' if n == 1 else f'on {n} local processes'


def add_worker_arguments(parser: argparse.ArgumentParser) -> None:
    """
    Add ``--jobs N`` or ``--cluster ADDRESS`` (read back with :meth:`Workers.from_args`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The command's parser.

    """
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        '--jobs',
        type=int,
        default=None,
        metavar='N',
        help=f'worker processes on this machine (default: all {local_cores()} cores; '
        '1: one job after the other in this process)',
    )
    where.add_argument(
        '--cluster',
        default=None,
        metavar='ADDRESS',
        help='run the jobs on the Dask distributed scheduler at ADDRESS (tcp://host:8786); its '
        'workers need iemd_ros installed and the inputs at the same paths',
    )


class InlineExecutor(Executor):
    """An executor that runs each job in this process when it is submitted (the serial run)."""

    def submit(self, fn, /, *args, **kwargs) -> Future:
        """
        Run ``fn(*args, **kwargs)`` now.

        Parameters
        ----------
        fn : callable
            The job function.
        *args, **kwargs
            Its arguments.

        Returns
        -------
        concurrent.futures.Future
            Done, with the result or the exception of the call.

        """
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:
            future.set_exception(exc)
        return future


@contextmanager
def _executor(workers: Workers, n_jobs: int) -> Iterator[tuple[Executor, int]]:
    """Return the executor of ``workers`` for ``n_jobs`` jobs and how many to keep submitted."""
    if workers.cluster is not None:
        from distributed import Client

        with Client(workers.cluster, set_as_default=False) as client:
            yield client.get_executor(pure=False), n_jobs  # the scheduler queues them
        return
    processes = workers.processes(n_jobs)
    if processes == 1:
        yield InlineExecutor(), 1
        return
    pool = ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context('spawn'))
    failed = True
    try:
        yield pool, WINDOW_PER_WORKER * processes
        failed = False
    finally:  # after a failure, report it without waiting for the jobs still running
        pool.shutdown(wait=not failed, cancel_futures=True)


def run_jobs(
    fn: Callable,
    items,
    workers: Workers = Workers(),
    *,
    label: str = '',
    progress: bool | None = None,
    report: Callable[[int, object], str | None] | None = None,
    log: Callable[[str], None] = print,
) -> list:
    """
    ``[fn(item) for item in items]``.

    The calls run by the executor of ``workers`` (module docstring).

    Parameters
    ----------
    fn : callable
        The job function, of one argument; for worker processes a module-level function, and the
        items and results picklable.
    items : iterable
        The jobs' arguments.
    workers : Workers, optional
        Where the jobs run (default: a process per local core).
    label : str, optional
        The progress bar's label.
    progress : bool, optional
        Show a progress bar on stderr, one step per job (default: when stderr is a terminal).
    report : callable, optional
        ``report(index, result)`` when a job is done, in the order they finish; a line it returns
        goes to ``log`` (above the bar).
    log : callable, optional
        Receives the lines of ``report`` (default: printed on stdout).

    Returns
    -------
    list
        The results, in the order of ``items``.

    Raises
    ------
    Exception
        The first exception a job raised, after the jobs not yet started are cancelled.
    OSError
        When the cluster cannot be reached.

    """
    items = list(items)
    results: list = [None] * len(items)
    bar = Progress(len(items), label, progress)
    todo = iter(enumerate(items))
    pending: dict[Future, int] = {}
    try:
        with _executor(workers, len(items)) as (executor, window):
            try:
                while True:
                    for index, item in todo:
                        pending[executor.submit(fn, item)] = index
                        if len(pending) >= window:
                            break
                    if not pending:
                        break
                    finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for future in sorted(finished, key=pending.get):
                        index = pending.pop(future)
                        results[index] = future.result()
                        bar.update(1)
                        line = report(index, results[index]) if report is not None else None
                        if line is not None:
                            with bar.above():
                                log(line)
            except BaseException:
                for future in pending:
                    future.cancel()
                raise
    finally:
        bar.close()
    return results
