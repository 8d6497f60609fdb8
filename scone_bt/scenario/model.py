"""The scenario file: a situation and the behaviour expected in it, validated before anything runs.

A scenario is a YAML mapping (docs/scenarios.md documents every key; scenarios/scenario.schema.json is the JSON
Schema editors use, exported from `ScenarioFile` by ``scone-scenario schema``). `load_scenario` reads one file
and returns its cases: one, or one per value (per combination) of its ``sweep:``. Every error is one line naming
the file, the key path and the valid choices (`scone_bt.errors.ConfigError`).
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import functools
import itertools
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Union

import numpy as np
from pydantic import BaseModel, Discriminator, Field, Tag, ValidationError, field_validator, model_validator

from scone_bt.config.schema import StrictModel, format_validation_error
from scone_bt.config.yaml_io import read_yaml
from scone_bt.defaults import EPISODE
from scone_bt.errors import ConfigError, SconeError
from scone_bt.events import EVENT_TYPES
from scone_bt.robot.registry import DEFAULT_BACKEND
from scone_bt.stocking.validate import SLOT_PATTERN, KitchenNames, kitchen_names, slots_beside

if TYPE_CHECKING:
    from scone_bt.config.kitchen import KitchenConfig
    from scone_bt.stocking.shelf import ShelfStock

__all__ = [
    "EVENT_ACTIONS",
    "EXPECTATION_KINDS",
    "Case",
    "ScenarioFile",
    "load_scenario",
    "load_scenarios",
    "scenario_files",
    "json_schema",
    "on_backend",
]

_Seconds = Annotated[float, Field(allow_inf_nan=False)]
_NonNeg = Annotated[float, Field(ge=0, allow_inf_nan=False)]
_Prob = Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)]
_Scale = Annotated[float, Field(gt=0, le=4, allow_inf_nan=False)]
_Name = Annotated[str, Field(min_length=1, max_length=200)]

EVENT_KINDS: tuple[str, ...] = tuple(EVENT_TYPES)
"""Stored event kinds (`scone_bt.events.EVENT_TYPES`) a condition or a count may name."""

# The kinds are the event registry's keys, known when the module runs: a type checker sees a string, pydantic the
# Literal of them (its JSON Schema enum and its error naming each).
if TYPE_CHECKING:
    _EventKind = str
else:
    _EventKind = Literal[EVENT_KINDS]


# ------------------------------------------------------------------------------------------------ the world
class Placement(StrictModel):
    """A product pinned to a shelf slot ``unit/tier/index`` (tier 0 the lowest), turned by ``yaw_deg``; its
    ``neighbours`` stand in the slots beside it on the same tier (index + 1, index − 1, index + 2, ...), or, with
    ``gap_m``, that far from its sides (metres; the first further along the tier, the second back; at most 2)."""

    product: _Name
    slot: Annotated[str, Field(pattern=SLOT_PATTERN)]
    yaw_deg: Annotated[float, Field(ge=-180, le=180, allow_inf_nan=False)] = 0.0
    neighbours: Annotated[list[_Name], Field(max_length=8)] = []
    gap_m: Annotated[float, Field(ge=0, le=0.3, allow_inf_nan=False)] | None = None

    def neighbour_slots(self, slots_on_tier: int) -> list[tuple[str, str]]:
        """(product, slot) for each neighbour: the free slots beside this one, nearest first, right first."""
        return list(zip(self.neighbours, slots_beside(self.slot, slots_on_tier), strict=False))


class WorldSection(StrictModel):
    """What the episode is: arm, kitchen, recipe, tree and its parameters, seed, and how the shelf is stocked."""

    robot: str = DEFAULT_BACKEND
    """The robot backend (``scone-run --robot``: sim = PyBullet, mujoco); ``--robot`` of the scenario commands
    overrides it."""
    arm: _Name = EPISODE.arm
    kitchen: _Name = EPISODE.kitchen
    catalogues: Annotated[list[_Name], Field(max_length=20)] = []
    recipe: _Name = EPISODE.recipe
    tree: _Name = EPISODE.tree
    parameters: dict[str, Any] = {}
    self_confidence: bool = True
    seed: Annotated[int, Field(ge=0, le=2**31 - 1)] = EPISODE.seed
    distractors: Annotated[int, Field(ge=0, le=45)] = EPISODE.distractors
    max_ticks: Annotated[int, Field(ge=1, le=20_000)] = EPISODE.max_ticks
    tick_period: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = EPISODE.tick_period
    place: Annotated[list[Placement], Field(max_length=45)] = []
    hidden_markers: Annotated[list[_Name], Field(max_length=45)] = []
    on_table: Annotated[list[_Name], Field(max_length=45)] = []
    experience_from: Annotated[list[Annotated[int, Field(ge=0, le=2**31 - 1)]], Field(max_length=5)] = []

    @field_validator("robot")
    @classmethod
    def _robot(cls, value: str) -> str:
        return _backend_name(value)

    @field_validator("parameters")
    @classmethod
    def _parameters(cls, value: dict[str, Any]) -> dict[str, Any]:
        from scone_bt.config.tree_parameters import TreeParameters
        from scone_bt.tree.build import parameter_name_problem

        try:
            TreeParameters(**value)
        except ValidationError as exc:
            line = format_validation_error(exc, "parameters", TreeParameters)
            raise ValueError(line.removeprefix("parameters: ")) from None
        problem = parameter_name_problem(value)  # as a tree file's: not only when the case runs
        if problem is not None:
            raise ValueError(problem)
        return value


# ------------------------------------------------------------------------------------------------ the robot
class Fault(StrictModel):
    """The robot's condition: each key overrides the robot's or kitchen's value (None keeps it).

    Units: gripper force N per finger, friction coefficient, camera noise 0-255, depth noise m, planner budget s,
    calibration offset m (x, y, z; added to every perceived position), speed scales as fractions of the
    datasheet's joint limits (the robot file's ``limits:``)."""

    gripper_force: Annotated[float, Field(gt=0, le=500, allow_inf_nan=False)] | None = None
    finger_friction: Annotated[float, Field(ge=0, le=5, allow_inf_nan=False)] | None = None
    camera_noise: Annotated[float, Field(ge=0, le=255, allow_inf_nan=False)] | None = None
    depth_noise: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] | None = None
    planner_budget_s: Annotated[float, Field(gt=0, le=600, allow_inf_nan=False)] | None = None
    calibration_offset: (
        Annotated[
            list[Annotated[float, Field(ge=-0.1, le=0.1, allow_inf_nan=False)]],
            Field(min_length=3, max_length=3),
        ]
        | None
    ) = None
    velocity_scale: _Scale | None = None
    acceleration_scale: _Scale | None = None
    jerk_scale: _Scale | None = None

    def values(self) -> dict[str, Any]:
        """The faults given (the keys of `Fault` only, not a subclass's), by `World.apply_fault` argument."""
        out = {k: getattr(self, k) for k in Fault.model_fields if getattr(self, k) is not None}
        if "calibration_offset" in out:
            out["calibration_offset"] = tuple(out["calibration_offset"])
        return out


class RobotSection(Fault):
    """The robot at the start: a proficiency profile (tools/profiles name or path), then individual faults."""

    profile: _Name | None = None


# ------------------------------------------------------------------------------------------------ the human
class HumanSection(StrictModel):
    """The simulated human (`scone_bt.human.HumanOptions`), simulated seconds; how it answers the robot's
    requests: ``help_answer`` fetch or decline ("try it yourself"), ``clarify_answer`` right, wrong or none."""

    patience_s: _NonNeg = 20.0
    takeover_probability: _Prob = EPISODE.takeover_probability
    takeover_delay_s: _NonNeg = 1.0
    fetch_time_s: _NonNeg = 6.0
    cook_time_s: _NonNeg = 2.0
    clarify_time_s: _NonNeg = 2.0
    help_answer: Literal["fetch", "decline"] = "fetch"
    clarify_answer: Literal["right", "wrong", "none"] = "right"


# ------------------------------------------------------------------------------------------------ conditions
class EventMatch(StrictModel):
    """Matches one typed event: its stored ``kind`` and, if given, its fields."""

    kind: _EventKind
    object: _Name | None = None
    success: bool | None = None
    stage: _Name | None = None
    verdict: Literal["act", "ask", "clarify", "idle"] | None = None
    rule: str | None = None
    step: Annotated[int, Field(ge=1)] | None = None
    explored: bool | None = None


# ------------------------------------------------------------------------------------------------ events
class _Timing(StrictModel):
    at: _Seconds | None = None
    when: EventMatch | None = None
    delay_s: _NonNeg = 0.0

    @model_validator(mode="after")
    def _one_trigger(self) -> _Timing:
        if (self.at is None) == (self.when is None):
            raise ValueError("give exactly one of 'at' (simulated seconds) or 'when' (an event to wait for)")
        if self.at is not None and self.at < 0:
            raise ValueError(f"at: {self.at} s is in the past (the episode starts at 0 s)")
        return self


class MoveEvent(_Timing):
    move: Placement


class Swap(StrictModel):
    """Two stocked products exchange places (``with``: a look-alike of ``product``)."""

    product: _Name
    with_: _Name = Field(alias="with")


class SwapEvent(_Timing):
    swap: Swap


class RemoveEvent(_Timing):
    remove: _Name


class ToTableEvent(_Timing):
    to_table: _Name


class HideMarkerEvent(_Timing):
    hide_marker: _Name


class ShowMarkerEvent(_Timing):
    show_marker: _Name


class CoverCameraEvent(_Timing):
    cover_camera: _Name


class UncoverCameraEvent(_Timing):
    uncover_camera: _Name


class FaultEvent(_Timing):
    fault: Fault


class NextStepEvent(_Timing):
    next_step: Literal[True]


EVENT_ACTIONS: dict[str, type[_Timing]] = {
    "move": MoveEvent,
    "swap": SwapEvent,
    "remove": RemoveEvent,
    "to_table": ToTableEvent,
    "hide_marker": HideMarkerEvent,
    "show_marker": ShowMarkerEvent,
    "cover_camera": CoverCameraEvent,
    "uncover_camera": UncoverCameraEvent,
    "fault": FaultEvent,
    "next_step": NextStepEvent,
}
"""What a scenario event does → its model."""


def _tag(keys: Sequence[str]) -> Any:
    def pick(value: Any) -> str | None:
        if isinstance(value, Mapping):
            found = [k for k in keys if k in value]
            return found[0] if len(found) == 1 else None
        found = [k for k in keys if getattr(value, k, None) is not None]
        return found[0] if len(found) == 1 else None

    return pick


def _union(table: Mapping[str, type[StrictModel]], what: str) -> Any:
    members = tuple(Annotated[model, Tag(key)] for key, model in table.items())
    return Annotated[
        Union[members],  # noqa: UP007 (a tuple of tagged members)
        Discriminator(
            _tag(list(table)),
            custom_error_type="one_of",
            custom_error_message=f"{what} needs exactly one of: {', '.join(table)}",
        ),
    ]


# Built from the table, so that a new event is one entry there: a type checker sees the members' base class,
# pydantic the union tagged by each member's key.
if TYPE_CHECKING:
    ScenarioEvent = _Timing
else:
    ScenarioEvent = _union(EVENT_ACTIONS, "an event")


# ------------------------------------------------------------------------------------------------ expectations
class _Expectation(StrictModel):
    name: _Name | None = None  # how failures call it (default: the expectation as written)


class AsksBeforeAttempt(_Expectation):
    """The robot asks for help with the product (ASK-HELP) before it ever attempts it (it may never attempt)."""

    asks_before_attempt: _Name


class NeverAttempts(_Expectation):
    """The robot never starts a pick-and-place of the product."""

    never_attempts: _Name


class CompletesStep(_Expectation):
    """Recipe step ``completes_step`` (1-based) is done within ``within_s`` simulated seconds."""

    completes_step: Annotated[int, Field(ge=1)]
    within_s: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None


class Completes(_Expectation):
    """The whole recipe is done (``true``) or not (``false``) when the episode ends; optionally within a time."""

    completes: bool
    within_s: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None


class MaxFailures(_Expectation):
    """At most this many of the robot's attempts fail (optionally only of one ``object``)."""

    max_failures: Annotated[int, Field(ge=0)]
    object: _Name | None = None


class Kappa(_Expectation):
    """κ̂ of the product's action, at the robot's first decision about it after ``after`` (an event; without it:
    the first decision about it), is below or above a value."""

    kappa: _Name
    below: _Prob | None = None
    above: _Prob | None = None
    after: EventMatch | None = None

    @model_validator(mode="after")
    def _bound(self) -> Kappa:
        if (self.below is None) == (self.above is None):
            raise ValueError("give exactly one of 'below' or 'above'")
        return self


class NoRepeatedFailure(_Expectation):
    """No failure repeats: the same action never fails twice at the same stage."""

    no_repeated_failure: Literal[True]


class DecisionsMatch(_Expectation):
    """The decision sequence, written ``verdict:object`` per decision separated by spaces (``act:salt ask:garlic
    clarify:- idle:-``), matches this regular expression somewhere (``re.search``)."""

    decisions_match: Annotated[str, Field(min_length=1, max_length=2000)]

    @field_validator("decisions_match")
    @classmethod
    def _regex(cls, value: str) -> str:
        try:
            re.compile(value)
        except re.error as exc:
            raise ValueError(f"not a regular expression ({exc})") from None
        return value


class Count(_Expectation):
    """The number of events matching ``count`` is within [``min``, ``max``]."""

    count: EventMatch
    min: Annotated[int, Field(ge=0)] = 0
    max: Annotated[int, Field(ge=0)] | None = None

    @model_validator(mode="after")
    def _bounds_meet(self) -> Count:
        if self.max is not None and self.min > self.max:
            raise ValueError(f"min {self.min} is above max {self.max}: no count passes")
        return self


class OnTable(_Expectation):
    """At the end, these products rest on the table (ground truth)."""

    on_table: Annotated[list[_Name], Field(min_length=1)]


EXPECTATION_KINDS: dict[str, type[_Expectation]] = {
    "asks_before_attempt": AsksBeforeAttempt,
    "never_attempts": NeverAttempts,
    "completes_step": CompletesStep,
    "completes": Completes,
    "max_failures": MaxFailures,
    "kappa": Kappa,
    "no_repeated_failure": NoRepeatedFailure,
    "decisions_match": DecisionsMatch,
    "count": Count,
    "on_table": OnTable,
}
"""Expectation key → its model."""

# As ScenarioEvent: the members' base class for a type checker, the tagged union for pydantic.
if TYPE_CHECKING:
    Expectation = _Expectation
else:
    Expectation = _union(EXPECTATION_KINDS, "an expectation")


# ------------------------------------------------------------------------------------------------ sweeps
class SweepRange(StrictModel):
    """Values ``start``, ``start + step``, ... up to ``stop`` (inclusive)."""

    start: _Seconds
    stop: _Seconds
    step: Annotated[float, Field(gt=0, allow_inf_nan=False)]

    def count(self) -> float:
        """How many values the range holds (a float: a huge or overflowing range is told, not built)."""
        return float(np.floor((self.stop - self.start) / self.step + 1e-9)) + 1

    @model_validator(mode="after")
    def _bounded(self) -> SweepRange:
        # As many values as a sweep list may hold: a range is its shorthand, not a way to run forever.
        n = self.count()
        if not np.isfinite(n) or n > MAX_SWEEP_VALUES:
            raise ValueError(
                f"the range from {self.start:g} to {self.stop:g} in steps of {self.step:g} holds more than "
                f"{MAX_SWEEP_VALUES} values; give a larger step or a shorter range"
            )
        return self

    def values(self) -> list[float]:
        n = int(self.count())
        return [round(self.start + i * self.step, 10) for i in range(max(n, 0))]


MAX_SWEEP_VALUES = 50
"""Most values one swept key takes (a list or a range)."""
MAX_SWEEP_CASES = 500
"""Most cases one scenario file's sweep makes (the product of its keys' values)."""


def _sweep_kind(value: Any) -> str:
    """A mapping is a range, anything else a list: each is validated as what it is (errors say so)."""
    return "range" if isinstance(value, (dict, SweepRange)) else "list"


_SweepValues = Annotated[
    Annotated[Annotated[list[Any], Field(min_length=1, max_length=MAX_SWEEP_VALUES)], Tag("list")]
    | Annotated[SweepRange, Tag("range")],
    Discriminator(_sweep_kind),
]


def _backend_name(value: str) -> str:
    from scone_bt.robot.registry import BACKENDS

    if value not in BACKENDS:
        raise ValueError(f"unknown robot backend {value!r}; valid: {', '.join(sorted(BACKENDS))}")
    return value


class BackendExpectation(StrictModel):
    """How a case is expected to end on one robot backend, where that differs from the file's ``expected``."""

    expected: Literal["pass", "fail"] = "fail"
    reason: Annotated[str, Field(min_length=1, max_length=2000)]


class ScenarioFile(StrictModel):
    """A scenario file (scenarios/*.yaml)."""

    description: Annotated[str, Field(min_length=1, max_length=2000)]
    name: Annotated[str, Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")] | None = None
    expected: Literal["pass", "fail"] = "pass"
    reason: Annotated[str, Field(min_length=1, max_length=2000)] | None = None
    tags: Annotated[list[Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,30}$")]], Field(max_length=10)] = []
    world: WorldSection = WorldSection()
    robot: RobotSection = RobotSection()
    human: HumanSection = HumanSection()
    events: Annotated[list[ScenarioEvent], Field(max_length=100)] = []
    expect: Annotated[list[Expectation], Field(min_length=1, max_length=100)]
    sweep: dict[str, _SweepValues] = {}
    expected_on: dict[str, BackendExpectation] = {}
    """Per robot backend (by name), an ``expected`` and its ``reason`` that replace the file's on that backend
    (a case that fails on one engine for a measured engine difference)."""

    @field_validator("expected_on")
    @classmethod
    def _expected_on(cls, value: dict[str, BackendExpectation]) -> dict[str, BackendExpectation]:
        for name in value:
            _backend_name(name)
        return value

    @model_validator(mode="after")
    def _reason(self) -> ScenarioFile:
        if self.expected == "fail" and not self.reason:
            raise ValueError("expected: fail needs a 'reason' (the bug it exposes)")
        return self


# ------------------------------------------------------------------------------------------------ cases
@dataclass(frozen=True)
class Case:
    """One run of a scenario: the file, the case's name and its validated content (sweep values filled in).

    Attributes:
        path: The scenario file.
        name: The scenario's name, with ``[key=value,...]`` for a sweep case.
        spec: The validated scenario.
        sweep: The sweep values of this case (key path → value), empty without a sweep.
    """

    path: Path
    name: str
    spec: ScenarioFile
    sweep: tuple[tuple[str, Any], ...] = ()

    @property
    def base(self) -> Path:
        """The folder relative paths in the file are read from."""
        return self.path.parent


def _error_line(exc: ValidationError, where: str) -> str:
    """The project's one line, with the discriminator tags pydantic puts into key paths taken out."""
    tags = set(EVENT_ACTIONS) | set(EXPECTATION_KINDS)
    errors = exc.errors(include_url=False)
    first = errors[0]
    loc = list(first.get("loc", ()))
    cleaned: list[Any] = []
    for i, part in enumerate(loc):
        if isinstance(part, str) and part in tags and i > 0 and isinstance(loc[i - 1], int):
            continue  # the union member's tag: the key itself follows (or the error is about the whole item)
        if part in ("list", "range") and i == 2 and loc[0] == "sweep":
            continue  # a sweep's values: a list or a range (its tags, not keys of the file)
        cleaned.append(part)
    key = ""
    for part in cleaned:
        key += f"[{part}]" if isinstance(part, int) else ("." if key else "") + str(part)
    kind = first.get("type", "")
    if kind == "extra_forbidden":
        owner = _owner(loc)
        valid = f"; valid: {', '.join(owner.model_fields)}" if owner is not None else ""
        parent = key.rsplit(".", 1)[0] if "." in key else ""
        head = f"{where}: {parent}: " if parent else f"{where}: "
        msg = f"{head}unknown key {str(loc[-1])!r}{valid}"
    else:
        text = " ".join(str(first.get("msg", "invalid")).split()).removeprefix("Value error, ")
        value = first.get("input")
        if kind not in ("value_error", "one_of", "missing") and not isinstance(value, (dict, list)):
            text += f" (got {_short(value)})"
        if kind == "missing":
            text = "missing (required)"
        if kind in ("model_type", "model_attributes_type", "dict_type"):  # pydantic names the model class
            owner = _owner((*loc, ""))
            keys = f" ({', '.join(owner.model_fields)})" if owner is not None else ""
            text = f"must be a mapping of keys to values{keys} (got {_short(value)})"
        if kind == "one_of" and isinstance(value, Mapping):
            text += f" (got keys: {', '.join(map(str, value)) or 'none'})"
        msg = f"{where}: {key}: {text}" if key else f"{where}: {text}"
    more = len(errors) - 1
    return msg + (f" (and {more} more problem{'s' if more > 1 else ''})" if more else "")


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _owner(loc: Sequence[Any]) -> type[BaseModel] | None:
    """The model whose key ``loc[-1]`` is unknown."""
    tables = {**EVENT_ACTIONS, **EXPECTATION_KINDS}
    current: Any = ScenarioFile
    for i, part in enumerate(loc[:-1]):
        if isinstance(part, int):
            continue
        if i > 0 and isinstance(loc[i - 1], int) and part in tables:
            current = tables[part]
            continue
        if not (isinstance(current, type) and issubclass(current, BaseModel)):
            return None
        field = current.model_fields.get(str(part))
        if field is None:
            return None
        current = None
        stack = [field.annotation]
        while stack:
            ann = stack.pop()
            if isinstance(ann, type) and issubclass(ann, BaseModel):
                current = ann
                break
            stack.extend(getattr(ann, "__args__", ()))
    return current if isinstance(current, type) and issubclass(current, BaseModel) else None


def _validate(data: Any, where: str) -> ScenarioFile:
    try:
        return ScenarioFile.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(_error_line(exc, where)) from None


def _set_path(data: dict[str, Any], path: str, value: Any, where: str) -> None:
    """Put ``value`` at a dotted key path (``robot.gripper_force``, ``events[0].at``) of the raw mapping."""
    parts: list[str | int] = []
    for piece in path.split("."):
        m = re.fullmatch(r"([A-Za-z0-9_-]+)((?:\[\d+\])*)", piece)
        if not m:
            raise ConfigError(
                f"{where}: sweep: {path!r} is not a key path like robot.gripper_force or events[0].at"
            )
        parts.append(m.group(1))
        parts.extend(int(i) for i in re.findall(r"\[(\d+)\]", m.group(2)))
    node: Any = data
    for i, part in enumerate(parts[:-1]):
        nxt = parts[i + 1]
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise ConfigError(f"{where}: sweep: {path!r}: no item {part} to set")
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise ConfigError(f"{where}: sweep: {path!r}: {part!r} is not inside a mapping")
        if part not in node:
            if isinstance(nxt, int):
                raise ConfigError(f"{where}: sweep: {path!r}: {part!r} has no items to set")
            node[part] = {}
        node = node[part]
    last = parts[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise ConfigError(f"{where}: sweep: {path!r}: no item {last} to set")
        node[last] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise ConfigError(f"{where}: sweep: {path!r}: {last!r} is not inside a mapping")


def _label(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def load_scenario(path: Path | str) -> list[Case]:
    """The cases of one scenario file (one per sweep combination), each validated and checked against the world.

    Raises:
        ConfigError: One line naming the file, the key path and the valid choices.
    """
    path = Path(path)
    raw = read_yaml(path)
    where = str(path)
    spec = _validate(raw, where)
    name = spec.name or path.stem
    if not spec.sweep:
        check_world(spec, path, where)
        return [Case(path, name, spec)]
    keys = list(spec.sweep)
    columns = [v.values() if isinstance(v, SweepRange) else list(v) for v in spec.sweep.values()]
    for key, column in zip(keys, columns, strict=True):
        if not column:
            raise ConfigError(f"{where}: sweep.{key}: the range has no values (stop is before start)")
    combinations = math.prod(len(c) for c in columns)
    if combinations > MAX_SWEEP_CASES:
        raise ConfigError(
            f"{where}: sweep: {' × '.join(str(len(c)) for c in columns)} = {combinations} cases, more than "
            f"{MAX_SWEEP_CASES}; sweep fewer values or split the file"
        )
    cases = []
    for combo in itertools.product(*columns):
        data = copy.deepcopy(raw)
        data.pop("sweep", None)
        for key, value in zip(keys, combo, strict=True):
            if key.split(".")[0].split("[")[0] in (
                "sweep",
                "expected_on",
                "name",
                "expected",
                "reason",
                "description",
                "tags",
            ):
                raise ConfigError(f"{where}: sweep.{key}: cannot sweep {key.split('.')[0]!r}")
            _set_path(data, key, value, where)
        label = ",".join(f"{k}={_label(v)}" for k, v in zip(keys, combo, strict=True))
        case_where = f"{where} [{label}]"
        case_spec = _validate(data, case_where)
        check_world(case_spec, path, case_where)
        cases.append(Case(path, f"{name}[{label}]", case_spec, tuple(zip(keys, combo, strict=True))))
    return cases


def on_backend(case: Case, backend: str | None, arm: str | None = None) -> Case:
    """The case as it runs on the robot backend ``backend`` (None: the file's ``world.robot``), with that backend's
    ``expected_on`` entry in force, and with the robot file ``arm`` (None: the file's ``world.arm``).

    Raises:
        SconeError: ``backend`` is not a backend's name (one line naming the valid ones, or saying to give a robot
            file with ``--arm``), or ``arm`` is not a robot file (one line naming the valid ones).
    """
    from scone_bt.config import load_robot
    from scone_bt.robot.flags import check_backend

    if backend is not None:
        check_backend(backend)
    world: dict[str, Any] = {"robot": backend or case.spec.world.robot}
    if arm is not None:
        load_robot(arm)  # a bad robot file stops here, before any case runs
        world["arm"] = str(Path(arm).resolve()) if Path(arm).is_file() else arm
    spec = case.spec
    name = world["robot"]
    update: dict[str, Any] = {"world": spec.world.model_copy(update=world)}
    if name in spec.expected_on:
        entry = spec.expected_on[name]
        update |= {"expected": entry.expected, "reason": entry.reason}
    return dataclasses.replace(case, spec=spec.model_copy(update=update))


def resolve_input(value: str, base: Path) -> str:
    """A file reference as the loaders take it: a path relative to the scenario file when it names one there, else
    as given (relative to the working folder); a path found in neither names the scenario's folder, so the error
    says where it was looked for."""
    candidate = base / value
    looks_like_a_path = "/" in value or value.endswith((".yaml", ".yml", ".json"))
    if looks_like_a_path and (candidate.is_file() or not Path(value).exists()):
        return str(candidate)
    return value


@dataclass(frozen=True)
class _Episode:
    """What a scenario is checked against: the stocked kitchen's names (`scone_bt.stocking.validate`), the
    recipe's step count and the episode's end (s)."""

    names: KitchenNames
    steps: int
    end_s: float

    @property
    def where(self) -> str:
        """What starts each error: the file, and the case of a sweep."""
        return self.names.where


def _episode_of(spec: ScenarioFile, path: Path, where: str) -> _Episode:
    """The kitchen the scenario names, stocked for its seed (its files loaded; the profile's name checked)."""
    base = path.parent
    w = spec.world
    try:
        kitchen, stock, steps = _episode_world(
            resolve_input(w.kitchen, base),
            tuple(resolve_input(c, base) for c in w.catalogues),
            resolve_input(w.arm, base),
            resolve_input(w.tree, base),
            resolve_input(w.recipe, base),
            w.distractors,
            w.seed,
        )
        if spec.robot.profile is not None:
            profile_path(spec.robot.profile, base)
    except SconeError as exc:
        raise ConfigError(f"{where}: world: {exc}") from None
    return _Episode(kitchen_names(kitchen, stock, where), steps, w.max_ticks * w.tick_period)


def check_world(spec: ScenarioFile, path: Path, where: str) -> None:
    """Check the scenario against the kitchen it names: products, slots, cameras, times, the profile.

    Loads the kitchen, catalogue, recipe, robot and tree files and draws the seeded stocking (pure and cheap), so
    a name that is not in this episode's kitchen is an error before the simulator starts.
    """
    k = _episode_of(spec, path, where)
    w = spec.world
    k.names.placements(w.place)
    k.names.products(w.hidden_markers, "world.hidden_markers")
    k.names.products(w.on_table, "world.on_table")
    for i, ev in enumerate(spec.events):
        _check_event(ev, f"events[{i}]", k)
    for i, ex in enumerate(spec.expect):
        _check_expectation(ex, f"expect[{i}]", k)


def _check_event(ev: Any, key: str, k: _Episode) -> None:
    """One event: its time within the episode, the products, slot and camera it names, its condition."""
    if ev.at is not None and ev.at > k.end_s:
        raise ConfigError(
            f"{k.where}: {key}.at: {ev.at:g} s is after the episode's end ({k.end_s:g} s: max_ticks × tick_period)"
        )
    for field in ("remove", "to_table", "hide_marker", "show_marker"):
        if getattr(ev, field, None) is not None:
            k.names.product(getattr(ev, field), f"{key}.{field}")
    if isinstance(ev, SwapEvent):
        k.names.product(ev.swap.product, f"{key}.swap.product")
        k.names.product(ev.swap.with_, f"{key}.swap.with")
    if isinstance(ev, MoveEvent):
        k.names.product(ev.move.product, f"{key}.move.product")
        k.names.slot(ev.move.slot, f"{key}.move.slot")
    for field in ("cover_camera", "uncover_camera"):
        cam = getattr(ev, field, None)
        if cam is not None:
            k.names.camera(cam, f"{key}.{field}")
    if ev.when is not None:
        _check_match(ev.when, f"{k.where}: {key}.when", set(k.names.catalogue))
        if ev.when.object is not None:
            k.names.product(ev.when.object, f"{key}.when.object")


def _check_expectation(ex: Any, key: str, k: _Episode) -> None:
    """One expectation: the products and events it names, its step within the recipe, its time within the
    episode."""
    if isinstance(ex, Count):  # a misspelt name would match no event, and the count would pass vacuously
        _check_match(ex.count, f"{k.where}: {key}.count", set(k.names.catalogue))
    for field in ("asks_before_attempt", "never_attempts", "kappa", "object"):
        if getattr(ex, field, None) is not None:
            k.names.product(getattr(ex, field), f"{key}.{field}")
    if isinstance(ex, OnTable):
        k.names.products(ex.on_table, f"{key}.on_table")
    if isinstance(ex, CompletesStep) and ex.completes_step > k.steps:
        raise ConfigError(
            f"{k.where}: {key}.completes_step: the recipe has steps 1-{k.steps} (got {ex.completes_step})"
        )
    for field in ("within_s",):
        t = getattr(ex, field, None)
        if t is not None and t > k.end_s:
            raise ConfigError(f"{k.where}: {key}.{field}: {t:g} s is after the episode's end ({k.end_s:g} s)")


def _check_match(match: EventMatch, where: str, products: set[str]) -> None:
    """An event match's product, failure stage and decision rule against what exists (one line naming the valid
    ones)."""
    from scone_bt.gate.types import DECISION_RULES
    from scone_bt.motion.types import FailureStage

    if match.object is not None and match.object not in products:
        close = difflib.get_close_matches(match.object, sorted(products), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ConfigError(f"{where}.object: {match.object!r} is not a product of the catalogue{hint}")
    stages = [s.value for s in FailureStage]
    if match.stage is not None and match.stage not in stages:
        raise ConfigError(f"{where}.stage: unknown failure stage {match.stage!r}; valid: {', '.join(stages)}")
    if match.rule is not None and match.rule not in ("", *DECISION_RULES):
        # a misspelt rule matched nothing, so "max: 0" of it passed whatever the robot did
        raise ConfigError(
            f"{where}.rule: unknown decision rule {match.rule!r}; valid: {', '.join(DECISION_RULES)}, "
            "or '' (κ̂ against the threshold)"
        )


@functools.lru_cache(maxsize=64)
def _episode_world(
    kitchen_file: str,
    catalogues: tuple[str, ...],
    arm: str,
    tree: str,
    recipe: str,
    distractors: int,
    seed: int,
) -> tuple[KitchenConfig, ShelfStock, int]:
    """The kitchen, its stocking and the recipe's step count, as the episode will draw them (cached: the cases of
    a sweep share one world)."""
    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.recipes import load_recipe
    from scone_bt.stocking import stock_shelf
    from scone_bt.tree import load_tree_spec

    kitchen = load_kitchen(kitchen_file, catalogues)
    load_robot(arm)
    load_tree_spec(tree)
    shelf = stock_shelf(
        load_recipe(recipe),
        kitchen.catalogue,
        kitchen.scene,
        distractors,
        np.random.default_rng(seed),
        option="distractors",
    )
    return kitchen, shelf, len(shelf.recipe.steps)


def profile_path(name: str, base: Path) -> Path:
    """A proficiency profile: a file relative to the scenario, or a name in tools/profiles (without .yaml)."""
    from scone_bt.resources import repo_root

    candidate = base / name
    if candidate.is_file():
        return candidate
    root = repo_root()
    folder = (root if root is not None else Path.cwd()) / "tools" / "profiles"
    known = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
    if name in known:
        return folder / f"{name}.yaml"
    raise ConfigError(f"unknown profile {name!r}; valid: {', '.join(known) or '(tools/profiles not found)'}")


def scenario_files(paths: Sequence[Path | str]) -> list[Path]:
    """The scenario files named or inside the folders named (``*.yaml``, not recursing into sub-folders)."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(x for x in p.glob("*.yaml") if x.is_file())
            if not found:
                raise ConfigError(f"{p}: no scenario files (*.yaml)")
            out.extend(found)
        elif p.exists():
            out.append(p)
        else:
            raise ConfigError(f"{p}: file not found")
    return out


def load_scenarios(paths: Sequence[Path | str]) -> list[Case]:
    """Every case of every scenario file named (or in the folders named); names must be unique."""
    cases: list[Case] = []
    seen: dict[str, Path] = {}
    for path in scenario_files(paths):
        for case in load_scenario(path):
            if case.name in seen:
                raise ConfigError(f"{path}: scenario name {case.name!r} is also used by {seen[case.name]}")
            seen[case.name] = path
            cases.append(case)
    return cases


def json_schema() -> dict[str, Any]:
    """The JSON Schema of a scenario file (for editors: ``# yaml-language-server: $schema=scenario.schema.json``)."""
    schema = ScenarioFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "SCONE-BT scenario"
    return schema
