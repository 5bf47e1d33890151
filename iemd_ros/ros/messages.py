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
rclpy message classes by type name.

And the :class:`~iemd_ros.messages.outputs.MessageFactory` over them.
"""
from __future__ import annotations

from functools import lru_cache
import importlib

__all__ = ['message_class', 'RclpyMessages', 'RCLPY_MESSAGES']


@lru_cache(maxsize=None)
def message_class(msgtype: str):
    """
    Return the rclpy message class of ``pkg/msg/Name`` (from the installed message package).

    ValueError when that package is not installed.
    """
    pkg, kind, name = msgtype.split('/')
    try:
        return getattr(importlib.import_module(f'{pkg}.{kind}'), name)
    except (ImportError, AttributeError):
        raise ValueError(
            f'message type {msgtype} is not installed for rclpy (package {pkg})'
        ) from None


class RclpyMessages:
    """
    Builds rclpy messages by type name and fields.

    (the node's outputs, :mod:`iemd_ros.messages.outputs`).
    """

    def __call__(self, msgtype: str, **fields):
        return message_class(msgtype)(**fields)

    @staticmethod
    def byte(value: int) -> bytes:
        return bytes([int(value)])


RCLPY_MESSAGES = RclpyMessages()
