"""A one-line progress bar on stderr, shared by the commands that run many steps (bags, evaluation, batches)."""
from __future__ import annotations

import sys
from contextlib import contextmanager

__all__ = ["Progress"]

CLEAR_LINE = "\x1b[K"  # ANSI: erase to the end of the line


class Progress:
    """A one-line progress bar on stderr (only when stderr is a terminal; ``enabled`` overrides).

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

    def __init__(self, total: int, label: str = "", enabled: bool | None = None, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = (self.stream.isatty() if enabled is None else enabled) and total > 0
        self.total, self.label, self.n, self._last, self._line = int(total), label, 0, -1, ""

    def update(self, n: int = 1, note: str = "") -> None:
        """Advance the bar.

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
        self._line = f"{self.label} [{'#' * filled}{'.' * (30 - filled)}] {self.n}/{self.total} {note}"
        self.stream.write(f"\r{CLEAR_LINE}{self._line}")
        self.stream.flush()

    @contextmanager
    def above(self):
        """A block whose output goes above the bar: the bar's line is cleared on entry and drawn again on exit.

        Yields
        ------
        None
        """
        if self.enabled:
            self.stream.write(f"\r{CLEAR_LINE}")
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
            self.stream.write("\n")
            self.stream.flush()
