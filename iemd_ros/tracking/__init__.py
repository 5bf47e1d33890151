"""The ROS-free iEMD tracker (the paper's Algorithms 1-2 with discriminative models around them)."""
from iemd_ros.tracking.config import TrackerConfig
from iemd_ros.tracking.tracker import Cause, IemdTracker, TrackResult

__all__ = ["IemdTracker", "TrackerConfig", "TrackResult", "Cause"]
