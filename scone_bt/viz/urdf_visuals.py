"""Read a URDF's drawable geometry (meshes and primitives per link) without a simulator or a viewer."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import ConfigError, UnknownNameError

__all__ = [
    "GEOMETRY_SOURCES",
    "MESH_SUFFIXES",
    "LinkVisual",
    "RobotVisuals",
    "read_robot_visuals",
    "rpy_to_quat",
]

GEOMETRY_SOURCES = ("visual", "collision")
MESH_SUFFIXES = (".obj", ".stl", ".glb", ".gltf")  # what a rerun Asset3D can hold

_DEFAULT_RGBA = (0.85, 0.85, 0.88, 1.0)


@dataclass(frozen=True)
class LinkVisual:
    """One piece of a link's geometry, in the link's URDF frame.

    Attributes:
        link: URDF link name.
        kind: "mesh", "box", "cylinder" or "sphere".
        position: Origin of the geometry in the link frame, metres.
        quaternion: Orientation of the geometry in the link frame (x, y, z, w).
        rgba: Colour, components in [0, 1].
        mesh: Mesh file (kind "mesh"), else None.
        scale: Mesh scale per axis (kind "mesh").
        size: Box full extents (x, y, z) in metres; cylinder (radius, radius, length); sphere (r, r, r).
    """

    link: str
    kind: str
    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]
    mesh: Path | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class RobotVisuals:
    """All drawable geometry of a robot.

    Attributes:
        name: The URDF's robot name.
        root_link: The link no joint moves (PyBullet calls it 'base').
        root_inertial_position: Centre of mass of the root in its link frame, metres (PyBullet reports the base
            pose there, so a viewer shifts it back to the link frame).
        root_inertial_quaternion: Inertial frame orientation of the root in its link frame (x, y, z, w).
        visuals: Every drawable piece.
        skipped: Human-readable notes on geometry that cannot be drawn (unsupported mesh formats, missing files).
    """

    name: str
    root_link: str
    root_inertial_position: tuple[float, float, float]
    root_inertial_quaternion: tuple[float, float, float, float]
    visuals: tuple[LinkVisual, ...]
    skipped: tuple[str, ...] = ()

    def links(self) -> list[str]:
        """Names of the links that have geometry, in file order."""
        return list(dict.fromkeys(v.link for v in self.visuals))


def rpy_to_quat(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """URDF fixed-axis roll-pitch-yaw (R = Rz·Ry·Rx) as a quaternion (x, y, z, w)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def _floats(text: str | None, n: int, default: tuple[float, ...], where: str) -> Any:
    # Any: the length n is checked here at run time, and callers store fixed-length tuples.
    if text is None:
        return default
    parts = text.split()
    if len(parts) == 1 and n > 1:
        parts = parts * n  # URDF allows a single uniform mesh scale
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise ConfigError(f"{where}: expected {n} numbers, got {text!r}") from None
    if len(values) != n:
        raise ConfigError(f"{where}: expected {n} numbers, got {text!r}")
    return values


def _origin(
    elem: ET.Element | None, where: str
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    if elem is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    xyz = _floats(elem.get("xyz"), 3, (0.0, 0.0, 0.0), f"{where} origin xyz")
    rpy = _floats(elem.get("rpy"), 3, (0.0, 0.0, 0.0), f"{where} origin rpy")
    return xyz, rpy_to_quat(*rpy)


def _resolve_mesh(filename: str, urdf: Path) -> Path | None:
    """PyBullet's rule: drop 'package://' or 'file://' and look beside the URDF, then in its parents."""
    name = filename
    for prefix in ("package://", "file://"):
        if name.startswith(prefix):
            name = name[len(prefix) :]
    candidate = Path(name)
    if candidate.is_absolute():
        return candidate if candidate.is_file() else None
    parts = candidate.parts
    for base in (urdf.parent, *urdf.parent.parents):
        # package://<pkg>/x may also mean <dir containing pkg>/<pkg>/x or <pkg dir>/x
        for rel in (candidate, Path(*parts[1:]) if len(parts) > 1 else candidate):
            path = base / rel
            if path.is_file():
                return path
    return None


def _material_colours(root: ET.Element, where: str) -> dict[str, tuple[float, ...]]:
    colours: dict[str, tuple[float, ...]] = {}
    for mat in root.iter("material"):
        colour = mat.find("color")
        if mat.get("name") and colour is not None:
            colours.setdefault(
                mat.get("name", ""), _floats(colour.get("rgba"), 4, _DEFAULT_RGBA, f"{where} material")
            )
    return colours


def _element_visual(
    elem: ET.Element, name: str, source: str, where: str, path: Path, colours: dict[str, tuple[float, ...]]
) -> LinkVisual | str:
    """One ``<visual>`` (or ``<collision>``) element of link ``name`` as a drawable, or why it is skipped."""
    lw = f"{where} link {name} {source}"
    pos, quat = _origin(elem.find("origin"), lw)
    rgba: tuple[float, ...] = _DEFAULT_RGBA
    mat = elem.find("material")
    if mat is not None:
        colour = mat.find("color")
        if colour is not None:
            rgba = _floats(colour.get("rgba"), 4, _DEFAULT_RGBA, f"{lw} material")
        else:
            rgba = colours.get(mat.get("name", ""), _DEFAULT_RGBA)
    geom = elem.find("geometry")
    shape = geom[0] if geom is not None and len(geom) else None
    common: dict[str, Any] = {"link": name, "position": pos, "quaternion": quat, "rgba": rgba}
    if shape is None:
        return f"{name}: {source} without geometry"
    if shape.tag == "mesh":
        filename = shape.get("filename", "")
        suffix = Path(filename).suffix.lower()
        if suffix not in MESH_SUFFIXES:
            return f"{name}: mesh format {suffix or '(none)'} not drawable (use {', '.join(MESH_SUFFIXES)})"
        mesh = _resolve_mesh(filename, path)
        if mesh is None:
            return f"{name}: mesh {filename!r} not found"
        scale = _floats(shape.get("scale"), 3, (1.0, 1.0, 1.0), f"{lw} mesh scale")
        return LinkVisual(kind="mesh", mesh=mesh, scale=scale, **common)
    if shape.tag == "box":
        size = _floats(shape.get("size"), 3, (0.0, 0.0, 0.0), f"{lw} box size")
        return LinkVisual(kind="box", size=size, **common)
    if shape.tag == "cylinder":
        r = float(shape.get("radius", 0.0))
        length = float(shape.get("length", 0.0))
        return LinkVisual(kind="cylinder", size=(r, r, length), **common)
    if shape.tag == "sphere":
        r = float(shape.get("radius", 0.0))
        return LinkVisual(kind="sphere", size=(r, r, r), **common)
    return f"{name}: geometry <{shape.tag}> not drawable (use mesh, box, cylinder, sphere)"


def read_robot_visuals(urdf: str | Path, source: str = "visual") -> RobotVisuals:
    """Parse the drawable geometry of every link.

    Args:
        urdf: URDF file.
        source: "visual" (the detailed meshes) or "collision" (the coarse ones, a much smaller recording).
    """
    if source not in GEOMETRY_SOURCES:
        raise UnknownNameError("robot geometry source", source, GEOMETRY_SOURCES)
    path = Path(urdf)
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ConfigError(f"cannot read URDF {path}: {exc}") from None
    where = str(path)
    colours = _material_colours(root, where)
    children = {c.get("link") for j in root.findall("joint") if (c := j.find("child")) is not None}
    links = root.findall("link")
    roots = [lk.get("name", "") for lk in links if lk.get("name") not in children]
    if not roots:
        raise ConfigError(f"{where}: no root link (every link is some joint's child)")
    root_name = roots[0]

    visuals: list[LinkVisual] = []
    skipped: list[str] = []
    inertial_pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertial_quat: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    for link in links:
        name = link.get("name", "")
        if name == root_name:
            inertial = link.find("inertial")
            if inertial is not None:
                inertial_pos, inertial_quat = _origin(
                    inertial.find("origin"), f"{where} link {name} inertial"
                )
        for elem in link.findall(source):
            found = _element_visual(elem, name, source, where, path, colours)
            if isinstance(found, str):
                skipped.append(found)
            else:
                visuals.append(found)
    return RobotVisuals(
        name=root.get("name", path.stem),
        root_link=root_name,
        root_inertial_position=inertial_pos,
        root_inertial_quaternion=inertial_quat,
        visuals=tuple(visuals),
        skipped=tuple(skipped),
    )
