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
The package's layers.

A sub-package imports only from the layers below it, and only ``ros`` touches rclpy.
"""
import ast
import json
import subprocess
import sys

from helpers import REPO
import pytest

PACKAGE = REPO / 'iemd_ros'
# Bottom to top.  A sub-package may import itself and the layers below it, never a peer of its own
# layer.
LAYERS = [
    {'common'},                  # boxes, parameter declarations, the command-line convention
    {'tracking', 'gyro'},        # the ROS-free core
    # messages' contents -> sync -> prediction -> tracker; files of real footage
    {'pipeline', 'datasets'},
    {'messages'},                # ROS messages <-> numpy and the outputs, for any message library
    {'bags'},                    # rosbag files (rosbags, no rclpy)
    {'ros'},                     # the rclpy adapter: node, parameters, live play
    {'evaluation'},              # metrics and runs against ground truth
    {'apps'},                    # the commands
]
LEVEL = {name: i for i, layer in enumerate(LAYERS) for name in layer}
# outside ros/, the only module that may import rclpy (it plays live)
ROS_MODULES = {'iemd_ros.apps.play'}


def _modules():
    for path in sorted(PACKAGE.rglob('*.py')):
        rel = path.relative_to(REPO).with_suffix('')
        parts = rel.parts[:-1] if rel.name == '__init__' else rel.parts
        yield '.'.join(parts), path


def _imports(path, module: str) -> set[str]:
    """Every module ``path`` imports (absolute, relative and inside functions), as dotted names."""
    names = set()
    package = module if path.name == '__init__.py' else module.rpartition('.')[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                anchor = package.split('.')[: len(package.split('.')) - node.level + 1]
                base = '.'.join(anchor + ([base] if base else []))
            names.add(base)
    return names


def _layer(module: str) -> str | None:
    parts = module.split('.')
    return parts[1] if len(parts) > 1 and parts[0] == 'iemd_ros' else None


def test_every_sub_package_has_a_layer():
    subs = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / '__init__.py').exists()}
    assert subs == set(LEVEL), subs ^ set(LEVEL)
    assert not [p.name for p in PACKAGE.glob('*.py') if p.name != '__init__.py'], (
        'modules belong in sub-packages'
    )


def test_no_module_imports_a_layer_above_or_beside_it():
    wrong = []
    for module, path in _modules():
        own = _layer(module)
        if own is None:
            continue
        for imported in _imports(path, module):
            other = _layer(imported)
            if other is not None and other != own and LEVEL[other] >= LEVEL[own]:
                wrong.append(f'{module} imports {imported}')
    assert not wrong, '\n'.join(wrong)


def test_the_checker_sees_an_upward_import(tmp_path):
    """The static check is not vacuous: an import of the pipeline from the tracker is caught."""
    bad = tmp_path / 'bad.py'
    bad.write_text('def f():\n    from iemd_ros.pipeline import TrackingPipeline\n')
    imported = _imports(bad, 'iemd_ros.tracking.bad')
    assert (
        'iemd_ros.pipeline' in imported and LEVEL[_layer('iemd_ros.pipeline')] > LEVEL['tracking']
    )


@pytest.mark.parametrize('layer', sorted(LEVEL))
def test_importing_a_layer_loads_nothing_above_it_and_no_rclpy_outside_ros(layer):
    """
    Each sub-package's modules imported in a fresh interpreter.

    No module of a layer above or beside it is loaded, and rclpy only by ros/ (and the live
    player).
    """
    modules = [m for m, _ in _modules() if _layer(m) == layer]
    code = (
        'import importlib, json, sys\n'
        f'for m in {modules!r}:\n    importlib.import_module(m)\n'
        'print(json.dumps(sorted(sys.modules)))'
    )
    out = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, cwd=REPO, timeout=120
    )
    assert out.returncode == 0, out.stderr
    loaded = json.loads(out.stdout.strip().splitlines()[-1])
    above = {
        _layer(m)
        for m in loaded
        if _layer(m) and _layer(m) != layer and LEVEL[_layer(m)] >= LEVEL[layer]
    }
    assert not above, f'importing {layer} loads {sorted(above)}'
    if layer not in ('ros', 'apps'):
        assert 'rclpy' not in loaded, f'importing {layer} loads rclpy'
    if layer == 'apps':
        without_play = [m for m in modules if m not in ROS_MODULES]
        code = (
            'import importlib, sys\n'
            f'for m in {without_play!r}:\n    importlib.import_module(m)\n'
            "print('rclpy' in sys.modules)"
        )
        out = subprocess.run(
            [sys.executable, '-c', code], capture_output=True, text=True, cwd=REPO, timeout=120
        )
        assert out.stdout.strip().splitlines()[-1] == 'False', 'the offline commands load rclpy'
