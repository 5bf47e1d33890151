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
Copyright and licence headers.

ament_copyright where a ROS install has it, and the project's own check.

ament_copyright has no PyPI wheel, so on a pip-only machine (CI) only the own check runs.  It asks
of every .py file what ament_copyright's ``bsd_3clause`` license accepts, plus the SPDX identifier
of package.xml's licence: a first comment block (after a shebang line) that starts with the
copyright line and holds the 3-Clause BSD text.
"""
import re

from lint_scope import python_files, REPO
import pytest

try:
    from ament_copyright.main import main as ament_copyright_main
except ImportError:
    ament_copyright_main = None

COPYRIGHT = re.compile(r'^Copyright \d{4}(-\d{4})? iemd_ros authors$')
SPDX = 'SPDX-License-Identifier: BSD-3-Clause'
# The 3-Clause BSD text as ament_copyright's bsd_3clause template has it, in two parts around the
# copyright holder's name; compared with the whitespace collapsed, as ament_copyright compares.
BSD_3CLAUSE = (
    'Redistribution and use in source and binary forms, with or without modification, are '
    'permitted provided '
    'that the following conditions are met: * Redistributions of source code must retain the '
    'above copyright '
    'notice, this list of conditions and the following disclaimer. * Redistributions in binary '
    'form must '
    'reproduce the above copyright notice, this list of conditions and the following disclaimer '
    'in the '
    'documentation and/or other materials provided with the distribution. * Neither the name of '
    'the',
    'nor the names of its contributors may be used to endorse or promote products derived from '
    'this software '
    'without specific prior written permission. THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT '
    'HOLDERS AND '
    'CONTRIBUTORS "AS IS" AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, '
    'THE IMPLIED '
    'WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE ARE DISCLAIMED. IN NO '
    'EVENT SHALL THE '
    'COPYRIGHT HOLDER OR CONTRIBUTORS BE LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, '
    'EXEMPLARY, OR '
    'CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR '
    'SERVICES; LOSS OF '
    'USE, DATA, OR PROFITS; OR BUSINESS INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF '
    'LIABILITY, WHETHER '
    'IN CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE) ARISING IN ANY '
    'WAY OUT OF THE '
    'USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE POSSIBILITY OF SUCH DAMAGE.',
)


def header_problem(text):
    """Return what is wrong with a file's header, or None."""
    lines = text.split('\n')
    if lines and lines[0].startswith('#!'):
        lines = lines[1:]
    block = []
    for line in lines:
        if not line.startswith('#'):
            break
        block.append(line[2:] if line.startswith('# ') else line[1:])
    if not block or not COPYRIGHT.match(block[0]):
        return 'no copyright line (%r) first' % 'Copyright YYYY iemd_ros authors'
    if SPDX not in block[1:3]:
        return 'no %r below the copyright line' % SPDX
    flat = ' '.join(' '.join(block[2:]).split())
    first = flat.find(BSD_3CLAUSE[0])
    if first < 0 or flat.find(BSD_3CLAUSE[1], first) < 0:
        return 'the 3-Clause BSD text is missing or changed'
    return None


def test_header_check_finds_missing_and_changed_headers():
    good = open(REPO / 'test' / 'lint_scope.py', encoding='utf-8').read()
    assert header_problem(good) is None
    assert header_problem('#!/usr/bin/env python3\n' + good) is None
    assert header_problem('"""No header."""\n') is not None
    assert header_problem(good.replace('iemd_ros authors', 'someone', 1)) is not None
    assert header_problem(good.replace(SPDX, 'SPDX-License-Identifier: MIT')) is not None
    assert header_problem(good.replace('FITNESS', 'FITNES')) is not None


@pytest.mark.copyright
@pytest.mark.linter
def test_every_python_file_has_the_project_header():
    files = python_files()
    assert len(files) > 100
    bad = []
    for path in files:
        text = path.read_text(encoding='utf-8')
        # empty files need none (nor does ament_copyright)
        problem = text.strip() and header_problem(text)
        if problem:
            bad.append('%s: %s' % (path.relative_to(REPO), problem))
    assert not bad, '%d file(s) without the header:\n' % len(bad) + '\n'.join(bad)


@pytest.mark.copyright
@pytest.mark.linter
@pytest.mark.skipif(
    ament_copyright_main is None,
    reason='ament_copyright is not installed (no PyPI wheel; a ROS 2 install has it)',
)
def test_copyright(monkeypatch):
    monkeypatch.chdir(REPO)
    rc = ament_copyright_main(argv=[str(p.relative_to(REPO)) for p in python_files()])
    assert rc == 0, 'Found errors'
