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
The rclpy examples' spin-and-shut-down pattern, kept light (rclpy only) for small helper processes.

SIGINT and SIGTERM make rclpy shut the context down from its signal handler, at any moment: between
two waits ``rclpy.spin`` ends with ExternalShutdownException, but in the middle of one it can raise
RCLError ("failed to initialize wait set: the given context is not valid"), and so can the node's
own calls.  Both are a clean stop.

rclpy's handler then calls the handler it found, Python's, which raises KeyboardInterrupt wherever
the main thread happens to be: under ``ros2 launch`` the node gets the terminal's SIGINT and
launch's forwarded one, and the second could land in the middle of the clean-up.
:func:`quiet_interrupts` (before ``rclpy.init``) makes Python's SIGINT handler a no-op, so SIGINT
only ever shuts the context down.
"""
from __future__ import annotations

import signal
import threading

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

__all__ = ['spin_until_shutdown', 'stopped_by_shutdown', 'quiet_interrupts']


def quiet_interrupts() -> None:
    """
    Make SIGINT raise no KeyboardInterrupt (call it from the main thread before ``rclpy.init``).

    rclpy's signal handler, installed by ``rclpy.init`` on top of this one, still shuts the context
    down on every SIGINT, which ends spinning cleanly; this handler, which it calls next, does
    nothing.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _no_interrupt)


def _no_interrupt(signum, frame) -> None:
    """SIGINT after rclpy's handler has shut the context down: nothing more to do."""


def stopped_by_shutdown(exc: BaseException, context=None) -> bool:
    """
    Whether ``exc`` is how a shutdown (Ctrl-C, SIGTERM, ``rclpy.shutdown``) ended a call.

    Parameters
    ----------
    exc : BaseException
        What the call raised.
    context : rclpy.context.Context, optional
        The context of the call (default: rclpy's default context).

    Returns
    -------
    bool
        True for KeyboardInterrupt and ExternalShutdownException, and for an RCLError once the
        context is shut down.

    """
    if isinstance(exc, (KeyboardInterrupt, ExternalShutdownException)):
        return True
    context = context if context is not None else rclpy.get_default_context()
    return isinstance(exc, _rclpy.RCLError) and not context.ok()


def spin_until_shutdown(node) -> None:
    """
    Spin ``node`` until Ctrl-C, SIGTERM or an external shutdown.

    Then destroy it and shut rclpy down.

    Once spinning has ended, further SIGINT and SIGTERM are ignored (the process is stopping
    already).

    Parameters
    ----------
    node : rclpy.node.Node
        The node.

    Raises
    ------
    Exception
        What spinning raised, unless it was the shutdown (:func:`stopped_by_shutdown`).

    """
    try:
        rclpy.spin(node)
    except BaseException as exc:
        if not stopped_by_shutdown(exc, node.context):
            raise
    finally:
        _ignore_stop_signals()
        try:
            node.destroy_node()
        except _rclpy.RCLError:
            if node.context.ok():
                raise
        rclpy.try_shutdown(context=node.context)


def _ignore_stop_signals() -> None:
    """
    Ignore further SIGINT / SIGTERM while the node is taken down.

    (a bounded wait: its worker is joined for at most 5 s): a second Ctrl-C, or launch's SIGTERM
    after its SIGINT, would otherwise interrupt the clean-up with a traceback.  Signal handlers can
    only be set from the main thread.
    """
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
