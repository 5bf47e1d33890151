"""iemd_ros: gyro-aided iEMD visual tracking (Yao & Dani) for ROS 2.

The tracker core is ROS-free: ``from iemd_ros import IemdTracker, TrackerConfig``.
"""
from iemd_ros.tracking import Cause, IemdTracker, TrackerConfig, TrackResult

__all__ = ["IemdTracker", "TrackerConfig", "TrackResult", "Cause"]
