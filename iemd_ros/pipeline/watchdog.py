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
A call that may never return, waited for at most a time.

The pipeline's watchdog on the tracker update.
"""
from __future__ import annotations

import threading

__all__ = ['Watchdog', 'Abandoned']


class Abandoned(Exception):
    """
    The call did not return in time.

    Its thread was left to it (it ends when the call returns, if ever).

    Parameters
    ----------
    message : str
        What happened.
    ran : bool
        False when the call was not even started, because too many abandoned calls are still
        running.

    """

    def __init__(self, message: str, ran: bool = True):
        super().__init__(message)
        self.ran = ran


class _Runner(threading.Thread):
    """A daemon thread running one call at a time for :class:`Watchdog`."""

    def __init__(self):
        super().__init__(name='iemd_tracker_update', daemon=True)
        self.cond = threading.Condition()
        self.call = None
        self.done = False
        self.result = self.error = None
        self.abandoned = False

    def run(self) -> None:
        while True:
            with self.cond:
                self.cond.wait_for(lambda: self.call is not None or self.abandoned)
                if self.abandoned:
                    return
                call = self.call
            try:
                result, error = call(), None
            except BaseException as exc:  # handed to the caller, raised there
                result, error = None, exc
            with self.cond:
                self.call, self.result, self.error, self.done = None, result, error, True
                self.cond.notify_all()


class Watchdog:
    """
    Runs calls on a thread of its own and waits at most ``timeout_s`` for each.

    A call that overruns is abandoned: :meth:`run` raises :class:`Abandoned`, the thread is left to
    the call (a daemon: it does not keep the process alive) and the next call gets a new thread.
    Python cannot stop a thread, so an abandoned call still runs (and uses a core) until it
    returns, if it ever does; only code that releases the GIL (OpenCV, POT) lets the caller go on
    meanwhile.  While ``max_running`` abandoned calls still run, a new call is not started
    (:class:`Abandoned` with ``ran`` False), so that they cannot take every core.

    Parameters
    ----------
    max_running : int, optional
        Abandoned calls that may still run while new ones start.

    """

    def __init__(self, max_running: int = 2):
        self._runner: _Runner | None = None
        self._left: list[_Runner] = []   # the threads of abandoned calls
        self.max_running = max_running
        self.abandoned = 0  # calls abandoned so far

    def run(self, call, timeout_s: float):
        """
        Return ``call()``'s result, or :class:`Abandoned` once it has run for ``timeout_s``.

        Parameters
        ----------
        call : callable
            Called without arguments on the watchdog's thread.
        timeout_s : float
            The longest wait, s.

        Returns
        -------
        object
            What ``call`` returned.

        Raises
        ------
        Abandoned
            When ``call`` has not returned within ``timeout_s``, or was not started (``ran`` False)
            because ``max_running`` abandoned calls still run.
        Exception
            What ``call`` raised.

        """
        self._left = [r for r in self._left if r.is_alive()]
        if len(self._left) >= self.max_running:
            raise Abandoned(
                f'not started: {len(self._left)} abandoned calls are still running', ran=False
            )
        runner = self._runner
        if runner is None:
            runner = self._runner = _Runner()
            runner.start()
        with runner.cond:
            runner.call, runner.done = call, False
            runner.cond.notify_all()
            if not runner.cond.wait_for(lambda: runner.done, timeout_s):
                runner.abandoned = True  # the thread ends when the call returns
                self._runner = None
                self._left.append(runner)
                self.abandoned += 1
                raise Abandoned(f'no answer within {timeout_s * 1e3:.0f} ms')
            result, error = runner.result, runner.error
            runner.result = runner.error = None
        if error is not None:
            raise error
        return result

    def close(self) -> None:
        """End the idle thread (an abandoned one ends when its call returns)."""
        runner, self._runner = self._runner, None
        if runner is not None:
            with runner.cond:
                runner.abandoned = True
                runner.cond.notify_all()
