"""Tree files → py_trees trees. Validation errors name the node and the valid choices."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import py_trees

from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.resources import resolve_file

__all__ = ["TreeSpec", "load_tree_spec", "build_tree", "render_tree"]

COMPOSITES = ("sequence", "selector")


@dataclass(frozen=True)
class TreeSpec:
    """A parsed tree file: its root node description and default parameters."""

    name: str
    root: dict[str, Any]
    parameters: dict[str, Any] = field(default_factory=dict)
    source: Path = Path(".")


def _validate(node: Any, where: str) -> None:
    from scone_bt.behaviours import BEHAVIOURS

    if not isinstance(node, dict):
        raise ConfigError(
            f"{where}: a node must be a mapping with one of: {', '.join(COMPOSITES)}, behaviour"
        )
    kinds = [k for k in (*COMPOSITES, "behaviour") if k in node]
    if len(kinds) != 1:
        raise ConfigError(
            f"{where}: a node needs exactly one of: {', '.join(COMPOSITES)}, behaviour (got {sorted(node)})"
        )
    if kinds[0] == "behaviour":
        if node["behaviour"] not in BEHAVIOURS:
            raise UnknownNameError(f"behaviour at {where}", str(node["behaviour"]), BEHAVIOURS)
        if not isinstance(node.get("args", {}), dict):
            raise ConfigError(f"{where}: 'args' must be a mapping")
        return
    children = node.get("children")
    if not isinstance(children, list) or not children:
        raise ConfigError(f"{where}: {kinds[0]} {node[kinds[0]]!r} needs a non-empty 'children' list")
    for i, child in enumerate(children):
        _validate(child, f"{where}/{node[kinds[0]]}[{i}]")


def load_tree_spec(name_or_path: str | Path = "assistive_cooking") -> TreeSpec:
    """Read and validate trees/<name>.yaml (or a path)."""
    path = resolve_file("trees", name_or_path, (".yaml", ".yml"))
    data = read_yaml(path)
    if "root" not in data:
        raise ConfigError(f"{path}: missing 'root'")
    _validate(data["root"], f"{path}:root")
    params = data.get("parameters", {}) or {}
    if not isinstance(params, dict):
        raise ConfigError(f"{path}: 'parameters' must be a mapping")
    return TreeSpec(str(data.get("name", path.stem)), data["root"], params, path)


def _build(node: dict[str, Any], services: Any) -> py_trees.behaviour.Behaviour:
    from scone_bt.behaviours import BEHAVIOURS

    if "behaviour" in node:
        cls = BEHAVIOURS[node["behaviour"]]
        name = str(node.get("name", node["behaviour"]))
        try:
            return cls(name, services, **node.get("args", {}))
        except TypeError as exc:
            raise ConfigError(f"tree node {name!r}: bad args {node.get('args')} ({exc})") from None
    kind = "sequence" if "sequence" in node else "selector"
    composite = py_trees.composites.Sequence if kind == "sequence" else py_trees.composites.Selector
    children = [_build(child, services) for child in node["children"]]
    return composite(name=str(node[kind]), memory=bool(node.get("memory", False)), children=children)


def build_tree(spec: TreeSpec, services: Any) -> py_trees.behaviour.Behaviour:
    """Instantiate the tree's behaviours (cheap; call `setup()` on the returned root before ticking)."""
    return _build(spec.root, services)


def render_tree(root: py_trees.behaviour.Behaviour, show_status: bool = False) -> str:
    """An ASCII drawing of the tree, optionally with each node's last status."""
    return py_trees.display.ascii_tree(root, show_status=show_status)
