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

"""Shared fixtures: location of the real data in ../shared (skipped cleanly when absent)."""
from pathlib import Path
import signal
import subprocess

import numpy as np
import pytest

SHARED = Path(__file__).resolve().parents[1].parent / 'shared'
DATA = SHARED / 'data'


def _need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(
            f'real data not available: {path} is absent (CI has ../shared beside the repo)'
        )
    return path


@pytest.fixture
def otb_root() -> Path:
    """Folder of OTB sequences (../shared/data/otb)."""
    return _need(DATA / 'otb')


@pytest.fixture
def uav_root() -> Path:
    """Folder of drone sequences (../shared/data/uav)."""
    return _need(DATA / 'uav')


@pytest.fixture
def car4_first(otb_root):
    """
    Car4's first frame (BGR) and its ground-truth box (x, y, w, h).

    The real texture of several tests.
    """
    from iemd_ros.datasets.otb import load_sequence, read_frame

    seq = load_sequence(otb_root / 'Car4')
    return read_frame(seq.frame_paths[0]), np.asarray(seq.gt_boxes[0], dtype=float)


@pytest.fixture
def imu_root() -> Path:
    """Folder of camera + gyro recordings (../shared/data/imu)."""
    return _need(DATA / 'imu')


@pytest.fixture(scope='module')
def ctx():
    """
    Yield an rclpy context on an isolated, localhost-only domain.

    For the ROS tests of one module.
    """
    from ros_harness import ros_context  # rclpy is imported only by the tests that need it

    with ros_context() as context:
        yield context


@pytest.fixture
def stop_process():
    """
    ``stop(proc, timeout=15)``: SIGINT a child (if still running), collect its output.

    Returns ``(stdout, stderr, stopped)``; a child still running after ``timeout`` s is killed and
    ``stopped`` is False.
    """

    def stop(proc: subprocess.Popen, timeout: float = 15.0):
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            out, err = proc.communicate(timeout=timeout)
            return out, err, True
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            return out, err, False

    return stop


@pytest.fixture(scope='session')
def dask_cluster() -> str:
    """
    Yield the address of a Dask distributed cluster on this machine only.

    A scheduler and 2 single-thread worker processes on 127.0.0.1, started here and closed at the
    end of the session.  Every port is a free one on the loopback (the scheduler's HTTP server
    listens even without a dashboard: on 127.0.0.1 too).  The workers are started as the README
    advises (DASK_WORKER_CONFIG); Dask's one-thread numpy settings stay.
    """
    import dask
    from distributed import LocalCluster
    from iemd_ros.common.parallel import DASK_WORKER_CONFIG

    with (
        dask.config.set(DASK_WORKER_CONFIG),
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host='127.0.0.1',
            scheduler_port=0,
            dashboard_address='127.0.0.1:0',
            memory_limit='4GiB',
        ) as cluster,
    ):
        yield cluster.scheduler_address
