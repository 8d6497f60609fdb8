"""The grocery catalogue: products the kitchen can stock, one YAML file per packaging family.

A family file (perception/catalogue/<family>.yaml) names its family, says where its figures come from, gives the
fields its products share (``defaults``: products of one family are handled alike) and lists the products. A user
adds products with one more file of the same shape (``--catalogue FILE``) without touching code.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.config.yaml_io import Fields, read_yaml, require
from scone_bt.errors import ConfigError, UnknownNameError

__all__ = ["SHAPES", "ObjectSpec", "Catalogue", "load_catalogue", "catalogue_files"]

SHAPES = ("box", "cylinder")


@dataclass(frozen=True)
class ObjectSpec:
    """One catalogue product.

    Attributes:
        name: Canonical name, used in action texts ("Put <name> on table").
        aliases: True synonyms recipes use for it ("garbanzo beans" for chickpeas).
        shape: "box" or "cylinder".
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
    shape: str
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

    def names(self) -> list[str]:
        return [o.name for o in self.objects]

    def families(self) -> list[str]:
        """Packaging families in first-appearance order."""
        return list(dict.fromkeys(o.family for o in self.objects))

    def get(self, name: str) -> ObjectSpec:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise UnknownNameError("object", name, self.names())

    def by_marker(self, marker_id: int) -> ObjectSpec | None:
        for obj in self.objects:
            if obj.marker_id == marker_id:
                return obj
        return None

    def __len__(self) -> int:
        return len(self.objects)


def _object(raw: Any, defaults: dict[str, Any], family: str, where: str) -> ObjectSpec:
    merged = {**defaults, **raw} if isinstance(raw, dict) else raw
    f = Fields(merged, where)
    shape = f.get("shape", str)
    require(shape in SHAPES, f"{f.where}.shape: {shape!r} is not one of {', '.join(SHAPES)}")
    size = f.vector("size", 3)
    require(all(s > 0 for s in size), f"{f.where}.size: all extents must be positive")
    mass = f.get("mass", float)
    require(mass > 0, f"{f.where}.mass must be positive")
    return ObjectSpec(
        name=f.get("name", str).strip(),
        aliases=tuple(str(a).strip() for a in f.get("aliases", list, [])),
        shape=shape,
        size=size,  # type: ignore[arg-type]
        mass=mass,
        friction=f.get("friction", float),
        material=f.get("material", str, "unknown"),
        rgba=f.vector("rgba", 4),  # type: ignore[arg-type]
        marker_id=f.get("marker_id", int),
        family=f.get("family", str, family),
    )


def _family_file(path: Path) -> list[ObjectSpec]:
    f = Fields(read_yaml(path), str(path))
    family = f.get("family", str)
    defaults = f.get("defaults", dict, {})
    return [
        _object(raw, defaults, family, f"{path}: products[{i}]")
        for i, raw in enumerate(f.get("products", list))
    ]


def catalogue_files(entries: Iterable[str | Path], base: Path, fallback: Path) -> list[Path]:
    """Family files named by a kitchen's ``catalogue:`` list: files or folders, relative to `base` or `fallback`."""
    out: list[Path] = []
    for entry in entries:
        for root in (Path(entry), base / entry, fallback / entry):
            if root.is_dir():
                out.extend(sorted(p for p in root.iterdir() if p.suffix in (".yaml", ".yml")))
                break
            if root.is_file():
                out.append(root)
                break
        else:
            raise ConfigError(f"{base}: catalogue entry {str(entry)!r} is neither a file nor a folder")
    return out


def load_catalogue(files: Sequence[Path]) -> Catalogue:
    """Read and merge family files, in order."""
    objects = [obj for path in files for obj in _family_file(Path(path))]
    names = [o.name for o in objects]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ConfigError(f"catalogue: duplicate object names: {', '.join(dupes)}")
    markers = [o.marker_id for o in objects]
    if len(set(markers)) != len(markers):
        raise ConfigError("catalogue: marker_id values must be unique")
    # Marker order: a seeded draw over the catalogue does not depend on how products are split into files.
    return Catalogue(tuple(sorted(objects, key=lambda o: o.marker_id)))
