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
Command-line plumbing shared by every ``iemd-*`` command.

Bad input gives one line and exit 2.
"""
from __future__ import annotations

import argparse
from collections.abc import Callable
import math
import sys

__all__ = [
    'CliParser',
    'FiniteFloat',
    'UsageError',
    'cli_main',
    'finite_float',
    'non_negative_float',
    'one_line',
    'positive_float',
    'split_ros_args',
]


class UsageError(Exception):
    """
    A command-line usage error (:meth:`CliParser.error`).

    Which :func:`cli_main` reports in one line.
    """

    pass


class CliParser(argparse.ArgumentParser):
    """
    ``argparse.ArgumentParser`` whose errors raise :class:`UsageError`.

    It does not print the usage and exit.

    It takes the parameters of :class:`argparse.ArgumentParser`.
    """

    def error(self, message: str):  # one readable line, exit 2 (no usage dump)
        """
        Report a usage error as one readable line, exit 2 (no usage dump).

        Through :func:`cli_main`.

        Parameters
        ----------
        message : str
            The error.

        Raises
        ------
        UsageError
            Always, with ``message``.

        """
        raise UsageError(message)


class FiniteFloat:
    """
    A finite number, within a bound when it has one.

    Called with an argument's text it is an argparse ``type``; :meth:`check` refuses the same
    values passed to a library function, so that a command and its library refuse alike.

    Parameters
    ----------
    bound : str, optional
        The bound in words, as the error says it (``' > 0'``); '' for none.
    holds : callable, optional
        Whether a finite value is within the bound; None for any.

    Examples
    --------
    >>> positive_float('2.5')
    2.5
    >>> positive_float.check('--rate', 0.0)
    Traceback (most recent call last):
    ...
    ValueError: --rate must be a finite number > 0, got 0.0

    """

    def __init__(self, bound: str = '', holds: Callable[[float], bool] | None = None):
        self.bound, self.holds = bound, holds

    def __call__(self, text: str) -> float:
        """
        Return ``text`` as such a number.

        Parameters
        ----------
        text : str
            The argument.

        Returns
        -------
        float
            Its value.

        Raises
        ------
        argparse.ArgumentTypeError
            For text that is not a number, or a number not finite or outside the bound.

        """
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'not a number: {text!r}') from None
        if not self._accepts(v):
            raise argparse.ArgumentTypeError(f'must be a finite number{self.bound}, got {text!r}')
        return v

    def check(self, name: str, value: float) -> float:
        """
        Return ``value`` if it is such a number.

        Parameters
        ----------
        name : str
            What the value is, as the error names it (the command's option).
        value : float
            The value.

        Returns
        -------
        float
            ``value``.

        Raises
        ------
        ValueError
            For a value not finite or outside the bound.

        """
        if not self._accepts(value):
            raise ValueError(f'{name} must be a finite number{self.bound}, got {value}')
        return value

    def _accepts(self, v: float) -> bool:
        return math.isfinite(v) and (self.holds is None or self.holds(v))


#: Any finite number.
finite_float = FiniteFloat()
#: A finite number > 0.
positive_float = FiniteFloat(' > 0', lambda v: v > 0)
#: A finite number >= 0.
non_negative_float = FiniteFloat(' >= 0', lambda v: v >= 0)


def one_line(exc: BaseException) -> str:
    """
    Return an exception's message on one line of at most 300 characters.

    Parameters
    ----------
    exc : BaseException
        The exception.

    Returns
    -------
    str
        Its message with the whitespace collapsed (its type's name when empty), cut with "..." at
        300 characters.

    """
    text = ' '.join(str(exc).split()) or type(exc).__name__
    return text if len(text) < 300 else text[:297] + '...'


def split_ros_args(argv: list[str] | None) -> tuple[list[str], list[str]]:
    """
    Split ``argv`` into the command's own arguments and the ``--ros-args ...`` tail.

    As ``ros2 run`` passes them.

    Parameters
    ----------
    argv : list of str or None
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    own : list of str
        The arguments before ``--ros-args``.
    ros : list of str
        ``--ros-args`` and the arguments after it (empty without it).

    """
    args = list(sys.argv[1:] if argv is None else argv)
    cut = args.index('--ros-args') if '--ros-args' in args else len(args)
    return args[:cut], args[cut:]


def cli_main(prog: str, body: Callable[[], int]) -> int:
    """
    Run ``body``; bad arguments / files (ValueError, OSError, usage errors) -> one stderr line.

    Exit 2.

    Parameters
    ----------
    prog : str
        The command's name, which starts the error line.
    body : callable
        The command; returns its exit status.

    Returns
    -------
    int
        ``body``'s exit status, 2 for bad input, 130 when interrupted.

    """
    try:
        return body()
    except (UsageError, ValueError, OSError) as exc:
        print(f'{prog}: error: {one_line(exc)}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f'{prog}: interrupted', file=sys.stderr)
        return 130
