"""Images of the empty kitchen kept on disk, so a fresh process does not render them again.

Every kitchen's first camera images are its products patched over each camera's image of the empty kitchen
(`world.camera.keep_background`): four whole renders (about half a second) before the first decision of every
process. The image is a pure function of what the renderer is given, so it is kept under a digest of exactly
that: every body's shapes (visual and collision, mesh files by content), every link's pose, the camera's
geometry, the PyBullet version and the rendering code itself (`world/camera.py`). Anything that could change a
pixel changes the digest; a file that cannot be read or written is rendered as before, never an error.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.resources import cache_switched_off, default_cache_dir

if TYPE_CHECKING:
    from scone_bt.world.parts import BulletParts

__all__ = [
    "RENDER_CACHE_ENV",
    "FORMAT",
    "MAX_FILES",
    "background_digest",
    "load_background",
    "render_cache_dir",
    "save_background",
]

FORMAT = 2
"""Bumped when what a stored file holds changes (the digest covers the rendering code already)."""
RENDER_CACHE_ENV = "SCONE_BT_RENDER_CACHE"
"""Set to 0 to render every background anew (nothing read or written)."""

_FILE_DIGESTS: dict[tuple[str, int, int], str] = {}
"""Content digests of mesh and source files by (path, size, mtime_ns): each read once per process."""


def render_cache_dir() -> Path | None:
    """Where backgrounds are kept (default_cache_dir()/renders), or None when $SCONE_BT_RENDER_CACHE is 0."""
    if cache_switched_off(RENDER_CACHE_ENV):
        return None
    return default_cache_dir() / "renders"


def _file_digest(path: str | bytes) -> str:
    """sha256 of a file's bytes ('' if it cannot be read: the name alone then stands for it)."""
    name = os.fsdecode(path)
    try:
        st = os.stat(name)
    except OSError:
        return ""
    key = (name, st.st_size, st.st_mtime_ns)
    digest = _FILE_DIGESTS.get(key)
    if digest is None:
        try:
            digest = hashlib.sha256(Path(name).read_bytes()).hexdigest()
        except OSError:
            digest = ""
        _FILE_DIGESTS[key] = digest
    return digest


def _shape_rows(rows: Sequence[Sequence[object]]) -> list[object]:
    """Shape data rows with every mesh file name followed by its content digest."""
    out: list[object] = []
    for row in rows:
        out.append(row)
        out.extend(_file_digest(v) for v in row if isinstance(v, bytes) and v)
    return out


def background_digest(kitchen: BulletParts, geometry: Sequence[object], renderer: str | Path) -> str:
    """A digest of everything the renderer is given for one camera's image of the kitchen as it is now.

    Args:
        kitchen: The kitchen as it is now.
        geometry: What the render depends on in the camera's settings (`world.camera`).
        renderer: The source file of the code that renders (`world/camera.py`): edited, every digest changes.
    """
    import importlib.metadata

    import pybullet as p

    bc = kitchen.bc
    parts: list[object] = [
        FORMAT,
        importlib.metadata.version("pybullet"),
        p.getAPIVersion(),
        _file_digest(str(renderer)),
        tuple(geometry),
    ]
    for i in range(bc.getNumBodies()):
        body = bc.getBodyUniqueId(i)
        parts.append((body, bc.getBasePositionAndOrientation(body)))
        parts.extend(_shape_rows(bc.getVisualShapeData(body)))
        for link in range(-1, bc.getNumJoints(body)):
            parts.extend(_shape_rows(bc.getCollisionShapeData(body, link)))
            if link >= 0:
                parts.append(bc.getLinkState(body, link, computeForwardKinematics=True)[4:6])
    return hashlib.sha256(repr(parts).encode()).hexdigest()


def _path(digest: str) -> Path | None:
    folder = render_cache_dir()
    return None if folder is None else folder / f"background-{digest}.npz"


def load_background(digest: str, width: int, height: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The stored (rgb, depth) for `digest`, read-only, or None (none stored, unreadable or not that size)."""
    path = _path(digest)
    if path is None or not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            rgb, depth = data["rgb"], data["depth"]
    except Exception:  # noqa: BLE001 - any unreadable file (truncated, not a zip, bad CRC) is rendered anew
        return None
    if rgb.shape != (height, width, 3) or rgb.dtype != np.uint8:
        return None
    if depth.shape != (height, width) or depth.dtype != np.float32:
        return None
    rgb.setflags(write=False)
    depth.setflags(write=False)
    return rgb, depth


def save_background(digest: str, rgb: np.ndarray, depth: np.ndarray) -> bool:
    """Store a background (`files.write_atomic`: a reader never sees half a file); False if it could not."""
    import io

    from scone_bt.files import write_atomic

    path = _path(digest)
    if path is None:
        return False
    data = io.BytesIO()
    # A kitchen's flat colours compress ~100x (2.1 MB -> ~20 kB); reading one back takes ~7 ms.
    np.savez_compressed(data, rgb=rgb, depth=depth)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, data.getvalue())
    except OSError:
        return False
    _prune(path.parent)
    return True


MAX_FILES = 1000
"""Backgrounds kept at most (~20 MB); beyond it the least recently written go (generated scene variants)."""


def _prune(folder: Path) -> None:
    """Remove the least recently written backgrounds beyond MAX_FILES (another process may be removing them too)."""
    written: list[tuple[int, Path]] = []
    for f in folder.glob("background-*.npz"):
        try:
            written.append((f.stat().st_mtime_ns, f))
        except OSError:
            continue
    written.sort()
    for _, f in written[: max(0, len(written) - MAX_FILES)]:
        try:
            f.unlink(missing_ok=True)
        except OSError:
            continue
