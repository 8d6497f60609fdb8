"""The files a kitchen or robot file reads besides itself: what no output of a run may be written over.

Best effort: a file that does not parse (its loader words that error) adds nothing but itself.
"""

from __future__ import annotations

from pathlib import Path

from scone_bt.errors import SconeError

__all__ = ["DESCRIPTION_FILES", "kitchen_inputs", "robot_inputs"]

DESCRIPTION_FILES = 10_000
"""At most this many files of a robot description's folder (its URDF's, with sub-folders) count as inputs."""


def kitchen_inputs(kitchen: Path) -> list[Path]:
    """The kitchen file and the product files its ``catalogue:`` names."""
    from scone_bt.config.catalogue import catalogue_files
    from scone_bt.config.yaml_io import read_yaml
    from scone_bt.resources import data_dir

    out = [kitchen]
    try:
        entries = read_yaml(kitchen).get("catalogue") or []
        out += catalogue_files(entries, kitchen.parent, data_dir("perception"))
    except (SconeError, TypeError, AttributeError):
        pass
    return out


def robot_inputs(robot: Path) -> list[Path]:
    """The robot file, its URDF and the files beside the URDF (meshes), unless the URDF ships with a library."""
    from scone_bt.config.robot import resolve_urdf
    from scone_bt.config.yaml_io import read_yaml

    out = [robot]
    try:
        spec = read_yaml(robot).get("urdf")
        if not isinstance(spec, str) or "://" in spec:
            return out  # pybullet_data:// and the like: a library's files, not the user's
        urdf = resolve_urdf(spec, robot)
    except (SconeError, TypeError, AttributeError):
        return out
    out.append(urdf)
    for path in urdf.parent.rglob("*"):  # lazily: a URDF in a large folder stops at the bound, unsorted
        if len(out) >= DESCRIPTION_FILES:
            break
        if path.is_file() and path != urdf:
            out.append(path)
    return out
