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
Parameters declared once.

A configuration field carries its meaning, unit, range and the paper's equation.

A configuration is a dataclass whose fields are made with :func:`param`::

    @dataclass
    class TrackerConfig:
        n_iter: int = param(20, "maximum descent iterations per start", range=(0, 500),
                            eq="Algorithm 1")

        def __post_init__(self):
            coerce(self)       # types and ranges of every field, from its Spec

The node's parameter descriptors, the parameter file and the parameter table of the docs are built
from these declarations (:mod:`iemd_ros.ros.parameters`); nothing else restates a range or a
meaning.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, MISSING
import enum
import math
import typing

import numpy as np

__all__ = ['Spec', 'param', 'specs', 'coerce', 'Choice', 'number_text']


class Choice(str, enum.Enum):
    """
    Base of a parameter's choices.

    An Enum whose values are the strings a parameter file holds.
    """

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Spec:
    """
    What a parameter means and which values it takes.

    Attributes
    ----------
    doc : str
        Its meaning, one line.
    unit : str
        Unit of its values ("" for none).
    range : tuple of float or None
        Closed interval ``[low, high]`` of its value, or of every element of a sequence.
    length : int or None
        Number of elements of a sequence parameter (None: a scalar).
    eq : str
        The paper's equation, algorithm or section it implements ("" when it is not the paper's).
    decision : str
        Anchor in ``docs/decisions.md`` of the measurement behind its default.
    read_only : bool
        True when a running node cannot change it (it shapes subscriptions or buffers).

    """

    doc: str
    unit: str = ''
    range: tuple[float, float] | None = None  # noqa: A003 (the declarations' keyword)
    length: int | None = None
    eq: str = ''
    decision: str = ''
    read_only: bool = False


def param(default=MISSING, doc: str = '', *, default_factory=MISSING, **spec) -> typing.Any:
    """
    Return a dataclass field declared with its :class:`Spec`.

    (keyword arguments of Spec after ``doc``).
    """
    if not doc:
        raise ValueError('a parameter needs its meaning (doc)')
    metadata = {'param': Spec(doc, **spec)}
    if default_factory is not MISSING:
        return field(default_factory=default_factory, metadata=metadata)
    return field(default=default, metadata=metadata)


def specs(config_type) -> list[tuple[dataclasses.Field, Spec]]:
    """Return the declared parameters of a configuration dataclass, in declaration order."""
    return [
        (f, f.metadata['param']) for f in dataclasses.fields(config_type) if 'param' in f.metadata
    ]


def coerce(config, prefix: str = '') -> None:
    """
    Convert every declared field of ``config`` to its annotated type and check it against its Spec.

    Tuples become tuples of their element type, choices their Enum member, ints must be integral.

    Raises
    ------
    ValueError
        Naming the parameter (``prefix`` + field name), the value and what it must be.

    """
    hints = typing.get_type_hints(type(config))
    for f, spec in specs(type(config)):
        name = prefix + f.name
        value = _converted(name, getattr(config, f.name), hints[f.name], spec)
        object.__setattr__(config, f.name, value)


def _converted(name: str, value, hint, spec: Spec):
    origin = typing.get_origin(hint)
    if origin is tuple:
        element = typing.get_args(hint)[0]
        try:
            items = tuple(value)
        except TypeError:
            raise ValueError(
                f'{name} must be a list of {spec.length or "some"} numbers, got {value!r}'
            ) from None
        if spec.length is not None and len(items) != spec.length:
            raise ValueError(f'{name} must have {spec.length} values, got {len(items)}')
        return tuple(_scalar(f'{name}[{i}]', v, element, spec) for i, v in enumerate(items))
    return _scalar(name, value, hint, spec)


def _scalar(name: str, value, kind, spec: Spec):
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        try:
            return kind(value)
        except ValueError:
            choices = ', '.join(str(c.value) for c in kind)
            raise ValueError(f'{name} must be one of {choices}, got {value!r}') from None
    if kind is bool:
        if not isinstance(value, (bool, np.bool_)):
            raise ValueError(f'{name} must be true or false, got {value!r}')
        return bool(value)
    if kind is str:
        if not isinstance(value, str):
            raise ValueError(f'{name} must be text, got {value!r}')
        return value
    if kind in (int, float):
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            and not hasattr(value, '__float__')
        ):
            raise ValueError(f'{name} must be a number, got {value!r}')
        number = float(value)
        if not math.isfinite(number):
            raise ValueError(f'{name} must be finite, got {value!r}')
        if kind is int:
            if number != int(number):
                raise ValueError(f'{name} must be an integer, got {value!r}')
            number = int(number)
        if spec.range is not None and not spec.range[0] <= number <= spec.range[1]:
            low, high = spec.range
            raise ValueError(
                f'{name} must be in [{number_text(low)}, {number_text(high)}]'
                f'{" " + spec.unit if spec.unit else ""}, got {value!r}'
            )
        return number
    return value


def number_text(v: float) -> str:
    """Return a range bound as a reader writes it: 30, 0.01, 1e-06 -> 1e-6, 1e+07 -> 1e7."""
    if float(v).is_integer() and abs(v) < 1e5:
        return str(int(v))
    return f'{v:g}'.replace('e+0', 'e').replace('e+', 'e').replace('e-0', 'e-')
