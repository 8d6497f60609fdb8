"""The grocery catalogue: products the kitchen can stock, one YAML file per packaging family.

A family file (perception/catalogue/<family>.yaml) names its family, says where its figures come from, gives the
fields its products share (``defaults``: products of one family are handled alike) and lists the products. A user
adds products with one more file of the same shape (``--catalogue FILE``) without touching code.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from dataclasses import field as dataclass_field
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any, Literal, cast

from pydantic import Field

from scone_bt.config.schema import PositiveFloat, StrictModel, UnitFloat, validate
from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError, UnknownNameError

__all__ = [
    "SHAPES",
    "Shape",
    "MARKER_DICTIONARY_SIZE",
    "UNDRAWABLE_MARKER_IDS",
    "ObjectSpec",
    "Catalogue",
    "load_catalogue",
    "catalogue_files",
]


class Shape(StrEnum):
    """A product's collision and grasp model: an axis-aligned box or an upright cylinder."""

    BOX = "box"
    CYLINDER = "cylinder"


SHAPES = tuple(s.value for s in Shape)
MARKER_DICTIONARY_SIZE = 1000
"""Ids of the lid markers' dictionary (ArUco DICT_6X6_1000, see `scone_bt.world.visuals`)."""
UNDRAWABLE_MARKER_IDS = frozenset({544})
"""Ids whose pattern needs more than PyBullet's 16 primitives with body and cap (tests/world checks all 1000)."""


@dataclass(frozen=True)
class ObjectSpec:
    """One catalogue product.

    Attributes:
        name: Canonical name, used in action texts ("Put <name> on table").
        aliases: True synonyms recipes use for it ("garbanzo beans" for chickpeas).
        shape: Shape.BOX or Shape.CYLINDER.
        size: Extent along x, y, z in metres (cylinder: diameter, diameter, height).
        mass: Kilograms.
        friction: Lateral friction coefficient of its surface.
        material: Free text (glass, metal, paper, ...).
        rgba: Body colour, components in [0, 1].
        marker_id: Fiducial id printed on the lid.
        family: Packaging family ("cans", "spice jars", ...): products of one family are handled alike.
    """

    name: str
    aliases: tuple[str, ...]
    shape: Shape
    size: tuple[float, float, float]
    mass: float
    friction: float
    material: str
    rgba: tuple[float, float, float, float]
    marker_id: int
    family: str = ""

    @property
    def grasp_width(self) -> float:
        """Narrowest horizontal extent in metres (what the fingers must span)."""
        return min(self.size[0], self.size[1])

    @property
    def height(self) -> float:
        return self.size[2]


@dataclass(frozen=True)
class Catalogue:
    """All objects the kitchen can stock, by canonical name."""

    objects: tuple[ObjectSpec, ...]
    _by_name: dict[str, ObjectSpec] = dataclass_field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        # The first of a name wins, as the scan it replaces did (load_catalogue refuses duplicates anyway).
        by_name: dict[str, ObjectSpec] = {}
        for obj in self.objects:
            by_name.setdefault(obj.name, obj)
        object.__setattr__(self, "_by_name", by_name)

    def names(self) -> list[str]:
        return [o.name for o in self.objects]

    def families(self) -> list[str]:
        """Packaging families in first-appearance order."""
        return list(dict.fromkeys(o.family for o in self.objects))

    def get(self, name: str) -> ObjectSpec:
        try:
            return self._by_name[name]
        except (KeyError, TypeError):
            raise UnknownNameError("object", name, self.names()) from None

    def by_marker(self, marker_id: int) -> ObjectSpec | None:
        for obj in self.objects:
            if obj.marker_id == marker_id:
                return obj
        return None

    def __len__(self) -> int:
        return len(self.objects)


MAX_PRODUCT_M = 1.0
"""Largest extent of a product, metres: a grocery item a one-armed robot might fetch (the shipped catalogue's
largest is 0.35 m); a 10 m product is a typo, refused with its file and name, not later as a shelf that is full."""
_Extent = Annotated[float, Field(gt=0, le=MAX_PRODUCT_M, allow_inf_nan=False)]
MAX_PRODUCT_KG = 50.0
"""Heaviest product, kilograms: far past any arm's payload (the shipped catalogue's heaviest is 2 kg), so a product
too heavy to lift is still a product the robot may fail on; 1e9 kg is a typo."""


class _ProductFields(StrictModel):
    """One product as written in a family file; omitted fields come from the family's ``defaults``."""

    name: Annotated[str, Field(min_length=1)]
    aliases: list[Annotated[str, Field(min_length=1)]] = []
    shape: Literal["box", "cylinder"]
    size: Annotated[list[_Extent], Field(min_length=3, max_length=3)]
    mass: Annotated[float, Field(gt=0, le=MAX_PRODUCT_KG, allow_inf_nan=False)]
    friction: PositiveFloat
    material: Annotated[str, Field(min_length=1)]
    rgba: Annotated[list[UnitFloat], Field(min_length=4, max_length=4)]
    marker_id: Annotated[int, Field(ge=0)]


class _Defaults(StrictModel):
    """Fields every product of a family shares unless it says otherwise."""

    shape: Literal["box", "cylinder"] | None = None
    material: str | None = None
    friction: PositiveFloat | None = None
    rgba: Annotated[list[UnitFloat], Field(min_length=4, max_length=4)] | None = None


class _FamilyFile(StrictModel):
    """A family file: its family, where its figures come from, shared fields and products (checked one by one)."""

    family: Annotated[str, Field(min_length=1)]
    source: Annotated[str, Field(min_length=1)]
    defaults: _Defaults = _Defaults()
    products: Annotated[list[Any], Field(min_length=1)]


def _product(raw: Any, defaults: _Defaults, family: str, where: str, index: int) -> ObjectSpec:
    if not isinstance(raw, dict):
        raise ConfigError(f"{where}: products[{index}]: expected a mapping, got {type(raw).__name__}")
    name = raw.get("name")
    label = f"{where}: product {name!r}" if isinstance(name, str) and name else f"{where}: products[{index}]"
    merged = {**defaults.model_dump(exclude_none=True), **raw}
    p = validate(_ProductFields, merged, label)
    return ObjectSpec(
        name=p.name.strip(),
        aliases=tuple(a.strip() for a in p.aliases),
        shape=Shape(p.shape),
        size=cast("tuple[float, float, float]", tuple(p.size)),
        mass=p.mass,
        friction=p.friction,
        material=p.material,
        rgba=cast("tuple[float, float, float, float]", tuple(p.rgba)),
        marker_id=p.marker_id,
        family=family,
    )


_FAMILIES: dict[tuple[str, int, int], tuple[ObjectSpec, ...]] = {}
"""Parsed family files by (path, modification time in ns, size): episodes one after another load the kitchen
anew, and parsing the grocery's 617 products was ~5 % of an episode's wall time. An edited file is read again."""


def _family_file(path: Path) -> tuple[ObjectSpec, ...]:
    try:
        st = path.stat()
        key: tuple[str, int, int] | None = (str(path.resolve()), st.st_mtime_ns, st.st_size)
    except OSError:
        key = None  # read_yaml below words the one-line error
    if key is not None and key in _FAMILIES:
        return _FAMILIES[key]
    f = validate(_FamilyFile, read_yaml(path), str(path))
    products = tuple(_product(raw, f.defaults, f.family, str(path), i) for i, raw in enumerate(f.products))
    if key is not None:
        _FAMILIES[key] = products
    return products


def catalogue_files(
    entries: Iterable[str | Path], base: Path, fallback: Path, where: str | None = None
) -> list[Path]:
    """Family files named by a kitchen's ``catalogue:`` list: files or folders, relative to `base` or `fallback`.

    `where` (the kitchen file) names the file in an error; without it, `base`.
    """
    out: list[Path] = []
    for i, entry in enumerate(entries):
        for root in (Path(entry), base / entry, fallback / entry):
            if root.is_dir():
                found = sorted(p for p in root.iterdir() if p.suffix in (".yaml", ".yml"))
                if not found:
                    raise ConfigError(
                        f"{base}: catalogue entry {str(entry)!r}: the folder {root} holds no .yaml family files"
                    )
                out.extend(found)
                break
            if root.is_file():
                out.append(root)
                break
        else:
            folders = sorted(p.name for p in fallback.iterdir() if p.is_dir() and any(p.glob("*.y*ml")))
            raise ConfigError(
                f"{where or base}: catalogue[{i}]: {str(entry)!r} is neither a file nor a folder (relative to {base} or "
                f"{fallback}); give family files (.yaml, .json) or folders of them (valid folders: "
                f"{', '.join(folders)})"
            )
    return out


def _free_marker(markers: dict[int, Any]) -> int | str:
    """The lowest drawable marker id no product has yet ("none" when the dictionary is full)."""
    free = (i for i in range(MARKER_DICTIONARY_SIZE) if i not in markers and i not in UNDRAWABLE_MARKER_IDS)
    return next(free, "none")


def load_catalogue(files: Sequence[Path]) -> Catalogue:
    """Read and merge family files, in order.

    Raises:
        ConfigError: One line naming the file, the product and the field: a malformed product, or one that
            conflicts with an earlier one (the same name, an alias that is another product's name or alias, the
            same marker id, a marker id outside the marker dictionary).
    """
    objects: list[ObjectSpec] = []
    names: dict[str, tuple[str, str]] = {}  # folded name or alias → (product, file)
    markers: dict[int, tuple[str, str]] = {}
    seen: dict[Path, Path] = {}
    for path in files:
        same = Path(path).resolve()
        if same in seen:  # e.g. `--catalogue` naming a family file the kitchen already lists
            raise ConfigError(
                f"{path}: this product file is already in the catalogue (as {seen[same]}); give it once"
            )
        seen[same] = Path(path)
        for obj in _family_file(Path(path)):
            where = f"{path}: product {obj.name!r}"
            for field, label in (("name", obj.name), *(("aliases", a) for a in obj.aliases)):
                key = " ".join(label.lower().split())
                if key in names and names[key][0] != obj.name or (field == "name" and key in names):
                    other, other_file = names[key]
                    raise ConfigError(
                        f"{where}: {field}: {label!r} is already product {other!r} (in {other_file}); "
                        "names and aliases must be unique across the catalogue"
                    )
                names[key] = (obj.name, str(path))
            if obj.marker_id >= MARKER_DICTIONARY_SIZE or obj.marker_id in UNDRAWABLE_MARKER_IDS:
                raise ConfigError(
                    f"{where}: marker_id: {obj.marker_id} is not a drawable marker (valid: 0-"
                    f"{MARKER_DICTIONARY_SIZE - 1} except {', '.join(map(str, sorted(UNDRAWABLE_MARKER_IDS)))};"
                    f" e.g. {_free_marker(markers)} is free)"
                )
            if obj.marker_id in markers:
                other, other_file = markers[obj.marker_id]
                raise ConfigError(
                    f"{where}: marker_id: {obj.marker_id} is already product {other!r} (in {other_file}); "
                    f"marker ids must be unique (e.g. {_free_marker(markers)} is free)"
                )
            markers[obj.marker_id] = (obj.name, str(path))
            objects.append(obj)
    # Marker order: a seeded draw over the catalogue does not depend on how products are split into files.
    return Catalogue(tuple(sorted(objects, key=lambda o: o.marker_id)))
