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
ROS 2 parameter files read as a node reads them.

(``ros__parameters`` of wildcard and named sections).
"""
from __future__ import annotations

from pathlib import Path

__all__ = ['read_parameter_file', 'NODE_NAME']

NODE_NAME = 'iemd_tracker'  # the tracker node's default name, as parameter files name it
_WILDCARD_NODES = ('*', '**')  # node names of a parameter file's sections that apply to every node


def read_parameter_file(path, node_name: str = NODE_NAME) -> dict | None:
    """
    Return the parameters of the node ``node_name`` in the YAML file ``path``.

    By dotted name (``tracker.n_iter``).

    The ``ros__parameters`` of wildcard sections (``/**``) apply, then those of the node's own
    section (under namespaces too), parameter by parameter as rcl merges them.  A file with one
    named section is read whatever that name (a renamed node's file).

    Parameters
    ----------
    path : str or path-like
        The YAML file.
    node_name : str, optional
        The node whose section is read.

    Returns
    -------
    dict or None
        The merged parameters; None when the file has no ``ros__parameters`` section (a plain
        mapping, whose contents :func:`read_yaml` returns).

    Raises
    ------
    ValueError
        For a file that cannot be read, or has several named sections and none for the node.

    """
    values = read_yaml(path)
    sections = list(_sections(values))
    if not sections:
        return None
    wildcard = [params for _, node, params in sections if node in _WILDCARD_NODES]
    named = [
        (where, node, params) for where, node, params in sections if node not in _WILDCARD_NODES
    ]
    if len(named) > 1:
        own = [section for section in named if section[1] == node_name]
        if len(own) != 1:
            raise ValueError(
                f'config {path} holds parameters of {len(named)} nodes '
                f'({", ".join(where for where, _, _ in named)}) and not one named {node_name}'
            )
        named = own
    merged: dict = {}
    for params in wildcard + [params for _, _, params in named]:
        if not isinstance(params, dict):
            raise ValueError(f'config {path}: ros__parameters must be a mapping, got {params!r}')
        merged.update(_dotted(params))
    return merged


def read_yaml(path) -> dict:
    """
    Return a YAML file holding a mapping.

    Parameters
    ----------
    path : str or path-like
        The YAML file.

    Returns
    -------
    dict
        Its contents ({} for an empty file).

    Raises
    ------
    ValueError
        Naming the file, when it cannot be read or does not hold a mapping.

    """
    import yaml  # noqa: PLC0415 - only the command-line tools and the node read parameter files

    path = Path(path)
    try:
        values = yaml.safe_load(path.read_text()) or {}
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ValueError(f'cannot read config {path}: {exc}') from None
    if not isinstance(values, dict):
        raise ValueError(f'config {path} must be a mapping')
    return values


def _sections(tree: dict, names: tuple = ()):
    """
    (node path, node name, its ``ros__parameters``) of every section.

    Namespaces included (the node name is the path's last part: ``**`` or ``*`` for wildcards).
    """
    for key, value in tree.items():
        if key == 'ros__parameters':
            where = '/'.join(names)
            yield where, where.rsplit('/', 1)[-1], value
        elif isinstance(value, dict):
            yield from _sections(value, names + (str(key),))


def _dotted(params: dict, prefix: str = '') -> dict:
    """
    Nested groups flattened to dotted names.

    (``tracker: {n_iter: 7}`` -> ``tracker.n_iter: 7``).
    """
    flat: dict = {}
    for key, value in params.items():
        if isinstance(value, dict):
            flat.update(_dotted(value, f'{prefix}{key}.'))
        else:
            flat[f'{prefix}{key}'] = value
    return flat
