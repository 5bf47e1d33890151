"""ament_python package for iemd_ros (works with colcon and with plain pip)."""
from glob import glob

from setuptools import find_packages, setup

PACKAGE = "iemd_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(exclude=["test", "test.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/config", glob("config/*")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="iemd_ros maintainers",
    maintainer_email="maintainers@iemd-ros.org",
    description="Gyro-aided iEMD visual tracking for ROS 2 Jazzy",
    license="BSD-3-Clause",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "iemd-demo = iemd_ros.demo:main",
            "iemd-eval = iemd_ros.evaluation:main",
        ],
    },
)
