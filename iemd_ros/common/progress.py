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
A one-line progress bar on stderr.

Shared by the commands that run many steps (bags, evaluation, batches).
"""
from __future__ import annotations

from contextlib import contextmanager
import sys

__all__ = ['Progress']

CLEAR_LINE = '\x1b[K'  # ANSI: erase to the end of the line


class Progress:
    """
    A one-line progress bar on stderr (only when stderr is a terminal; ``enabled`` overrides).

    Parameters
    ----------
    total : int
        Number of steps (0: no bar).
    label : str, optional
        Text before the bar.
    enabled : bool, optional
        Show the bar (default: when the stream is a terminal).
    stream : file, optional
        Where the bar goes (default ``sys.stderr``).

    """

    def __init__(self, total: int, label: str = '', enabled: bool | None = None, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = (self.stream.isatty() if enabled is None else enabled) and total > 0
        self.total, self.label, self.n, self._last, self._line = int(total), label, 0, -1, ''

    def update(self, n: int = 1, note: str = '') -> None:
        """
        Advance the bar.

        Parameters
        ----------
        n : int, optional
            Steps done.
        note : str, optional
            Text after the bar.

        """
        self.n += n
        if not self.enabled:
            return
        pct = int(100 * self.n / self.total)
        if pct == self._last and self.n < self.total:
            return
        self._last = pct
        filled = int(30 * self.n / self.total)
        self._line = (
            f'{self.label} [{"#" * filled}{"." * (30 - filled)}] {self.n}/{self.total} {note}'
        )
        self.stream.write(f'\r{CLEAR_LINE}{self._line}')
        self.stream.flush()

    @contextmanager
    def above(self):
        """
        Yield a block whose output goes above the bar.

        The bar's line is cleared on entry and drawn again on exit.

        Yields
        ------
        None

        """
        if self.enabled:
            self.stream.write(f'\r{CLEAR_LINE}')
            self.stream.flush()
        try:
            yield
        finally:
            if self.enabled and self._line:
                self.stream.write(self._line)
                self.stream.flush()

    def close(self) -> None:
        """End the bar's line."""
        if self.enabled:
            self.stream.write('\n')
            self.stream.flush()
