# Copyright 2026 iemd_ros authors
# SPDX-License-Identifier: BSD-3-Clause
#
# Redistribution and use in source and binary forms, with or without
# modification, are permitted provided that the following conditions are met:
#
#    * Redistributions of source code must retain the above copyright
#      notice, this list of conditions and the following disclaimer.
#
#    * Redistributions in binary form must reproduce the above copyright
#      notice, this list of conditions and the following disclaimer in the
#      documentation and/or other materials provided with the distribution.
#
#    * Neither the name of the iemd_ros authors nor the names of its
#      contributors may be used to endorse or promote products derived from
#      this software without specific prior written permission.
#
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"
# AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE
# IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE
# ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE
# LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR
# CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF
# SUBSTITUTE GOODS OR SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS
# INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN
# CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE)
# ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE
# POSSIBILITY OF SUCH DAMAGE.

"""
The ament_python package manifest.

Valid for catkin_pkg (so colcon builds it as a ROS package), and every module the package imports
is declared (package.xml) or pip-installed (requirements.txt).
"""
import ast
import re
import sys

from catkin_pkg import package as catkin_package
from helpers import REPO

# Top-level module -> its rosdep key.
ROSDEP_KEYS = {
    'cv2': 'python3-opencv',
    'numpy': 'python3-numpy',
    'yaml': 'python3-yaml',
    'matplotlib': 'python3-matplotlib',
    'scipy': 'python3-scipy',
    'numba': 'python3-numba',
    'rosbags': 'python3-rosbags-pip',
}
# Top-level module -> its PyPI distribution (no rosdep key for Jazzy's platforms; distributed is
# imported only by --cluster, iemd_ros.common.parallel).
PIP_ONLY = {'ot': 'POT', 'distributed': 'distributed'}


def _imported_modules() -> set[str]:
    """
    Top-level modules imported anywhere in iemd_ros/ (also inside functions).

    Absolute imports only.
    """
    names = set()
    for path in (REPO / 'iemd_ros').rglob('*.py'):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names.update(alias.name.split('.')[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names.add(node.module.split('.')[0])
    return names


def test_manifest_is_a_valid_format_3_ament_python_package():
    package = catkin_package.parse_package(REPO)
    package.validate()  # raises InvalidPackage, e.g. for a maintainer email catkin_pkg rejects
    assert package.package_format == 3 and package.name == 'iemd_ros'
    assert package.get_build_type() == 'ament_python'
    setup_call = next(node for node in ast.walk(ast.parse((REPO / 'setup.py').read_text()))
                      if isinstance(node, ast.Call) and getattr(node.func, 'id', None) == 'setup')
    keywords = {
        k.arg: k.value.value for k in setup_call.keywords if isinstance(k.value, ast.Constant)
    }
    assert keywords['version'] == package.version
    assert keywords['maintainer_email'] == package.maintainers[0].email


def test_every_imported_module_is_declared():
    package = catkin_package.parse_package(REPO)
    declared = {
        d.name for d in package.build_depends + package.exec_depends + package.build_export_depends
    }
    requirements = {
        re.split(r'[\[=<>]', line)[0].strip().lower()
        for line in (REPO / 'requirements.txt').read_text().splitlines()
        if line.strip() and not line.startswith('#')
    }
    stdlib = set(sys.stdlib_module_names) | {'iemd_ros'}
    third_party = _imported_modules() - stdlib
    # the scan sees them
    assert {'rclpy', 'sensor_msgs', 'vision_msgs', 'cv2', 'numba', 'ot'} <= third_party
    for module in sorted(third_party):
        if module in PIP_ONLY:
            assert PIP_ONLY[module].lower() in requirements, module
        else:
            assert ROSDEP_KEYS.get(module, module) in declared, (
                f'{module} is imported but not in package.xml'
            )
    for key in (
        'rclpy',
        'sensor_msgs',
        'vision_msgs',
        'diagnostic_msgs',
        'std_srvs',
        'python3-numpy',
        'python3-scipy',
        'python3-opencv',
    ):
        assert key in declared, key
