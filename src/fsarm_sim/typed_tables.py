"""One strict reader of typed tables: a JSON object or a TOML table into a dataclass's fields.

:func:`typed_kwargs` takes a mapping and a dataclass and returns the keyword arguments that build
it, each value checked against the field's type hint and converted to what the field holds (a
list to a tuple, an integer to a float). Nested dataclasses are read the same way. A table that
does not fit raises :class:`UnknownKeys`, :class:`MissingKey` or :class:`Mismatch`, which carry the
key and what is allowed; the callers (the record sidecar, the claims files) turn them into their
own named errors. :func:`describe` says a type hint in the files' words ("a finite number").
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Mapping
from typing import Any


class TableError(Exception):
    """A table that does not fit its dataclass (translated by the caller into its named error)."""


class UnknownKeys(TableError):
    """Keys the dataclass has no field for; ``prefix`` is the nested table's path ("shaft.")."""

    def __init__(self, keys: list[str], allowed: tuple[str, ...], prefix: str) -> None:
        super().__init__(keys)
        self.keys, self.allowed, self.prefix = keys, allowed, prefix


class MissingKey(TableError):
    """A required field absent from the table (``key`` with its prefix)."""

    def __init__(self, key: str, hint: Any) -> None:
        super().__init__(key)
        self.key, self.hint = key, hint


class Mismatch(TableError):
    """A value that does not fit its field's type hint."""

    def __init__(self, key: str, hint: Any, value: Any) -> None:
        super().__init__(key)
        self.key, self.hint, self.value = key, hint, value


def describe(hint: Any) -> str:
    """A type hint in the files' words."""
    simple = {float: "a finite number", int: "an integer", bool: "true or false", str: "a string"}
    if hint in simple:
        return simple[hint]
    if hint is Any:
        return "any JSON value"
    if dataclasses.is_dataclass(hint):
        return "an object"
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(hint))
    if origin in (typing.Union, types.UnionType):
        return " or ".join(describe(a) for a in typing.get_args(hint) if a is not type(None))
    if origin is dict:
        return "an object"
    if origin is tuple:
        item = typing.get_args(hint)[0]
        return "a list of " + {float: "numbers", str: "strings"}.get(item, describe(item))
    raise TypeError(f"no file form for the type {hint!r}")  # a schema bug, not a data error


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def convert(hint: Any, v: Any, key: str) -> Any:
    """``v`` as the field of type ``hint`` holds it, or :class:`Mismatch` naming ``key``."""
    if hint is Any:
        return v
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        if v is None and type(None) in args:
            return None
        arms = [a for a in args if a is not type(None)]
        if len(arms) == 1:  # X | None: X's own (more precise) error
            return convert(arms[0], v, key)
        for arm in arms:
            try:
                return convert(arm, v, key)
            except Mismatch:
                continue
        raise Mismatch(key, hint, v)
    checks = {
        float: _is_number,
        int: lambda x: isinstance(x, int) and not isinstance(x, bool),
        bool: lambda x: isinstance(x, bool),
        str: lambda x: isinstance(x, str),
    }
    if hint in checks:
        if not checks[hint](v):
            raise Mismatch(key, hint, v)
        return float(v) if hint is float else v
    if origin is typing.Literal:
        if v not in typing.get_args(hint):
            raise Mismatch(key, hint, v)
        return v
    if origin is tuple:
        if not isinstance(v, list | tuple):
            raise Mismatch(key, hint, v)
        item = typing.get_args(hint)[0]
        return tuple(convert(item, a, f"{key}[{i}]") for i, a in enumerate(v))
    if origin is dict:
        if not isinstance(v, Mapping):
            raise Mismatch(key, hint, v)
        item = typing.get_args(hint)[1]
        return {str(k): convert(item, a, f"{key}.{k}") for k, a in v.items()}
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        if not isinstance(v, Mapping):
            raise Mismatch(key, hint, v)
        return hint(**typed_kwargs(hint, v, prefix=key + "."))
    raise TypeError(f"no reader for the type {hint!r}")  # a schema bug, not a data error


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def typed_kwargs(
    cls: type,
    table: Mapping[str, Any],
    *,
    prefix: str = "",
    skip: tuple[str, ...] = (),
    extra: tuple[str, ...] = (),
    required: tuple[str, ...] = (),
) -> dict[str, Any]:
    """The keyword arguments of dataclass ``cls`` from ``table``, strictly. ``skip``: fields not
    taken from the table; ``extra``: keys of the table the caller reads itself; ``required``:
    fields that must be in the table though they have a default."""
    hints = _hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.name not in skip}
    unknown = [str(k) for k in table if k not in fields and k not in extra]
    if unknown:
        raise UnknownKeys(unknown, (*fields, *extra), prefix)
    out: dict[str, Any] = {}
    for name, f in fields.items():
        if name not in table:
            no_default = (
                f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
            )
            if no_default or name in required:
                raise MissingKey(prefix + name, hints[name])
            continue
        out[name] = convert(hints[name], table[name], prefix + name)
    return out
