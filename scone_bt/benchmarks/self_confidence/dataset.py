"""Self-confidence datasets: one file per robot, one row per attempted action, its outcome and its context.

Schema of the generator's CSV (`COLUMNS`, in this order; a reader accepts extra columns, and needs only action,
object and outcome):
    index              execution number within the profile (0-based)
    action             the action text ("Put salt on table")
    object             catalogue name of the target
    family             the catalogue's packaging family of the target ("cans", "spice jars", ...)
    outcome            "success" or "failure" (a reader also accepts 1/0, true/false)
    failure_stage      empty on success, else where it failed (perception, ik, planning, grasp, ...)
    seed               the seed of that execution
    detail             what the pipeline reported
    shelf_unit         shelf unit under the detected target (empty when not detected)
    shelf_tier         tier of that unit under the detected top face, 0 = lowest (empty when not detected)
    slot               slot nearest the detection, index into the scene's slots (empty when not detected)
    clearance_m        gap between the target's side and its nearest detected neighbour on the tier, metres
    neighbours         detected products whose centre is within 0.15 m of the target's
    detected           1 if the shelf cameras detected the target, else 0
    detected_width_m   perceived lid width from the depth image, metres (empty when not detected or measured)
    detected_height_m  perceived height above the shelf step, metres (empty likewise)
    width_m            catalogue grasp width (narrowest horizontal extent), metres
    height_m           catalogue height, metres
    mass_kg            catalogue mass, kilograms
    material           catalogue material
    detected_depth_m   perceived longer horizontal extent of the lid, metres (empty when not measured)
    detected_fill      perceived lid area over its bounding rectangle (π/4 cylinder, 1 box; empty likewise)
    depth_m            catalogue longer horizontal extent, metres
    shape              catalogue shape (box, cylinder)
    probe_held         the heft test (motion.probe, sensing only): 1 if the fingers still held it after the hold
    probe_load_n       vertical load the fingers carried over the hold's second half, newtons
    probe_load_first_n the same over its first half, newtons
    probe_grip_n       the fingers' summed grip force over the second half, newtons
    probe_s            simulated seconds the probe took (all probe columns empty when the arm never held it up)
    probe_pressed      1 if the fingers' vertical force pointed down over the second half (they did not carry it
                       up: a fingertip on its top, or they rose past it), else 0 (empty likewise)
    probe_drift_mm     how far the contacts moved on the farther finger's pad, millimetres (empty: not measured)
    probe_drift_both_mm the same on the nearer finger: how far they moved on both pads (empty likewise)
    probe_wrist_load_n the vertical load the whole hand carried over the second half (the wrist's reading), newtons
    probe_wrist_load_first_n the same over the first half (both empty when not measured)
    probe_in_place     after fingers that closed on nothing: 1 if the product still stood where it stood once the
                       hand had left, else 0 (empty for every other execution)

The last fifteen columns came later: a file without them is still read (they are then unknown). Every column from shelf_unit to detected_height_m is what the robot perceived, computed by the episode's own
context function (`scone_bt.perception.context.execution_contexts`, see generate.perceived_context); an undetected
target leaves them empty (detected 0). width_m to material describe the product, not what the robot knew.

An experience store export (`ExperienceStore.export_csv`) is read too: its `object_name` and `success` columns
stand for `object` and `outcome`; when its `context` JSON names several robots (or profiles), each becomes its
own dataset.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from scone_bt.errors import ConfigError

__all__ = [
    "COLUMNS",
    "CONTEXT_COLUMNS",
    "PROBE_COLUMNS",
    "PROBE_READING_COLUMNS",
    "PROBE_SENSED_COLUMNS",
    "Dataset",
    "ExecutionRecord",
    "load_datasets",
    "read_dataset",
    "read_records",
    "write_records",
]

PROBE_COLUMNS = ("probe_held", "probe_load_n", "probe_load_first_n", "probe_grip_n", "probe_s")
"""What the generator's probe felt, in the order the replay reads them
(scone_bt.benchmarks.replay_streams.probe_readings): all of them, or none (the arm never held it up)."""

PROBE_SENSED_COLUMNS = (
    "probe_pressed",
    "probe_drift_mm",
    "probe_drift_both_mm",
    "probe_wrist_load_n",
    "probe_wrist_load_first_n",
)
"""What the hand sensed beside them (a later schema: files before it lack them), in the order the replay reads
them after PROBE_COLUMNS: each given only where probe_held is, and each may be unmeasured (empty)."""

PROBE_READING_COLUMNS = (*PROBE_COLUMNS, *PROBE_SENSED_COLUMNS, "probe_in_place")
"""Every column of a probe's reading, in the order the replay reads them (replay_streams.probe_readings):
``probe_in_place`` is given only where nothing was felt (a miss)."""

COLUMNS = (
    "index",
    "action",
    "object",
    "family",
    "outcome",
    "failure_stage",
    "seed",
    "detail",
    "shelf_unit",
    "shelf_tier",
    "slot",
    "clearance_m",
    "neighbours",
    "detected",
    "detected_width_m",
    "detected_height_m",
    "width_m",
    "height_m",
    "mass_kg",
    "material",
    "detected_depth_m",
    "detected_fill",
    "depth_m",
    "shape",
    *PROBE_READING_COLUMNS,
)
"""Columns the generator writes, in this order (see the module docstring)."""

CONTEXT_COLUMNS = (
    "shelf_tier",
    "slot",
    "clearance_m",
    "neighbours",
    "detected",
    "detected_width_m",
    "detected_height_m",
    "width_m",
    "height_m",
    "mass_kg",
    "detected_depth_m",
    "detected_fill",
    "depth_m",
    *PROBE_READING_COLUMNS,
)
"""Numeric context columns, read into `Dataset.context` as float arrays (NaN where a row leaves one empty)."""

_LATER = COLUMNS[COLUMNS.index("detected_depth_m") :]
"""Columns a file of the previous schema lacks (read as unknown): those after ``material``, the last it had."""

_TRUE = {"success", "1", "true", "yes", "ok"}
_FALSE = {"failure", "0", "false", "no", "fail"}
_SPLIT_KEYS = ("profile", "robot")


@dataclass(frozen=True)
class ExecutionRecord:
    """One simulated pick-and-place and the context it ran in (units in the column names: m, kg).

    Attributes:
        index: Position of the execution in its profile (0-based).
        action: Action text.
        object: Catalogue name of the target.
        success: Whether the target ended upright on the table.
        failure_stage: None on success, else the FailureStage value.
        seed: Seed of the execution.
        detail: Human-readable detail of the outcome.
        family: Packaging family of the target.
        shelf_unit: Shelf unit under its detection ("" when not detected).
        shelf_tier: Tier of that unit, 0 = lowest (None when not detected or off the shelf).
        slot: Slot nearest its detection (index into SceneSpec.slots(); None when not detected).
        clearance_m: Gap to the nearest detected product on its tier, metres (None when unknown).
        neighbours: Detected products within 0.15 m of it (None when not detected).
        detected: Whether the shelf cameras detected it.
        detected_width_m: Perceived width, metres (None when not detected or not measurable).
        detected_height_m: Perceived height above its shelf step, metres (None likewise).
        width_m: Catalogue grasp width, metres.
        height_m: Catalogue height, metres.
        mass_kg: Catalogue mass, kilograms.
        material: Catalogue material.
        probe_held … probe_in_place: What the heft test felt (the module docstring's columns; None: not felt,
            not measured, or, for probe_in_place, no miss).
    """

    index: int
    action: str
    object: str
    success: bool
    failure_stage: str | None
    seed: int
    detail: str = ""
    family: str = ""
    shelf_unit: str = ""
    shelf_tier: int | None = None
    slot: int | None = None
    clearance_m: float | None = None
    neighbours: int | None = None
    detected: bool = False
    detected_width_m: float | None = None
    detected_height_m: float | None = None
    width_m: float = float("nan")
    height_m: float = float("nan")
    mass_kg: float = float("nan")
    material: str = ""
    detected_depth_m: float | None = None
    detected_fill: float | None = None
    depth_m: float = float("nan")
    shape: str = ""
    probe_held: bool | None = None
    probe_load_n: float | None = None
    probe_load_first_n: float | None = None
    probe_grip_n: float | None = None
    probe_s: float | None = None
    probe_pressed: bool | None = None
    probe_drift_mm: float | None = None
    probe_drift_both_mm: float | None = None
    probe_wrist_load_n: float | None = None
    probe_wrist_load_first_n: float | None = None
    probe_in_place: bool | None = None

    def row(self) -> list[str]:
        """The CSV row, in COLUMNS order."""

        def num(v: float | None) -> str:
            return "" if v is None or v != v else repr(float(v))

        def count(v: int | None) -> str:
            return "" if v is None else str(v)

        def flag(v: bool | None) -> str:
            return "" if v is None else str(int(v))

        return [
            str(self.index),
            self.action,
            self.object,
            self.family,
            "success" if self.success else "failure",
            self.failure_stage or "",
            str(self.seed),
            self.detail,
            self.shelf_unit,
            count(self.shelf_tier),
            count(self.slot),
            num(self.clearance_m),
            count(self.neighbours),
            "1" if self.detected else "0",
            num(self.detected_width_m),
            num(self.detected_height_m),
            num(self.width_m),
            num(self.height_m),
            num(self.mass_kg),
            self.material,
            num(self.detected_depth_m),
            num(self.detected_fill),
            num(self.depth_m),
            self.shape,
            "" if self.probe_held is None else str(int(self.probe_held)),
            num(self.probe_load_n),
            num(self.probe_load_first_n),
            num(self.probe_grip_n),
            num(self.probe_s),
            flag(self.probe_pressed),
            num(self.probe_drift_mm),
            num(self.probe_drift_both_mm),
            num(self.probe_wrist_load_n),
            num(self.probe_wrist_load_first_n),
            flag(self.probe_in_place),
        ]


@dataclass(frozen=True, eq=False)
class Dataset:
    """One robot's outcomes in the order they were observed.

    Attributes:
        name: Dataset name (file stem, plus the robot/profile when one file held several).
        actions: Action texts, one per row.
        objects: Object names, one per row.
        success: (n,) bool outcomes.
        failure_stages: Failure stage per row ("" on success).
        families: Packaging family per row ("" when the file has no family column).
        context: CONTEXT_COLUMNS present in the file → (n,) float array (NaN where a row leaves it empty).
        materials: Material per row ("" when the file has none).
        shelf_units: Shelf unit per row ("" when the file has none).
        details: The motion system's first line of detail per row ("" when the file has none).
    """

    name: str
    actions: tuple[str, ...]
    objects: tuple[str, ...]
    success: np.ndarray
    failure_stages: tuple[str, ...]
    families: tuple[str, ...] = ()
    context: dict[str, np.ndarray] = field(default_factory=dict)
    materials: tuple[str, ...] = ()
    shelf_units: tuple[str, ...] = ()
    details: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.actions)

    @property
    def success_rate(self) -> float:
        return float(self.success.mean()) if len(self) else float("nan")


def write_records(path: Path | str, records: Iterable[ExecutionRecord]) -> Path:
    """Write records sorted by index to a CSV file atomically (a reader never sees a half-written file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(COLUMNS)
        for rec in sorted(records, key=lambda r: r.index):
            writer.writerow(rec.row())
    os.chmod(tmp, 0o644)  # mkstemp makes it private; a dataset is for everyone to read
    os.replace(tmp, path)
    return path


def _float(text: str, path: Path, row: int, column: str) -> float:
    """A measured quantity (metres, kilograms, newtons, seconds, counts): a finite number ≥ 0, or NaN for an
    empty cell; else ConfigError naming the file, row and column (an inf or a negative size made κ̂'s confidence
    NaN, and the replay stopped on it without saying where it came from)."""
    if text == "":
        return float("nan")
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(f"{path} row {row + 2}: {column} {text!r} is not a number") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise ConfigError(f"{path} row {row + 2}: {column} {value:g} must be a finite number ≥ 0 (or empty)")
    return value


_FLAGS = ("probe_held", "probe_pressed", "probe_in_place")
"""Probe columns that are 0 or 1."""


def _check_probe(context: dict[str, np.ndarray], rows: Sequence[int], path: Path) -> None:
    """ConfigError (one line: file, row, column, valid values) for a malformed probe reading: the flags 0 or 1,
    every PROBE_COLUMNS column given or none (the arm never held it up), what the hand sensed only where something
    was felt, and ``probe_in_place`` only where nothing was; that each is finite and ≥ 0 (newtons, seconds,
    millimetres) `_float` checked as it read the cell. What the replay makes the felt context of (experience.felt) is
    checked here, where the file is known."""
    if not any(c in context for c in PROBE_READING_COLUMNS):
        return
    nan = np.full(len(rows), np.nan)
    held, *rest = (context.get(c, nan) for c in PROBE_COLUMNS)
    for j, row in enumerate(rows):
        where = f"{path} row {row + 2}"
        for column in _FLAGS:
            v = context.get(column, nan)[j]
            if not (np.isnan(v) or v in (0.0, 1.0)):
                empty = "empty: never held up" if column == "probe_held" else "or empty"
                raise ConfigError(f"{where}: {column} {v:g} must be 0 or 1 ({empty})")
        for column, values in zip(PROBE_COLUMNS[1:], rest, strict=True):
            v = values[j]
            if np.isnan(v) != np.isnan(held[j]):
                raise ConfigError(
                    f"{where}: {column} must be given exactly where probe_held is (every probe column, or none)"
                )
        for column in PROBE_SENSED_COLUMNS:
            if np.isnan(held[j]) and not np.isnan(context.get(column, nan)[j]):
                raise ConfigError(f"{where}: {column} must be empty where probe_held is (nothing was felt)")
        if not np.isnan(held[j]) and not np.isnan(context.get("probe_in_place", nan)[j]):
            raise ConfigError(
                f"{where}: probe_in_place must be empty where probe_held is given (it held something)"
            )


def _int(text: str, path: Path, row: int, column: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ConfigError(f"{path} row {row + 2}: {column} {text!r} is not an integer") from None


def read_records(path: Path | str) -> list[ExecutionRecord]:
    """Records of a generator CSV (used to resume a half-finished profile); a missing file gives none.

    Raises:
        ConfigError: The file lacks a generator column (an older schema: delete it to regenerate) or holds a
            malformed value.
    """
    from scone_bt.config.schema import MAX_DATA_FILE_BYTES, read_text

    path = Path(path)
    if not path.exists():
        return []
    try:  # bounded, regular files only (read_text), and csv's own complaints as one line
        reader = csv.DictReader(io.StringIO(read_text(path, limit=MAX_DATA_FILE_BYTES), newline=""))
        rows = list(reader)
    except csv.Error as exc:
        raise ConfigError(f"{path}: not a readable CSV file ({exc})") from None
    # The header is checked even without rows: a file of one line (someone's notes, another CSV's header) is not
    # a generator file whose run was cut short, and would otherwise be written over.
    header = reader.fieldnames or []
    missing = [c for c in COLUMNS if header and c not in header and c not in _LATER]
    if missing:
        raise ConfigError(
            f"{path}: not a generator file of this version (missing column {missing[0]!r}); delete it to regenerate"
        )
    out = []
    for i, r in enumerate(rows):

        def opt(column: str, r: dict[str, str] = r, i: int = i) -> float | None:
            v = _float(r.get(column) or "", path, i, column)
            return None if v != v else v

        def opt_int(column: str, r: dict[str, str] = r, i: int = i) -> int | None:
            return None if r[column] == "" else _int(r[column], path, i, column)

        out.append(
            ExecutionRecord(
                index=_int(r["index"], path, i, "index"),
                action=r["action"],
                object=r["object"],
                success=_outcome(r["outcome"], path, i),
                failure_stage=r["failure_stage"] or None,
                seed=_int(r["seed"], path, i, "seed"),
                detail=r["detail"],
                family=r["family"],
                shelf_unit=r["shelf_unit"],
                shelf_tier=opt_int("shelf_tier"),
                slot=opt_int("slot"),
                clearance_m=opt("clearance_m"),
                neighbours=opt_int("neighbours"),
                detected=r["detected"].strip() == "1",
                detected_width_m=opt("detected_width_m"),
                detected_height_m=opt("detected_height_m"),
                width_m=_float(r["width_m"], path, i, "width_m"),
                height_m=_float(r["height_m"], path, i, "height_m"),
                mass_kg=_float(r["mass_kg"], path, i, "mass_kg"),
                material=r["material"],
                detected_depth_m=opt("detected_depth_m"),
                detected_fill=opt("detected_fill"),
                depth_m=opt("depth_m") or float("nan"),
                shape=r.get("shape") or "",
                probe_held=None if not r.get("probe_held") else r["probe_held"].strip() == "1",
                probe_load_n=opt("probe_load_n"),
                probe_load_first_n=opt("probe_load_first_n"),
                probe_grip_n=opt("probe_grip_n"),
                probe_s=opt("probe_s"),
                probe_pressed=None if not r.get("probe_pressed") else r["probe_pressed"].strip() == "1",
                probe_drift_mm=opt("probe_drift_mm"),
                probe_drift_both_mm=opt("probe_drift_both_mm"),
                probe_wrist_load_n=opt("probe_wrist_load_n"),
                probe_wrist_load_first_n=opt("probe_wrist_load_first_n"),
                probe_in_place=None if not r.get("probe_in_place") else r["probe_in_place"].strip() == "1",
            )
        )
    return out


def _outcome(value: object, path: Path, row: int) -> bool:
    text = str(value).strip().lower()
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    raise ConfigError(
        f"{path} row {row + 2}: outcome {value!r} is not one of success, failure, 1, 0, true, false"
    )


def _table(path: Path) -> list[dict[str, object]]:
    from scone_bt.config.schema import MAX_DATA_FILE_BYTES, check_input_file, read_text

    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        return pq.read_table(
            check_input_file(path)
        ).to_pylist()  # pyarrow reads it: checked (size, kind) first
    try:  # strict UTF-8, and csv's own complaints (NUL bytes, a field too large) as one line
        return list(csv.DictReader(io.StringIO(read_text(path, limit=MAX_DATA_FILE_BYTES), newline="")))
    except csv.Error as exc:
        raise ConfigError(f"{path}: not a readable CSV file ({exc})") from None


def read_dataset(path: Path | str) -> list[Dataset]:
    """Read one CSV/Parquet file; usually one dataset, several if an experience export mixes robots."""
    path = Path(path)
    rows = _table(path)
    if not rows:
        raise ConfigError(f"{path}: no rows")
    cols = set(rows[0])
    obj_col = "object" if "object" in cols else "object_name" if "object_name" in cols else None
    out_col = "outcome" if "outcome" in cols else "success" if "success" in cols else None
    needed = [
        ("action", "action" in cols),
        ("object (or object_name)", obj_col),
        ("outcome (or success)", out_col),
    ]
    missing = [name for name, ok in needed if not ok]
    if missing:
        raise ConfigError(
            f"{path}: missing column {missing[0]}; a dataset needs action, object, outcome, failure_stage, seed"
        )
    assert obj_col is not None and out_col is not None  # none missing: both were found above
    groups: dict[str, list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault(_group(r, path, i), []).append(i)
    datasets = []
    for key, idx in groups.items():
        name = path.stem if len(groups) == 1 else f"{path.stem}:{key}"
        context = {
            c: np.array([_float(str(rows[i].get(c) or ""), path, i, c) for i in idx], dtype=float)
            for c in CONTEXT_COLUMNS
            if c in cols
        }
        _check_probe(context, idx, path)
        datasets.append(
            Dataset(
                name=name,
                actions=tuple(str(rows[i]["action"]) for i in idx),
                objects=tuple(str(rows[i][obj_col]) for i in idx),
                success=np.array([_outcome(rows[i][out_col], path, i) for i in idx], dtype=bool),
                failure_stages=tuple(str(rows[i].get("failure_stage") or "") for i in idx),
                families=tuple(str(rows[i].get("family") or "") for i in idx),
                context=context,
                materials=tuple(str(rows[i].get("material") or "") for i in idx),
                shelf_units=tuple(str(rows[i].get("shelf_unit") or "") for i in idx),
                details=tuple(str(rows[i].get("detail") or "") for i in idx),
            )
        )
    return datasets


def _group(row: dict[str, object], path: Path, index: int) -> str:
    raw = row.get("context")
    if not raw:
        return ""
    try:
        ctx = json.loads(str(raw))
    except json.JSONDecodeError:
        raise ConfigError(f"{path} row {index + 2}: context is not valid JSON") from None
    if not isinstance(ctx, dict):
        return ""
    return "/".join(str(ctx[k]) for k in _SPLIT_KEYS if k in ctx)


def load_datasets(
    directory: Path | str, min_rows: int = 0, names: Sequence[str] | None = None
) -> list[Dataset]:
    """Every *.csv / *.parquet dataset in `directory`, sorted by name.

    Args:
        directory: Folder of dataset files.
        min_rows: Datasets with fewer rows are an error (the evaluation needs them).
        names: Only these dataset names (file stems).
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise ConfigError(f"dataset directory {directory} does not exist")
    files = sorted(
        p for p in directory.iterdir() if p.suffix in (".csv", ".parquet") and not p.name.startswith(".")
    )
    if names:
        stems = {p.stem for p in files}
        missing = [n for n in names if n not in stems]
        if missing:
            raise ConfigError(
                f"unknown dataset {missing[0]!r} in {directory}; valid: {', '.join(sorted(stems))}"
            )
        files = [p for p in files if p.stem in names]
    if not files:
        raise ConfigError(f"{directory}: no dataset files (*.csv or *.parquet)")
    datasets = [d for p in files for d in read_dataset(p)]
    short = [d for d in datasets if len(d) < min_rows]
    if short:
        raise ConfigError(
            f"dataset {short[0].name} has {len(short[0])} rows; the evaluation needs at least {min_rows}"
        )
    return datasets
