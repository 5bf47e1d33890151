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
Message definitions for rosbags typestores (bag I/O, no rclpy).

rosbags ships the core ROS 2 message types but not vision_msgs or foxglove_msgs.
:func:`interface_types` parses a package's ``.msg`` definitions into the dict that
``Typestore.register`` takes, so bags with ``vision_msgs/msg/Detection2DArray`` (the tracker's
output) or ``foxglove_msgs/msg/ImageAnnotations`` (its overlay) can be written and read without
ROS:

    from rosbags.typesys import Stores, get_typestore
    from iemd_ros.bags.types import interface_types
    typestore = get_typestore(Stores.ROS2_JAZZY)
    typestore.register(interface_types("vision_msgs"))

The definitions are read, in this order, from an explicit folder, from ``share/<package>/msg`` of
an installed package (the prefixes in AMENT_PREFIX_PATH, then this interpreter's prefix, where
scripts/build_interfaces.sh installs it), or from the repository's ``interfaces/<package>/msg``.
"""
from __future__ import annotations

import os
from pathlib import Path
import sys

__all__ = ['VENDORED', 'msg_dirs', 'find_msg_dir', 'interface_types', 'vision_msgs_types']

REPO_INTERFACES = Path(__file__).resolve().parents[2] / 'interfaces'
VENDORED = ('vision_msgs', 'foxglove_msgs')  # vendored packages whose types rosbags lacks


def msg_dirs(package: str) -> list[Path]:
    """
    Candidate folders of a package's ``.msg`` files, most authoritative first.

    Parameters
    ----------
    package : str
        The interface package.

    Returns
    -------
    list of Path
        ``share/<package>/msg`` of each prefix in AMENT_PREFIX_PATH and of this interpreter's
        prefix, then the repository's ``interfaces/<package>/msg``.

    """
    prefixes = [Path(p) for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    prefixes.append(Path(sys.prefix))
    dirs = [prefix / 'share' / package / 'msg' for prefix in prefixes]
    dirs.append(REPO_INTERFACES / package / 'msg')
    return dirs


def find_msg_dir(package: str) -> Path:
    """
    First folder of :func:`msg_dirs` that holds ``.msg`` files.

    Parameters
    ----------
    package : str
        The interface package.

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    FileNotFoundError
        When none holds them.

    """
    searched = msg_dirs(package)
    for folder in searched:
        if folder.is_dir() and any(folder.glob('*.msg')):
            return folder
    raise FileNotFoundError(
        f'no {package} .msg definitions found; searched: ' + ', '.join(map(str, searched))
    )


def interface_types(package: str, msg_dir: str | os.PathLike | None = None) -> dict:
    """
    Parse every ``<package>/msg/*.msg`` into ``{type name: definition}`` for rosbags.

    Parameters
    ----------
    package : str
        The interface package.
    msg_dir : str or path-like, optional
        Folder of the ``.msg`` files; default ``find_msg_dir(package)``.

    Returns
    -------
    dict
        Type name -> definition, as ``Typestore.register`` takes it.

    Raises
    ------
    ValueError
        When an explicit ``msg_dir`` is not a folder or holds no ``.msg`` file.
    FileNotFoundError
        When no ``msg_dir`` is given and no folder holds the definitions.

    """
    from rosbags.typesys import get_types_from_msg

    if msg_dir is None:
        folder = find_msg_dir(package)
    else:
        folder = Path(msg_dir)
        if not folder.is_dir():
            raise ValueError(f'{package} msg folder {folder} is not a directory')
    files = sorted(folder.glob('*.msg'))
    if not files:
        raise ValueError(f'{package} msg folder {folder} holds no .msg file')
    types: dict = {}
    for path in files:
        types.update(
            get_types_from_msg(path.read_text(encoding='utf-8'), f'{package}/msg/{path.stem}')
        )
    return types


def vision_msgs_types(msg_dir: str | os.PathLike | None = None) -> dict:
    """
    :func:`interface_types` of vision_msgs.

    Parameters
    ----------
    msg_dir : str or path-like, optional
        Folder of the ``.msg`` files.

    Returns
    -------
    dict
        Type name -> definition.

    """
    return interface_types('vision_msgs', msg_dir)
