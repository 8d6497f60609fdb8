"""Tree files → py_trees trees. Validation errors name the node and the valid choices."""

from __future__ import annotations

import inspect
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import py_trees
from pydantic import BaseModel, Field, ValidationError, create_model, field_validator

from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.help import WAIT_S
from scone_bt.config.schema import StrictModel, format_validation_error, validate
from scone_bt.config.tree_parameters import TreeParameters
from scone_bt.config.yaml_io import read_yaml
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.resources import resolve_file

if TYPE_CHECKING:
    from scone_bt.behaviours.base import StageBehaviour

__all__ = [
    "TreeSpec",
    "TreeParameters",
    "ARG_MODELS",
    "load_tree_spec",
    "build_tree",
    "render_tree",
    "parameter_name_problem",
]

COMPOSITES = ("sequence", "selector")


@dataclass(frozen=True)
class TreeSpec:
    """A parsed tree file: its root node description and default parameters."""

    name: str
    root: dict[str, Any]
    parameters: dict[str, Any] = field(default_factory=dict)
    source: Path = Path(".")


MAX_DEPTH = 64
"""Nesting limit of a tree file (a deeper one is refused rather than overflowing the stack)."""

_NODE_KEYS = {"behaviour": ("behaviour", "name", "args"), "composite": ("name", "memory", "children")}


class _DecisionIsArgs(StrictModel):
    kind: str

    @field_validator("kind")
    @classmethod
    def _known_kind(cls, kind: str) -> str:
        from scone_bt.gate.types import DecisionKind

        valid = [k.value for k in DecisionKind]
        if kind not in valid:
            raise ValueError(f"unknown decision kind {kind!r}; valid: {', '.join(valid)}")
        return kind


class _WaitForHumanArgs(StrictModel):
    seconds: Annotated[float, Field(gt=0, le=3600, allow_inf_nan=False)] = WAIT_S


ARG_MODELS: dict[str, type[StrictModel]] = {"DecisionIs": _DecisionIsArgs, "WaitForHuman": _WaitForHumanArgs}
"""Argument schemas of behaviours that take arguments; others are checked against their constructor's signature."""


def _signature_model(cls: type[StageBehaviour]) -> type[BaseModel]:
    """A pydantic model of a behaviour's keyword arguments (those of `from_context` after name and context)."""
    build = cls.from_context
    try:
        hints = typing.get_type_hints(build)
    except NameError:  # an annotation only a type checker can resolve: the args are still checked by name
        hints = {}
    fields: dict[str, Any] = {}
    for pname, param in list(inspect.signature(build).parameters.items())[2:]:
        if param.kind not in (param.POSITIONAL_OR_KEYWORD, param.KEYWORD_ONLY):
            continue
        default = ... if param.default is inspect.Parameter.empty else param.default
        fields[pname] = (hints.get(pname, Any), default)
    return create_model(f"{cls.__name__}Args", __base__=StrictModel, **fields)


def _check_args(behaviour: str, args: Any, where: str) -> dict[str, Any]:
    from scone_bt.behaviours import BEHAVIOURS

    model = ARG_MODELS.get(behaviour) or _signature_model(BEHAVIOURS[behaviour])
    if not isinstance(args, dict):
        raise ConfigError(f"{where}: 'args' must be a mapping, got {type(args).__name__}")
    if not model.model_fields and args:
        raise ConfigError(f"{where}: behaviour {behaviour} takes no args (got {', '.join(map(str, args))})")
    return validate(model, args, f"{where} ({behaviour} args)").model_dump()


class _TreeFile(StrictModel):
    """The top level of a tree file."""

    name: str | None = None
    root: Any
    parameters: dict[Any, Any] | None = None


class _BehaviourNode(StrictModel):
    behaviour: str
    name: str | None = None
    args: Any = None  # checked against the behaviour's own model by _check_args

    @field_validator("behaviour")
    @classmethod
    def _known_behaviour(cls, behaviour: str) -> str:
        from scone_bt.behaviours import (
            BEHAVIOURS,
        )  # the registry imports the behaviours: only when a tree is read

        if behaviour not in BEHAVIOURS:
            raise ValueError(f"unknown behaviour {behaviour!r}")
        return behaviour


class _CompositeNode(StrictModel):
    """A sequence or a selector; the kind's key holds its name (renamed to `kind_name` before validation)."""

    kind_name: str
    name: str | None = None
    memory: bool = False
    children: Annotated[list[Any], Field(min_length=1)]


_UNKNOWN_KEY = ("extra_forbidden", "invalid_key")


def _problem(model: type[BaseModel], data: dict[Any, Any]) -> ValidationError | None:
    """pydantic's error with `data`, or None if it fits `model`."""
    try:
        model.model_validate(data)
    except ValidationError as exc:
        return exc
    return None


def _first(exc: ValidationError) -> tuple[str, str]:
    """The problem reported, as (error type, top-level key): an unknown key first, since a misspelt key explains a
    "missing" one and is what the author must fix (`format_validation_error(..., unknown_key_first=True)`)."""
    errors = exc.errors(include_url=False)
    first = next((e for e in errors if e["type"] in _UNKNOWN_KEY), errors[0])
    return first["type"], str(first["loc"][0]) if first["loc"] else ""


def _line(exc: ValidationError, where: str, words: Callable[[str, str], str]) -> str:
    """The project's one line (`format_validation_error`), in the tree file's words for the problem."""

    def say(error: Mapping[str, Any]) -> str:
        return words(str(error["type"]), str(error["loc"][0]) if error["loc"] else "")

    return format_validation_error(exc, where, words=say, unknown_key_first=True)


def _validate(node: Any, where: str, depth: int = 0) -> None:
    """One node of the tree (then its children): pydantic checks it, the message says where and what is valid."""
    if depth > MAX_DEPTH:
        raise ConfigError(f"{where}: the tree is nested deeper than {MAX_DEPTH} levels")
    if not isinstance(node, dict):
        raise ConfigError(
            f"{where}: a node must be a mapping with one of: {', '.join(COMPOSITES)}, behaviour"
        )
    kinds = [k for k in (*COMPOSITES, "behaviour") if k in node]
    if len(kinds) != 1:  # the kind is the discriminator: exactly one of the keys
        raise ConfigError(
            f"{where}: a node needs exactly one of: {', '.join(COMPOSITES)}, behaviour (got {sorted(map(str, node))})"
        )
    kind = kinds[0]
    if "kind_name" in node:  # the name renamed below: a key of that name is unknown
        raise ConfigError(f"{where}: {_node_words(node, kind, 'extra_forbidden', 'kind_name')}")
    if kind == "behaviour":
        problem = _problem(_BehaviourNode, node)
    else:
        problem = _problem(
            _CompositeNode,
            {("kind_name" if k == kind else k): v for k, v in node.items()},
        )
    if problem is not None:
        error, key = _first(problem)
        if key == "behaviour" and error not in _UNKNOWN_KEY:
            from scone_bt.behaviours import BEHAVIOURS

            raise UnknownNameError(f"behaviour at {where}", str(node["behaviour"]), BEHAVIOURS)
        raise ConfigError(_line(problem, where, lambda e, k: _node_words(node, kind, e, k)))
    if kind == "behaviour":
        _check_args(
            node["behaviour"],
            node.get("args") if node.get("args") is not None else {},
            where,
        )
        return
    for i, child in enumerate(node["children"]):
        _validate(child, f"{where}/{node[kind]}[{i}]", depth + 1)


def _node_words(node: dict[Any, Any], kind: str, error: str, key: str) -> str:
    """A node's problem in the tree file's words, naming the choices."""
    allowed = _NODE_KEYS["behaviour" if kind == "behaviour" else "composite"]
    if error in _UNKNOWN_KEY:
        unknown = next(str(k) for k in node if k != kind and k not in allowed)
        return f"unknown key {unknown!r}; valid: {kind}, {', '.join(allowed[1:] if kind == 'behaviour' else allowed)}"
    if key == "name":
        return f"'name' must be text, got {node['name']!r}"
    if key == "kind_name":
        return f"the {kind}'s name must be text, got {node[kind]!r}"
    if key == "memory":
        return f"'memory' must be true or false, got {node['memory']!r}"
    return f"{kind} {node[kind]!r} needs a non-empty 'children' list"


def _check_parameter_names(params: dict[str, Any], path: Path) -> None:
    """The estimator and embedder a tree file names are ones the registries build, or a one-line ConfigError
    naming the file, the key and the valid names (not only when the robot first needs them)."""
    problem = parameter_name_problem(params)
    if problem is not None:
        raise ConfigError(f"{path}: parameters.{problem}")


def parameter_name_problem(params: Mapping[str, Any]) -> str | None:
    """What is wrong with the estimator or embedder `params` names ("estimator: unknown estimator 'x'; valid:
    ..."), or None: the tree file's check, and a scenario's ``world.parameters``'."""
    from scone_bt.confidence.registry import estimator_names

    estimator = params.get("estimator")
    valid = estimator_names()
    if estimator is not None and estimator not in valid:
        return f"estimator: unknown estimator {estimator!r}; valid: {', '.join(valid)}"
    embedder = params.get("embedder")
    if embedder is None:
        return None
    from scone_bt.embedding.registry import embedder_names, names_an_embedder

    names = (
        *embedder_names(),
        "mpnet-ft",
    )  # mpnet-ft: registered once its benchmark is imported
    if embedder == "mpnet-ft" or names_an_embedder(embedder):
        return None
    return (
        f"embedder: unknown embedder {embedder!r}; valid: {', '.join(sorted(set(names)))}, "
        "finetuned:<dir> or a sentence-transformers model directory"
    )


def _file_words(data: dict[Any, Any], error: str, key: str) -> str:
    """A tree file's top-level problem in its words."""
    if error in _UNKNOWN_KEY:
        unknown = next(str(k) for k in data if k not in _TreeFile.model_fields)
        return f"unknown key {unknown!r}; valid: {', '.join(_TreeFile.model_fields)}"
    if key == "root":
        return "missing 'root'"
    if key == "name":
        return f"'name' must be text, got {data['name']!r}"
    return "'parameters' must be a mapping"


def load_tree_spec(name_or_path: str | Path = "assistive_cooking") -> TreeSpec:
    """Read and validate trees/<name>.yaml (or a path): nodes, behaviour names, their args and the parameters.

    Everything a tick would trip over (`{seconds: soon}`, `{kind: maybe}`, `confidence_threshold: high`) is a
    one-line ConfigError here, before the robot acts.
    """
    path = resolve_file("trees", name_or_path, (".yaml", ".yml"))
    data = read_yaml(path)
    problem = _problem(_TreeFile, data)
    if problem is not None:
        raise ConfigError(_line(problem, str(path), lambda error, key: _file_words(data, error, key)))
    _validate(data["root"], f"{path}:root")
    params = data.get("parameters", {}) or {}
    if isinstance(params, dict):  # a name that is not text (`estimator: 5`) is told the valid names too
        for key in ("estimator", "embedder"):
            if key in params and not isinstance(params[key], str):
                _check_parameter_names({key: str(params[key])}, path)
    validate(TreeParameters, params, f"{path}: parameters")
    _check_parameter_names(params, path)
    return TreeSpec(str(data.get("name", path.stem)), data["root"], params, path)


def _build(node: dict[str, Any], context: EpisodeContext) -> py_trees.behaviour.Behaviour:
    from scone_bt.behaviours import BEHAVIOURS

    if "behaviour" in node:
        cls = BEHAVIOURS[node["behaviour"]]
        name = str(node.get("name", node["behaviour"]))
        args = _check_args(node["behaviour"], node.get("args") or {}, f"tree node {name!r}")
        try:
            return cls.from_context(name, context, **args)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"tree node {name!r}: bad args {node.get('args')} ({exc})") from None
    kind = "sequence" if "sequence" in node else "selector"
    composite = py_trees.composites.Sequence if kind == "sequence" else py_trees.composites.Selector
    children = [_build(child, context) for child in node["children"]]
    return composite(name=str(node[kind]), memory=bool(node.get("memory", False)), children=children)


def build_tree(spec: TreeSpec, context: EpisodeContext) -> py_trees.behaviour.Behaviour:
    """Instantiate the tree's behaviours, each wired from ``context`` (an `EpisodeContext`) by its
    `from_context`; call `setup()` on the returned root before ticking."""
    return _build(spec.root, context)


def render_tree(root: py_trees.behaviour.Behaviour, show_status: bool = False) -> str:
    """An ASCII drawing of the tree, optionally with each node's last status."""
    return py_trees.display.ascii_tree(root, show_status=show_status)
