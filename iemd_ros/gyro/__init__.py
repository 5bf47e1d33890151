"""The ROS-free gyro prior (paper, section 5.2): IMU buffer and integration, lens model, K R^T K^-1 prediction."""
from iemd_ros.gyro.camera import CameraModel
from iemd_ros.gyro.config import GyroConfig
from iemd_ros.gyro.predictor import GyroPrediction, GyroPredictor

__all__ = ["CameraModel", "GyroConfig", "GyroPrediction", "GyroPredictor"]
