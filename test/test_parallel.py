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
iemd_ros.common.parallel.

The jobs of a command run in this process, on local processes or on a Dask cluster started by the
test (127.0.0.1), by the same loop; results in the order of the jobs; errors raised again.
"""
import os
import time

from iemd_ros.common.cli import CliParser, UsageError
from iemd_ros.common.parallel import add_worker_arguments, local_cores, run_jobs, Workers
from iemd_ros.common.progress import CLEAR_LINE
import pytest

# bound on a job that waits for another one (test_results_come_back_in_the_order_of_the_jobs)
WAIT_S = 30


def pid_of(item):
    """Return a job: its item and the process that ran it."""
    return item, os.getpid()


def wait_for(item):
    """
    Return a job: ``("wait", path)`` waits (at most WAIT_S) until ``path`` exists.

    ``("make", path)`` creates it, any other returns at once; each returns its kind and the time it
    ended (a "make": before the file exists).
    """
    kind, path = item
    if kind == 'make':
        ended = time.time()
        open(path, 'w').close()
        return kind, ended
    deadline = time.monotonic() + WAIT_S
    while kind == 'wait' and not os.path.exists(path) and time.monotonic() < deadline:
        time.sleep(0.01)
    return kind, time.time()


def fail_on_zero(item):
    """Return a job that raises a ValueError naming its item when the item is 0."""
    if item == 0:
        raise ValueError(f'job {item} failed')
    return item


def test_inline_runs_each_job_here_one_after_the_other():
    done = []
    out = run_jobs(pid_of, [3, 1, 2], Workers(1), report=lambda i, r: done.append(i))
    assert out == [(3, os.getpid()), (1, os.getpid()), (2, os.getpid())] and done == [0, 1, 2]


def test_results_come_back_in_the_order_of_the_jobs(tmp_path):
    """
    Job 0 finishes only after job 2 (it waits for job 2's file).

    The results keep the jobs' order, each job is reported once, and the jobs ran in other
    processes than this one.
    """
    flag = str(tmp_path / 'flag')
    done = []
    out = run_jobs(wait_for, [('wait', flag), ('other', '-'), ('make', flag)], Workers(2),
                   report=lambda i, r: done.append(i))
    assert [kind for kind, _ in out] == ['wait', 'other', 'make'] and sorted(done) == [0, 1, 2]
    assert out[0][1] > out[2][1]                                      # job 0 ended after job 2
    pids = {pid for _, pid in run_jobs(pid_of, range(4), Workers(2))}
    assert os.getpid() not in pids and 1 <= len(pids) <= 2


@pytest.mark.parametrize('jobs', [1, 2])
def test_a_job_error_is_raised_again(jobs):
    with pytest.raises(ValueError, match='job 0 failed'):
        run_jobs(fail_on_zero, [1, 0, 2, 3], Workers(jobs))


def test_inline_stops_at_the_first_error():
    done = []
    with pytest.raises(ValueError):
        run_jobs(fail_on_zero, [1, 0, 2], Workers(1), report=lambda i, r: done.append(i))
    assert done == [0]      # job 2 never ran


def test_cluster_runs_the_jobs_on_its_workers(dask_cluster):
    out = run_jobs(pid_of, range(5), Workers(cluster=dask_cluster))
    assert [item for item, _ in out] == list(range(5)) and os.getpid() not in {
        pid for _, pid in out
    }
    with pytest.raises(ValueError, match='job 0 failed'):
        run_jobs(fail_on_zero, [1, 0, 2], Workers(cluster=dask_cluster))


def test_unreachable_cluster_is_an_oserror():
    import dask

    with dask.config.set({'distributed.comm.timeouts.connect': '2s'}), pytest.raises(OSError):
        run_jobs(pid_of, [1], Workers(cluster='tcp://127.0.0.1:9'))


def test_workers_options_and_counts():
    p = CliParser(prog='x')
    add_worker_arguments(p)
    assert (
        Workers.from_args(p.parse_args([])) == Workers()
        and Workers().processes(1000) == local_cores()
    )
    # no idle process
    assert Workers.from_args(p.parse_args(['--jobs', '3'])).processes(2) == 2
    assert Workers(cluster='tcp://h:8786').describe(4) == 'on the Dask cluster at tcp://h:8786'
    assert (
        Workers(1).describe(4) == 'in this process'
        and Workers(2).describe(4) == 'on 2 local processes'
    )
    with pytest.raises(UsageError, match='not allowed with'):
        p.parse_args(['--jobs', '2', '--cluster', 'tcp://h:8786'])
    with pytest.raises(ValueError, match='--jobs must be >= 1, got 0'):
        Workers(0)


def test_progress_bar_on_stderr_and_the_reported_lines_above_it(capsys):
    run_jobs(
        pid_of, range(2), Workers(1), label='lbl', progress=True, report=lambda i, r: f'job {i}'
    )
    one, two = (f'lbl [{"#" * n}{"." * (30 - n)}] {k}/2 ' for n, k in ((15, 1), (30, 2)))
    clear = f'\r{CLEAR_LINE}'
    captured = capsys.readouterr()
    assert captured.err == f'{clear}{one}{clear}{one}{clear}{two}{clear}{two}\n'
    assert captured.out == 'job 0\njob 1\n'
