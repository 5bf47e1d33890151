"""Plain helpers shared by several test modules (no fixtures, no ROS imports).

Imported as a top-level module (``from helpers import ...``): pytest's default ``prepend`` import
mode puts this folder, which holds conftest.py and no __init__.py, on ``sys.path``.
"""
from __future__ import annotations

import numpy as np

# The CMU desk camera (cmu_hwangbo_desk/derived_camera_info.yaml): 640x480, a small skew, plumb_bob.
DESK_K_DATA = (570.246, -0.100721, 309.408, 0, 569.324, 217.996, 0, 0, 1)
DESK_D = (-0.346217, 0.128289, 0, 0, 0)
DESK_K = np.reshape(DESK_K_DATA, (3, 3))
DESK_K.setflags(write=False)        # CameraModel keeps the array it is given: no test may change it
DESK_INFO = dict(image_width=640, image_height=480,
                 camera_matrix=dict(rows=3, cols=3, data=DESK_K_DATA),
                 distortion_model="plumb_bob", distortion_coefficients=dict(rows=1, cols=5, data=DESK_D))
