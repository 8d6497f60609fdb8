"""The collision kernel's flat arrays (motion.kernel_layout): every field packs and reads back, in Python and in
the compiled kernel's reading of the offset tables."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion import compiled
from scone_bt.motion.kernel_layout import ARM_F, ARM_I, LAYOUTS, WORK, Field, Layout, layout_digest
from scone_bt.motion.spheres import arm_spheres

SIZES = [
    {"nj": 8, "ns": 31, "ng": 12, "n_ob": 5, "n_pairs": 40},
    {"nj": 1, "ns": 0, "ng": 0, "n_ob": 0, "n_pairs": 0},
    {"nj": 10, "ns": 3, "ng": 2, "n_ob": 45, "n_pairs": 1},
]


def _rows(layout: Layout, field: Field, sizes: dict[str, int]) -> int:
    if field.rows is None:
        return 7  # the rest: any number of rows
    size, constant = field.rows if isinstance(field.rows, tuple) else (field.rows, 0)
    return (sizes[size] if isinstance(size, str) else size) + constant


@pytest.mark.parametrize("layout", LAYOUTS, ids=lambda lay: lay.name)
@pytest.mark.parametrize("sizes", SIZES)
def test_every_field_packs_and_unpacks(layout: Layout, sizes: dict[str, int]) -> None:
    """Each field gets its own numbers; unpacking gives each back, in its shape, and the fields tile the array."""
    values, start = {}, 0
    for f in layout.fields:
        n = _rows(layout, f, sizes)
        values[f.name] = np.arange(start, start + n * int(np.prod(f.each)), dtype=float).reshape((n, *f.each))
        start += values[f.name].size
    packed = layout.pack(sizes, values, float)
    assert np.array_equal(packed, np.arange(start, dtype=float))  # in declaration order, no gap, no overlap
    unpacked = layout.unpack(packed, sizes)
    assert list(unpacked) == list(layout.names)
    for name, value in values.items():
        assert np.array_equal(unpacked[name].reshape(value.shape), value), name
        assert unpacked[name].base is packed or unpacked[name].base is not None  # a view, not a copy


@pytest.mark.parametrize("layout", LAYOUTS, ids=lambda lay: lay.name)
@pytest.mark.parametrize("sizes", SIZES)
def test_the_kernel_reads_the_fields_where_python_packs_them(layout: Layout, sizes: dict[str, int]) -> None:
    table = layout.table()
    args = [sizes[s] for s in layout.sizes] + [0] * (3 - len(layout.sizes))
    total = layout.span(layout.fields[-1].name, sizes, 10_000)[1] if layout.fields[-1].rows is None else None
    for k, f in enumerate(layout.fields):
        expected = layout.span(f.name, sizes, total)
        got = compiled.field_span(table, k, *args, total if total is not None else -1)
        assert tuple(int(v) for v in got) == expected, f.name


def test_the_compiled_module_was_built_against_these_layouts() -> None:
    assert layout_digest() == compiled.LAYOUT_DIGEST


def test_a_field_of_the_wrong_length_or_name_is_refused_naming_it() -> None:
    sizes = {"nj": 2, "ns": 1, "ng": 1}
    values = {
        f.name: np.zeros(WORK.span(f.name, sizes)[1] - WORK.span(f.name, sizes)[0]) for f in WORK.fields
    }
    WORK.pack(sizes, values, float)
    with pytest.raises(ValueError, match="field 'centres' has 4 numbers, the layout 3"):
        WORK.pack(sizes, {**values, "centres": np.zeros(4)}, float)
    with pytest.raises(ValueError, match=r"unknown fields \['centers'\], missing fields \['centres'\]"):
        WORK.pack(sizes, {**{k: v for k, v in values.items() if k != "centres"}, "centers": [0.0] * 3}, float)
    with pytest.raises(KeyError, match="layout work has no field 'nope'"):
        WORK.index("nope")


def test_a_layout_with_a_rest_before_the_end_is_refused() -> None:
    with pytest.raises(ValueError, match="only the last field may take the rest"):
        Layout("bad", ("n",), (Field("rest", None), Field("after", "n")))


def test_an_arms_packed_arrays_read_back_as_the_arm(arm) -> None:
    spheres = arm_spheres(arm, None)
    assert spheres is not None
    sizes = {"nj": spheres.n_joints, "ns": spheres.n_spheres, "ng": len(spheres.shapes)}
    ints = ARM_I.unpack(spheres.arm_i, sizes)
    floats = ARM_F.unpack(spheres.arm_f, sizes)
    assert (ints["nj"][0], ints["ns"][0], ints["ng"][0]) == (sizes["nj"], sizes["ns"], sizes["ng"])
    assert np.array_equal(ints["geom_joint"], spheres.joints)
    assert np.array_equal(floats["geom_placement"], spheres.placements)
    assert int(ints["count"].sum()) == sizes["ns"]
    assert len(floats["hull"]) == int(ints["hull_count"].sum())
    assert np.all(floats["lowest"] <= floats["highest"])
