"""The rclpy examples' spin-and-shut-down pattern, kept light (rclpy only) for small helper processes."""
from __future__ import annotations

import rclpy
from rclpy.executors import ExternalShutdownException


def spin_until_shutdown(node) -> None:
    """Spin ``node`` until Ctrl-C or an external shutdown, then destroy it and shut rclpy down."""
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
