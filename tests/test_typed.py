"""The shared typed-table reader (records.typed): conversion, nesting and its three errors."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import pytest

from fsarm_sim.records import typed


@dataclass(frozen=True)
class Inner:
    d_mm: float


@dataclass(frozen=True)
class Outer:
    name: str
    kind: Literal["a", "b"] = "a"
    n: int = 1
    tags: tuple[str, ...] = ()
    inner: Inner | None = None


def test_values_are_converted_and_nested_tables_read() -> None:
    kw = typed.typed_kwargs(Outer, {"name": "x", "tags": ["p", "q"], "inner": {"d_mm": 9}})
    assert kw == {"name": "x", "tags": ("p", "q"), "inner": Inner(9.0)}
    assert isinstance(kw["inner"].d_mm, float)


@pytest.mark.parametrize(
    ("table", "error", "key"),
    [
        ({"name": "x", "colour": 1}, typed.UnknownKeys, None),
        ({"kind": "a"}, typed.MissingKey, "name"),
        ({"name": 3}, typed.Mismatch, "name"),
        ({"name": "x", "n": True}, typed.Mismatch, "n"),  # a bool is not an integer
        ({"name": "x", "kind": "c"}, typed.Mismatch, "kind"),
        ({"name": "x", "tags": ["p", 1]}, typed.Mismatch, "tags[1]"),
        ({"name": "x", "inner": {"d_mm": float("inf")}}, typed.Mismatch, "inner.d_mm"),
        ({"name": "x", "inner": {}}, typed.MissingKey, "inner.d_mm"),
    ],
)
def test_a_table_that_does_not_fit_names_its_key(
    table: dict[str, object], error: type[typed.TableError], key: str | None
) -> None:
    with pytest.raises(error) as info:
        typed.typed_kwargs(Outer, table)
    if key is not None:
        assert info.value.key == key  # type: ignore[attr-defined]
    else:
        assert info.value.keys == ["colour"] and "name" in info.value.allowed  # type: ignore[attr-defined]


def test_required_and_described() -> None:
    with pytest.raises(typed.MissingKey):
        typed.typed_kwargs(Outer, {"name": "x"}, required=("kind",))
    assert typed.describe(float | None) == "a finite number"
    assert typed.describe(tuple[float, ...]) == "a list of numbers"
    assert typed.describe(Literal["a", "b"]) == "one of 'a', 'b'"
