"""The ROS-free pipeline: messages' contents in (images, IMU rates, camera model), tracked boxes and diagnostics out."""
from iemd_ros.pipeline.config import PipelineConfig
from iemd_ros.pipeline.diagnostics import Level, Part, Status, statuses
from iemd_ros.pipeline.imu_wait import ImuWait
from iemd_ros.pipeline.pipeline import TrackingPipeline
from iemd_ros.pipeline.results import DEFAULT_TARGET, INIT_REASON, ExtrinsicSource, FrameResult, Rejection, TrackState

__all__ = ["PipelineConfig", "TrackingPipeline", "FrameResult", "TrackState", "Rejection", "INIT_REASON", "ImuWait",
           "Level", "Part", "Status", "statuses", "DEFAULT_TARGET", "ExtrinsicSource"]
