"""iemd_ros: gyro-aided iEMD visual tracking (Yao & Dani) for ROS 2.

The tracker core is ROS-free: ``from iemd_ros import IemdTracker, TrackerConfig``.  The names are loaded on first
use, so that importing one sub-package (``iemd_ros.gyro``, ``iemd_ros.bags``) does not load the tracker.
"""
import importlib

__all__ = ["IemdTracker", "TrackerConfig", "TrackResult", "Cause"]


def __getattr__(name: str):
    if name in __all__:
        return getattr(importlib.import_module("iemd_ros.tracking"), name)
    raise AttributeError(f"module 'iemd_ros' has no attribute {name!r}")
