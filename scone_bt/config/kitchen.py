"""The kitchen file: scene geometry, camera and object catalogue (perception/kitchen.yaml)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from scone_bt.config.catalogue import Catalogue, ObjectSpec, catalogue_files, load_catalogue
from scone_bt.config.scene import (
    CameraFile,
    CameraSpec,
    NamedCameraFile,
    SceneFile,
    SceneSpec,
    camera_specs,
    scene_spec,
)
from scone_bt.config.schema import StrictModel, validate
from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError
from scone_bt.resources import data_dir, resolve_file

__all__ = ["ObjectSpec", "Catalogue", "CameraSpec", "SceneSpec", "KitchenConfig", "load_kitchen"]


class KitchenFile(StrictModel):
    """A kitchen file as written: the scene, the cameras (or one ``camera``) and the product files it lists."""

    scene: SceneFile
    cameras: list[NamedCameraFile] | None = None
    camera: CameraFile | None = None
    catalogue: list[str]


KITCHEN_KEYS = tuple(KitchenFile.model_fields)
"""The top-level keys of a kitchen file."""


@dataclass(frozen=True)
class KitchenConfig:
    """A whole kitchen file: scene, cameras (``camera`` is the first shelf camera) and catalogue."""

    scene: SceneSpec
    camera: CameraSpec
    catalogue: Catalogue
    source: Path = field(default=Path("."), compare=False)
    cameras: tuple[CameraSpec, ...] = ()

    @property
    def shelf_cameras(self) -> tuple[CameraSpec, ...]:
        """The cameras that watch the shelving: ``camera`` first, then the others with ``camera``'s noise levels.

        The shelf cameras are one model, so replacing ``camera`` (a proficiency profile's noisier camera) changes
        the noise of all of them.
        """
        first = self.camera
        others = tuple(
            replace(c, noise_std=first.noise_std, depth_noise_std=first.depth_noise_std)
            for c in self.cameras
            if c.role == "shelf" and c.name != first.name
        )
        return (first, *others)

    @property
    def table_camera(self) -> CameraSpec | None:
        """The camera that watches the table, if the kitchen has one."""
        return next((c for c in self.cameras if c.role == "table"), None)


def load_kitchen(
    name_or_path: str | Path = "kitchen", catalogues: Sequence[str | Path] = ()
) -> KitchenConfig:
    """Load a kitchen file by name (perception/<name>.yaml) or path.

    Args:
        name_or_path: The kitchen file.
        catalogues: Extra product files (a user's own products), merged after the kitchen's ``catalogue:`` list.
    """
    path = resolve_file("perception", name_or_path, (".yaml", ".yml"))
    where = str(path)
    f = validate(KitchenFile, read_yaml(path), where)
    scene = scene_spec(f.scene, f"{where}: scene")
    cameras = camera_specs(f.cameras, f.camera, where)
    entries = f.catalogue
    files = catalogue_files(entries, path.parent, data_dir("perception"), str(path)) + [
        Path(c) for c in catalogues
    ]
    if not files:
        raise ConfigError(
            f"{path}: catalogue: lists no product files, so the kitchen has no products; give family files or "
            "folders of them (e.g. catalogue: [catalogue]) or --catalogue FILE"
        )
    catalogue = load_catalogue(files)
    shelf_camera = next(c for c in cameras if c.role == "shelf")
    return KitchenConfig(scene=scene, camera=shelf_camera, catalogue=catalogue, source=path, cameras=cameras)
