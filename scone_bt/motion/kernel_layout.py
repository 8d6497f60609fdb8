"""The collision kernel's flat arrays (`compiled.pair_candidates`), each declared once: its fields in order.

The kernel takes an arm's floats and ints (`ARM_F`, `ARM_I`, packed once per arm and finger position by
`spheres.ArmSpheres`), a world's floats and ints (`WORLD_F`, `WORLD_I`, once per collision world by
`spheres.SphereChecks`) and a scratch array (`WORK`). A field's length is a whole multiple of one of the layout's
sizes (``nj`` joints, ``ns`` spheres, ``ng`` geometries; ``n_ob`` obstacles and ``n_pairs`` pairs), plus a constant;
the last field may take the rest of the array. `Layout.table` turns the declaration into an offset table, a
numpy array that the kernel reads as a compile-time constant; `Layout.pack` and `Layout.unpack` use the same
declaration on the Python side, so packing and reading cannot drift apart.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from math import prod
from typing import Any

import numpy as np

__all__ = [
    "ARM_F",
    "ARM_I",
    "LAYOUTS",
    "REST",
    "WORK",
    "WORLD_F",
    "WORLD_I",
    "Field",
    "Layout",
    "layout_digest",
]

MAX_SIZES = 3
"""Sizes a layout may have; the offset table has one column per size, after the constant term."""

REST = -(1 << 40)
"""The constant term of a rest-of-array field's length in `Layout.table` (no real field is that long)."""


@dataclass(frozen=True)
class Field:
    """One field of a flat array.

    Attributes:
        name: The field's name.
        rows: How many rows: a size's name (``"nj"``), a constant (``1``), or (size, constant to add) as
            (``"nj", -1``) for the joints without the universe; None: the rest of the array (the last field only).
        each: The shape of one row: () a number, (3,) a vector, (4, 4) a pose.
    """

    name: str
    rows: str | int | tuple[str, int] | None
    each: tuple[int, ...] = ()


@dataclass(frozen=True)
class Layout:
    """A flat array's fields in order, and the sizes their rows count in (at most `MAX_SIZES`)."""

    name: str
    sizes: tuple[str, ...]
    fields: tuple[Field, ...]

    def __post_init__(self) -> None:
        if len(self.sizes) > MAX_SIZES:
            raise ValueError(f"layout {self.name}: at most {MAX_SIZES} sizes, not {self.sizes}")
        for k, f in enumerate(self.fields):
            if f.rows is None and k != len(self.fields) - 1:
                raise ValueError(f"layout {self.name}: only the last field may take the rest, not {f.name!r}")
            size = f.rows[0] if isinstance(f.rows, tuple) else f.rows
            if isinstance(size, str) and size not in self.sizes:
                raise ValueError(
                    f"layout {self.name}: field {f.name!r} counts in {size!r}; sizes: {self.sizes}"
                )

    def _rows_form(self, f: Field) -> np.ndarray:
        """The field's row count as (constant, per size...), MAX_SIZES + 1 integers."""
        form = np.zeros(MAX_SIZES + 1, dtype=np.int64)
        size, constant = f.rows if isinstance(f.rows, tuple) else (f.rows, 0)
        if isinstance(size, str):
            form[1 + self.sizes.index(size)] = 1
            form[0] = constant
        elif isinstance(size, int):
            form[0] = size + constant
        return form

    def table(self) -> np.ndarray:
        """(fields, 2, MAX_SIZES + 1) int64: each field's offset and length as linear forms in the sizes
        (constant, size 1, size 2, size 3); the rest-of-array field's length is `REST`. Read-only, made once."""
        return self._table

    @cached_property
    def _table(self) -> np.ndarray:
        out = np.zeros((len(self.fields), 2, MAX_SIZES + 1), dtype=np.int64)
        offset = np.zeros(MAX_SIZES + 1, dtype=np.int64)
        for k, f in enumerate(self.fields):
            out[k, 0] = offset
            if f.rows is None:
                out[k, 1, 0] = REST
                continue
            out[k, 1] = self._rows_form(f) * prod(f.each)
            offset = offset + out[k, 1]
        out.flags.writeable = False
        return out

    def index(self, name: str) -> int:
        """The position of field ``name`` in the layout (its row in `table`)."""
        k = self._positions.get(name)
        if k is None:
            raise KeyError(f"layout {self.name} has no field {name!r}; fields: {', '.join(self.names)}")
        return k

    @cached_property
    def _positions(self) -> dict[str, int]:
        return {f.name: k for k, f in enumerate(self.fields)}

    @cached_property
    def _forms(self) -> tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]:
        """`table` as Python ints, field by field: (offset form, length form)."""
        return tuple((tuple(map(int, row[0])), tuple(map(int, row[1]))) for row in self._table)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fields)

    def span(self, name: str, sizes: Mapping[str, int], total: int | None = None) -> tuple[int, int]:
        """[start, end) of field ``name`` for these sizes; the rest-of-array field needs the array's ``total``."""
        # Plain Python on the table made once: a collision world packs and reads its arrays a few hundred times
        # per plan, and building the table and numpy vectors per call cost a third of a plan's time.
        offset, length = self._forms[self.index(name)]
        values = (1, *(int(sizes[s]) for s in self.sizes), *(0,) * (MAX_SIZES - len(self.sizes)))
        start = sum(a * b for a, b in zip(offset, values, strict=True))
        if length[0] == REST:
            if total is None:
                raise ValueError(f"layout {self.name}: field {name!r} is the rest; give the array's length")
            return start, total
        return start, start + sum(a * b for a, b in zip(length, values, strict=True))

    def unpack(self, array: np.ndarray, sizes: Mapping[str, int]) -> dict[str, np.ndarray]:
        """Every field of ``array`` as a view of its declared shape (rows, *each)."""
        out: dict[str, np.ndarray] = {}
        for f in self.fields:
            start, end = self.span(f.name, sizes, len(array))
            out[f.name] = array[start:end].reshape((-1, *f.each) if f.each else (-1,))
        return out

    def pack(self, sizes: Mapping[str, int], values: Mapping[str, Any], dtype: Any) -> np.ndarray:
        """One flat array of ``dtype`` from each field's value (any array-like of its declared length), in order.

        Raises:
            ValueError: a field missing or unknown, or a value of the wrong length (naming the field).
        """
        unknown = sorted(set(values) - set(self.names))
        missing = [n for n in self.names if n not in values]
        if unknown or missing:
            raise ValueError(f"layout {self.name}: unknown fields {unknown}, missing fields {missing}")
        parts = []
        for f in self.fields:
            part = np.asarray(values[f.name], dtype=dtype).ravel()
            if f.rows is not None:
                start, end = self.span(f.name, sizes)
                if part.size != end - start:
                    raise ValueError(
                        f"layout {self.name}: field {f.name!r} has {part.size} numbers, the layout {end - start}"
                    )
            parts.append(part)
        return np.concatenate(parts).astype(dtype)


ARM_I = Layout(
    "arm_i",
    ("nj", "ns", "ng"),
    (
        Field("nj", 1),
        Field("ns", 1),
        Field("ng", 1),
        Field("parents", "nj"),
        Field("sphere_joint", "ns"),
        Field("first", "ng"),  # a geometry's first sphere
        Field("count", "ng"),  # and how many
        Field("geom_joint", "ng"),
        Field("hull_first", "ng"),  # a geometry's first hull vertex in arm_f's hull
        Field("hull_count", "ng"),
    ),
)
"""The arm's ints: sizes, then per joint its parent, per sphere its joint, per geometry its spheres, joint and hull."""

ARM_F = Layout(
    "arm_f",
    ("nj", "ns", "ng"),
    (
        Field("placements", "nj", (4, 4)),  # each joint in its parent's frame at q = 0
        Field("axes", "nj", (3,)),
        Field("sphere_local", "ns", (3,)),  # in its joint's frame
        Field("radius", "ns"),
        Field("bound_local", "ng", (3,)),  # a geometry's bounding sphere, in its joint's frame
        Field("bound_radius", "ng"),
        Field("geom_placement", "ng", (4, 4)),
        Field("lowest", ("nj", -1)),  # joint limits (with tolerance), radians
        Field("highest", ("nj", -1)),
        Field("swept", "ng"),  # coal's swept-sphere radius of each geometry
        Field("hull", None, (3,)),  # every geometry's hull vertices, in its own frame
    ),
)
"""The arm's floats (metres, radians)."""

WORLD_I = Layout(
    "world_i",
    ("n_ob", "n_pairs"),
    (
        Field("n_ob", 1),
        Field("n_pairs", 1),
        Field("tilt_checked", 1),
        Field("limits_checked", 1),
        Field("pairs", "n_pairs", (3,)),  # (kind, a, b)
    ),
)
"""The world's ints: sizes, the two checks switched on or off, and the pairs to check."""

WORLD_F = Layout(
    "world_f",
    ("n_ob",),
    (
        Field("ob_pose", "n_ob", (4, 4)),
        Field("ob_size", "n_ob", (3,)),  # padded half sizes; a cylinder's (radius, half height, -1)
        Field("held_local", 1, (4, 4)),  # the held object in its joint's frame
        Field("held_half", 1, (3,)),
        Field("held_joint", 1),  # -1: nothing held
        Field("tilt_joint", 1),
        Field("min_up", 1),  # the cosine of the largest tilt
        Field("up_axis", 1, (3,)),
        Field("ob_radius", "n_ob"),  # the padded shape's bounding radius
        Field("held_radius", 1),
    ),
)
"""The world's floats (metres)."""

WORK = Layout(
    "work",
    ("nj", "ns", "ng"),
    (
        Field("poses", "nj", (4, 4)),
        Field("centres", "ns", (3,)),
        Field("bounds", "ng", (3,)),
        Field("held", 1, (4, 4)),
        Field("rotation", "ng", (3, 3)),
        Field("translation", "ng", (3,)),
        Field("scratch", 24),
    ),
)
"""The kernel's scratch: what it computes at a state (poses, sphere centres, geometry poses), read back by
`spheres.SphereChecks` for coal's GJK."""

LAYOUTS = (ARM_I, ARM_F, WORLD_I, WORLD_F, WORK)


def layout_digest() -> str:
    """A short hash of every layout's declaration (`compiled.LAYOUT_DIGEST` must match it: numba's on-disk cache
    keeps the tables as they were when it compiled, and is refreshed only when compiled.py changes)."""
    text = repr([(lay.name, lay.sizes, lay.fields, lay.table().tolist()) for lay in LAYOUTS])
    return hashlib.sha256(text.encode()).hexdigest()[:16]
