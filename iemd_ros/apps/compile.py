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
``iemd-compile``: compile the tracker's and the gyro's numba kernels into numba's cache.

The cache is beside the installed package, so that the first start of the node or of
``iemd-replay`` compiles nothing.

Run at install time (``scripts/setup_venv.sh``, and ``setup.py install``/``develop`` as colcon runs
them); it takes 10-30 s once per install.  Without it the first start compiles them and says so.
"""

from __future__ import annotations

import sys
import time

__all__ = ['main']


def main(argv: list[str] | None = None) -> int:
    """
    Compile (or load) every kernel and print where the cache is and how long it took.

    Parameters
    ----------
    argv : list of str, optional
        No arguments are taken.

    Returns
    -------
    int
        0.

    """
    if argv is None:
        argv = sys.argv[1:]
    if argv:
        print('usage: iemd-compile (no arguments)', file=sys.stderr)
        return 2
    start = time.perf_counter()
    from iemd_ros.pipeline.pipeline import kernel_cache_dir, warm_up_kernels

    cached = warm_up_kernels()
    print(
        f'iemd-compile: numba kernels {"loaded from" if cached else "compiled into"} the cache in '
        f'{kernel_cache_dir()} in {time.perf_counter() - start:.1f} s'
    )
    return 0


if __name__ == '__main__':
    sys.exit(main())
