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
What the ament lint tests (test_flake8, test_pep257, test_copyright) check.

Every .py file of the repository.

Left out: folders starting with '.' or '_' (as ament's linters do) and the build outputs that pip
and colcon leave in the source tree.
"""
from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# `pip install .` (scripts/setup_venv.sh) leaves build/ beside setup.py; colcon's build/install/log
# when the repository is the workspace; out/ holds benchmark and evaluation outputs.
BUILD_OUTPUTS = ('build', 'install', 'log', 'out')


def excluded_paths() -> list[str]:
    """Absolute paths of the build outputs, for the linters' ``--exclude``."""
    return [str(REPO / p) for p in BUILD_OUTPUTS]


def python_files() -> list[Path]:
    """Every .py file the lint tests check, sorted."""
    skip = [REPO / p for p in BUILD_OUTPUTS]
    files = []
    for path in REPO.rglob('*.py'):
        rel = path.relative_to(REPO)
        if any(part.startswith(('.', '_')) for part in rel.parts[:-1]):
            continue
        if any(path == s or s in path.parents for s in skip):
            continue
        files.append(path)
    return sorted(files)
