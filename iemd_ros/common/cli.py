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


def finite_float(text: str) -> float:
    """
    Return ``text`` as a finite number: an argparse ``type``.

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
        For text that is not a number, or a number not finite.

    """
    return _finite_float(text)


def positive_float(text: str) -> float:
    """
    Return ``text`` as a finite number > 0: an argparse ``type``.

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
        For text that is not a number, or a number not finite and > 0.

    """
    return _finite_float(text, lambda v: v > 0, ' > 0')


def non_negative_float(text: str) -> float:
    """
    Return ``text`` as a finite number >= 0: an argparse ``type``.

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
        For text that is not a number, or a number not finite and >= 0.

    """
    return _finite_float(text, lambda v: v >= 0, ' >= 0')


def _finite_float(
    text: str, holds: Callable[[float], bool] | None = None, bound: str = ''
) -> float:
    """Return ``text`` as a finite number that ``holds`` accepts (``bound`` says so in words)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a number: {text!r}') from None
    if not (math.isfinite(v) and (holds is None or holds(v))):
        raise argparse.ArgumentTypeError(f'must be a finite number{bound}, got {text!r}')
    return v


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
