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
The command lines' argument types (iemd_ros/common/cli.py).

Each refuses what is not a finite number in its range with ``argparse.ArgumentTypeError``, so that
argparse reports it in one line, and reads the rest as a float.
"""
import argparse

from iemd_ros.common.cli import finite_float, non_negative_float, positive_float
import pytest

REFUSED = [
    (positive_float, ['inf', '-inf', 'nan', '0', '-2', 'fast', '']),
    (non_negative_float, ['inf', '-inf', 'nan', '-1e-9', '-2', 'soon', '']),
    (finite_float, ['inf', '-inf', 'nan', 'later', '']),
]
READ = [
    (positive_float, [('12.5', 12.5), ('1e-3', 0.001)]),
    (non_negative_float, [('0', 0.0), ('2.5', 2.5)]),
    (finite_float, [('-4.5', -4.5), ('0', 0.0), ('1e3', 1000.0)]),
]


@pytest.mark.parametrize(
    'kind, text', [(kind, text) for kind, texts in REFUSED for text in texts]
)
def test_a_type_refuses_what_is_not_a_finite_number_in_its_range(kind, text):
    with pytest.raises(argparse.ArgumentTypeError):
        kind(text)


@pytest.mark.parametrize(
    'kind, text, value', [(kind, text, value) for kind, pairs in READ for text, value in pairs]
)
def test_a_type_reads_a_number_in_its_range(kind, text, value):
    assert kind(text) == value
