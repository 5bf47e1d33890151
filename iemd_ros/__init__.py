"""iemd_ros: gyro-aided iEMD visual tracking (Yao & Dani) for ROS 2."""
