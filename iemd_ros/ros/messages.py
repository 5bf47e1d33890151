"""rclpy message classes by type name, and the :class:`~iemd_ros.messages.outputs.MessageFactory` over them."""
from __future__ import annotations

import importlib
from functools import lru_cache

__all__ = ["message_class", "RclpyMessages", "RCLPY_MESSAGES"]


@lru_cache(maxsize=None)
def message_class(msgtype: str):
    """rclpy message class of ``pkg/msg/Name`` (from the installed message package); ValueError when that
    package is not installed."""
    pkg, kind, name = msgtype.split("/")
    try:
        return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
    except (ImportError, AttributeError):
        raise ValueError(f"message type {msgtype} is not installed for rclpy (package {pkg})") from None


class RclpyMessages:
    """Builds rclpy messages by type name and fields (the node's outputs, :mod:`iemd_ros.messages.outputs`)."""

    def __call__(self, msgtype: str, **fields):
        return message_class(msgtype)(**fields)

    @staticmethod
    def byte(value: int) -> bytes:
        return bytes([int(value)])


RCLPY_MESSAGES = RclpyMessages()
