"""Command-line plumbing shared by every ``iemd-*`` command: bad input gives one line and exit 2."""
from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

__all__ = ["CliParser", "UsageError", "cli_main", "one_line", "split_ros_args"]


class UsageError(Exception):
    pass


class CliParser(argparse.ArgumentParser):
    def error(self, message: str):  # one readable line, exit 2 (no usage dump)
        raise UsageError(message)


def one_line(exc: BaseException) -> str:
    """An exception's message on one line of at most 300 characters."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) < 300 else text[:297] + "..."


def split_ros_args(argv: list[str] | None) -> tuple[list[str], list[str]]:
    """(own arguments, ``--ros-args ...`` tail) of ``argv`` (default ``sys.argv[1:]``), as ``ros2 run`` passes them."""
    args = list(sys.argv[1:] if argv is None else argv)
    cut = args.index("--ros-args") if "--ros-args" in args else len(args)
    return args[:cut], args[cut:]


def cli_main(prog: str, body: Callable[[], int]) -> int:
    """Run ``body``; bad arguments / files (ValueError, OSError, usage errors) -> one stderr line, exit 2."""
    try:
        return body()
    except (UsageError, ValueError, OSError) as exc:
        print(f"{prog}: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
