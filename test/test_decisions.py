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

"""docs/decisions.md: its anchors, and the index of the accuracy records by theme."""
import re

from helpers import REPO

TEXT = (REPO / 'docs' / 'decisions.md').read_text()
ANCHORS = re.findall(r'<a id="([a-z0-9-]+)"></a>', TEXT)
START, END = TEXT.index('<a id="records-by-theme">'), TEXT.index('<a id="candidate-per-iterate">')
INDEX = TEXT[START:END]
LISTED = re.findall(r'\]\(#([a-z0-9-]+)\)', INDEX)


def test_every_record_has_one_anchor_and_a_heading_of_its_id():
    assert len(ANCHORS) == len(set(ANCHORS))
    for name in ANCHORS:
        assert re.search(f'<a id="{name}"></a>\n## {name}:', TEXT), name


def test_the_index_lists_every_issue_24_record_once_and_only_records():
    issue_24 = re.findall(r'<a id="([a-z0-9-]+)"></a>\n## [^\n]*issues? [^\n]*#24', TEXT)
    assert len(issue_24) > 100
    assert len(LISTED) == len(set(LISTED))
    assert set(LISTED) <= set(ANCHORS) - {'records-by-theme'}
    missing = set(issue_24) - set(LISTED)
    assert not missing, f'add {sorted(missing)} to records-by-theme'
