"""The shared typed-table reader (fsarm_sim.typed_tables): conversion, nesting and its three errors."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import pytest

from fsarm_sim import typed_tables


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
    kw = typed_tables.typed_kwargs(Outer, {"name": "x", "tags": ["p", "q"], "inner": {"d_mm": 9}})
    assert kw == {"name": "x", "tags": ("p", "q"), "inner": Inner(9.0)}
    assert isinstance(kw["inner"].d_mm, float)


@pytest.mark.parametrize(
    ("table", "error", "key"),
    [
        ({"name": "x", "colour": 1}, typed_tables.UnknownKeys, None),
        ({"kind": "a"}, typed_tables.MissingKey, "name"),
        ({"name": 3}, typed_tables.Mismatch, "name"),
        ({"name": "x", "n": True}, typed_tables.Mismatch, "n"),  # a bool is not an integer
        ({"name": "x", "kind": "c"}, typed_tables.Mismatch, "kind"),
        ({"name": "x", "tags": ["p", 1]}, typed_tables.Mismatch, "tags[1]"),
        ({"name": "x", "inner": {"d_mm": float("inf")}}, typed_tables.Mismatch, "inner.d_mm"),
        ({"name": "x", "inner": {}}, typed_tables.MissingKey, "inner.d_mm"),
    ],
)
def test_a_table_that_does_not_fit_names_its_key(
    table: dict[str, object], error: type[typed_tables.TableError], key: str | None
) -> None:
    with pytest.raises(error) as info:
        typed_tables.typed_kwargs(Outer, table)
    if key is not None:
        assert info.value.key == key  # type: ignore[attr-defined]
    else:
        assert info.value.keys == ["colour"] and "name" in info.value.allowed  # type: ignore[attr-defined]


def test_required_and_described() -> None:
    with pytest.raises(typed_tables.MissingKey):
        typed_tables.typed_kwargs(Outer, {"name": "x"}, required=("kind",))
    assert typed_tables.describe(float | None) == "a finite number"
    assert typed_tables.describe(tuple[float, ...]) == "a list of numbers"
    assert typed_tables.describe(Literal["a", "b"]) == "one of 'a', 'b'"
