"""Anyone's study data as CSV: the ratings (one row per answer) and, optionally, the sessions (interventions).

Ratings CSV, one row per answered item::

    participant,condition,session,group,question,rating,categories[,questionnaire]
    P01,on,1,A,reliable,6,8,mdmt

- ``condition`` is ``on`` or ``off`` (self-confidence), ``session`` 1 or 2 (the order), ``group`` A or B (the
  counterbalancing order; all participants of a group must share it);
- ``rating`` is the answer's category, an integer from 0 to ``categories - 1`` with higher meaning more trust
  (flip reverse-scored items first); an empty rating is a skipped item ("does not fit") and is left out;
- ``categories`` is the size of the item's scale and must be the same for all items of a questionnaire;
- ``questionnaire`` is optional (default ``ratings``): each questionnaire is fitted on its own, with its own
  cut-points.

Sessions CSV, one row per session: ``participant,condition,session,group,interventions`` (a count >= 0).

Every participant needs both conditions, and the study needs both groups (both condition orders): with one group
only, condition and session order are confounded. Other column names are mapped with ``columns`` (e.g.
``{"participant": "subject"}``). Files are read as UTF-8 (a byte-order mark is fine) and never modified. Anything
wrong is a one-line RatingsFileError naming the file, the row (as a spreadsheet numbers it, header = row 1), the
column and what is allowed.
"""

from __future__ import annotations

import csv
import functools
import io
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError, model_validator
from pydantic_core import PydanticCustomError

from scone_bt.config.schema import format_validation_error
from scone_bt.errors import SconeError

__all__ = [
    "RatingsFileError",
    "RATINGS_COLUMNS",
    "SESSIONS_COLUMNS",
    "parse_column_map",
    "load_ratings_csv",
]

RATINGS_COLUMNS = ("participant", "condition", "session", "group", "question", "rating", "categories")
OPTIONAL_RATINGS_COLUMNS = ("questionnaire",)
SESSIONS_COLUMNS = ("participant", "condition", "session", "group", "interventions")
DEFAULT_QUESTIONNAIRE = "ratings"
_ALLOWED = {"condition": ("off", "on"), "session": ("1", "2"), "group": ("A", "B")}


class RatingsFileError(SconeError):
    """A ratings or sessions CSV that cannot be analysed as it is."""


@dataclass(frozen=True)
class _Row:
    line: int
    values: dict[str, str]


def parse_column_map(text: str | None) -> dict[str, str]:
    """``"participant=subject,rating=answer"`` → {"participant": "subject", "rating": "answer"}."""
    if not text:
        return {}
    known = (*RATINGS_COLUMNS, *OPTIONAL_RATINGS_COLUMNS, "interventions")
    out: dict[str, str] = {}
    for part in text.split(","):
        key, sep, name = (s.strip() for s in part.partition("="))
        if not sep or not name:
            raise RatingsFileError(f"--columns: {part!r} is not COLUMN=NAME (e.g. participant=subject)")
        if key not in known:
            raise RatingsFileError(f"--columns: unknown column {key!r}; valid: {', '.join(known)}")
        out[key] = name
    return out


def _read(
    path: Path, required: tuple[str, ...], optional: tuple[str, ...], columns: Mapping[str, str]
) -> list[_Row]:
    from scone_bt.config.schema import MAX_DATA_FILE_BYTES, read_bytes

    if not path.exists():
        raise RatingsFileError(f"{path}: file not found")
    raw = read_bytes(path, RatingsFileError, MAX_DATA_FILE_BYTES)  # no device, FIFO or oversized file
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise RatingsFileError(
            f"{path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} on row {line}); save the file as UTF-8 CSV"
        ) from None
    if "\x00" in text:  # as every other loader says it (the header line printed the NULs invisibly)
        raise RatingsFileError(f"{path}: contains NUL characters; it is not a text file")
    reader = csv.reader(io.StringIO(text, newline=""))
    header = next(reader, None)
    if not header:
        raise RatingsFileError(f"{path}: empty file; expected a header row with {', '.join(required)}")
    header = [h.strip() for h in header]
    position = {}
    for col in (*required, *optional):
        name = columns.get(col, col)
        if name in header:
            position[col] = header.index(name)
        elif col in required:
            mapped = f" (mapped to {name!r})" if name != col else ""
            raise RatingsFileError(
                f"{path}: missing column {col!r}{mapped}; the header has {', '.join(header)}; "
                f"needed: {', '.join(required)} (rename with --columns {col}=NAME)"
            )
    rows = []
    for values in reader:
        line = reader.line_num
        if not any(v.strip() for v in values):
            continue
        if len(values) != len(header):
            raise RatingsFileError(f"{path}: row {line} has {len(values)} fields, the header {len(header)}")
        rows.append(_Row(line, {col: values[i].strip() for col, i in position.items()}))
    if not rows:
        raise RatingsFileError(f"{path}: no data rows under the header")
    return rows


def _strip_case(upper: bool) -> BeforeValidator:
    """Spreadsheet spelling tolerated: ON, On and on are one condition; a and A one group."""
    return BeforeValidator(lambda v: (v.upper() if upper else v.lower()) if isinstance(v, str) else v)


def _empty_is_none(value: object) -> object:
    return None if value == "" else value


class _DesignRow(BaseModel):
    """The design columns every row of both files has (as text; whole numbers like "3.0" are numbers)."""

    model_config = ConfigDict(frozen=True)

    participant: Annotated[str, Field(min_length=1)]
    condition: Annotated[Literal["off", "on"], _strip_case(upper=False)]
    session: Literal["1", "2"]
    group: Annotated[Literal["A", "B"], _strip_case(upper=True)]


class _RatingRow(_DesignRow):
    """One answered (or skipped: no rating) item of the ratings CSV."""

    question: Annotated[str, Field(min_length=1)]
    categories: Annotated[int, Field(ge=2)]
    rating: Annotated[int | None, BeforeValidator(_empty_is_none)] = None

    @model_validator(mode="after")
    def _on_the_scale(self) -> _RatingRow:
        if self.rating is not None and not 0 <= self.rating < self.categories:
            k = self.categories
            raise PydanticCustomError(
                "off_scale",
                "{rating} is outside the scale 0..{top} ({k} categories); ratings are category numbers from 0",
                {"rating": self.rating, "top": k - 1, "k": k},
            )
        return self


class _SessionRow(_DesignRow):
    """One session of the sessions CSV."""

    interventions: Annotated[int, Field(ge=0)]


_WHAT = {
    "categories": "a whole number of categories (2 or more)",
    "interventions": "a whole number of interventions (0 or more)",
}
"""What a numeric column takes, for 'is not ...' (the rating's range is the row's own scale)."""
_BELOW = {
    "categories": "{value} categories; an ordinal scale has 2 or more",
    "interventions": "{value} < 0; interventions are counts (0 or more)",
}


def _row_words(error: Mapping[str, Any], row: _Row, columns: Mapping[str, str]) -> str:
    """A row's problem in the words a spreadsheet user reads: row, column, what it takes (`format_validation_error`
    puts the file before it)."""
    col = str(error["loc"][0]) if error["loc"] else "rating"  # a model-level check is the rating's scale
    value = row.values.get(col, "")
    head = f"row {row.line}, column {columns.get(col, col)!r}"
    if error["type"] == "string_too_short":
        return f"{head} is empty"
    if error["type"] == "literal_error":
        return f"{head}: {value!r} is not one of {', '.join(_ALLOWED[col])}"
    if error["type"] == "off_scale":
        return f"{head}: {error['msg']}"
    if error["type"] == "greater_than_equal":
        return f"{head}: {_BELOW[col].format(value=int(float(error['input'])))}"
    # the rating is checked after `categories`, so a problem with it means the row's scale is a whole number
    what = _WHAT.get(col) or f"a whole number from 0 to {int(float(row.values['categories'])) - 1}"
    return f"{head}: {value!r} is not {what}"


def _row_error(path: Path, row: _Row, columns: Mapping[str, str], exc: ValidationError) -> RatingsFileError:
    """pydantic's first problem with a row as the project's one line (naming the file, row and column)."""
    words = functools.partial(_row_words, row=row, columns=columns)
    return RatingsFileError(format_validation_error(exc, str(path), words=words))


R = TypeVar("R", bound=_DesignRow)


def _parse_row(model: type[R], path: Path, row: _Row, columns: Mapping[str, str]) -> R:
    """A row checked by `model`, or the one-line RatingsFileError naming its row and column."""
    try:
        return model.model_validate(row.values)
    except ValidationError as exc:
        raise _row_error(path, row, columns, exc) from None


def _check_design(
    path: Path, plan: dict[str, dict[int, tuple[str, str, int]]], columns: Mapping[str, str]
) -> None:
    """Each participant: one group, one condition per session, both conditions; each group: one order; both groups.

    The paper's design is a crossover: group A has self-confidence on in session 1, group B off. With one group
    only, every "on" answer is also a session-1 (or every one a session-2) answer, so the condition and session
    effects are aliased and the analysis could only return undecided contrasts.
    """
    orders: dict[str, tuple[str, tuple[str, ...]]] = {}
    for participant, sessions in sorted(plan.items()):
        groups = {g for _c, g, _line in sessions.values()}
        if len(groups) > 1:
            line = max(line for *_x, line in sessions.values())
            raise RatingsFileError(
                f"{path}: participant {participant!r} is in groups {', '.join(sorted(groups))} (row {line}); "
                "a participant belongs to one group"
            )
        conditions = {c for c, _g, _line in sessions.values()}
        if conditions != {"on", "off"}:
            only = ", ".join(sorted(conditions))
            raise RatingsFileError(
                f"{path}: participant {participant!r} has condition {only} only; "
                "every participant needs both conditions (on and off)"
            )
        group = groups.pop()
        order = tuple(sessions[s][0] for s in sorted(sessions))
        first = orders.setdefault(group, (participant, order))
        if first[1] != order:
            raise RatingsFileError(
                f"{path}: participant {participant!r} (group {group}) has the order {'/'.join(order)} but "
                f"{first[0]!r} in the same group has {'/'.join(first[1])}; a group is one condition order"
            )
    if len(orders) == 1:
        ((group, (participant, order)),) = orders.items()
        raise RatingsFileError(
            f"{path}: column {columns.get('group', 'group')!r}: every participant is in group {group} (order "
            f"{'/'.join(order)}, e.g. {participant!r}); the design needs both groups A and B, so that each "
            "condition is seen in session 1 and in session 2, else condition and session order are confounded"
        )
    if len(orders) == 2 and orders["A"][1] == orders["B"][1]:
        raise RatingsFileError(
            f"{path}: groups A and B both have the order {'/'.join(orders['A'][1])} (participants "
            f"{orders['A'][0]!r}, {orders['B'][0]!r}); the groups are the two condition orders"
        )


_Plan = dict[str, dict[int, tuple[str, str, int]]]
"""Participant → session → (condition, group, the row that first gave them)."""


@dataclass(frozen=True)
class _Ratings:
    """The checked ratings file.

    Attributes:
        records: One dict per non-empty rating (the analysis frame's rows).
        plan: Each participant's sessions (`_Plan`).
        categories: Questionnaire → (its scale's categories, the row and the question that set it).
    """

    records: list[dict[str, Any]]
    plan: _Plan
    categories: dict[str, tuple[int, int, str]]


def _check_session(plan: _Plan, rpath: Path, row: _Row, checked: _RatingRow) -> None:
    """Record the row's session, refusing one whose condition or group another row contradicts."""
    participant, condition, group = checked.participant, checked.condition, checked.group
    session = int(checked.session)
    known = plan.setdefault(participant, {}).setdefault(session, (condition, group, row.line))
    if known[:2] != (condition, group):
        raise RatingsFileError(
            f"{rpath}: row {row.line}: participant {participant!r} session {session} is condition {condition} "
            f"group {group}, but row {known[2]} says condition {known[0]} group {known[1]}"
        )


def _check_scale(
    categories: dict[str, tuple[int, int, str]], rpath: Path, row: _Row, checked: _RatingRow
) -> str:
    """The row's questionnaire, refusing a scale size other than its questionnaire's first."""
    question, k = checked.question, checked.categories
    questionnaire = row.values.get("questionnaire") or DEFAULT_QUESTIONNAIRE
    first = categories.setdefault(questionnaire, (k, row.line, question))
    if first[0] != k:
        hint = "" if "questionnaire" in row.values else "; add a questionnaire column to fit them separately"
        raise RatingsFileError(
            f"{rpath}: row {row.line}: question {question!r} has {k} categories but {first[2]!r} "
            f"(row {first[1]}) of questionnaire {questionnaire!r} has {first[0]}{hint}"
        )
    return questionnaire


def _read_ratings(rpath: Path, columns: Mapping[str, str]) -> _Ratings:
    """Read and check every row of the ratings file, row by row, then the study's design."""
    plan: _Plan = {}
    categories: dict[str, tuple[int, int, str]] = {}
    seen: dict[tuple[str, int, str, str], int] = {}
    records = []
    for row in _read(rpath, RATINGS_COLUMNS, OPTIONAL_RATINGS_COLUMNS, columns):
        checked = _parse_row(_RatingRow, rpath, row, columns)
        _check_session(plan, rpath, row, checked)
        questionnaire = _check_scale(categories, rpath, row, checked)
        participant, session, question = checked.participant, int(checked.session), checked.question
        key = (participant, session, questionnaire, question)
        if key in seen:
            raise RatingsFileError(
                f"{rpath}: row {row.line} repeats participant {participant!r} session {session} question "
                f"{question!r} (first on row {seen[key]})"
            )
        seen[key] = row.line
        if checked.rating is None:
            continue  # a skipped item ("does not fit")
        records.append(
            {
                "session_id": f"{participant}/{session}",
                "participant": participant,
                "group": checked.group,
                "condition": checked.condition,
                "session_index": session,
                "questionnaire": questionnaire,
                "item": question,
                "category": checked.rating,
                "n_categories": checked.categories,
            }
        )
    _check_design(rpath, plan, columns)
    if not records:
        raise RatingsFileError(f"{rpath}: every rating is empty; nothing to analyse")
    return _Ratings(records, plan, categories)


def _session_table(plan: _Plan) -> list[dict[str, Any]]:
    """One row per session, in participant and session order (interventions unknown: NaN)."""
    return [
        {
            "session_id": f"{participant}/{session}",
            "participant": participant,
            "group": group,
            "condition": condition,
            "session_index": session,
            "interventions": float("nan"),
        }
        for participant, sessions_of in sorted(plan.items())
        for session, (condition, group, _line) in sorted(sessions_of.items())
    ]


def load_ratings_csv(
    ratings: str | Path,
    sessions: str | Path | None = None,
    columns: Mapping[str, str] | None = None,
    simulated: bool = False,
):  # -> StudyData
    """Read and check the CSV files into the StudyData the analysis fits.

    Args:
        ratings: The ratings CSV.
        sessions: The sessions CSV with interventions (None: no Poisson model).
        columns: Our column name → the file's, for files that name them differently.
        simulated: Label the data SIMULATED.

    Raises:
        RatingsFileError: A missing column, a value off its scale, a broken design; the message names the file,
            the row and column, and what is allowed.
    """
    import pandas as pd

    from scone_bt.study.analysis import StudyData

    columns = dict(columns or {})
    rpath = Path(ratings)
    checked = _read_ratings(rpath, columns)
    frame = pd.DataFrame(checked.records)
    table = _session_table(checked.plan)
    table_frame = pd.DataFrame(table)
    if sessions is not None:
        counts = _load_sessions(Path(sessions), checked.plan, columns)
        table_frame["interventions"] = [counts[(r["participant"], r["session_index"])] for r in table]
    names = tuple(sorted(checked.categories))
    for name in names:
        means = frame[frame["questionnaire"] == name].groupby("session_id")["category"].mean()
        table_frame[name] = table_frame["session_id"].map(means)
    units = {name: f"mean rating (0-{checked.categories[name][0] - 1})" for name in names}
    label = str(rpath) + (f" + {sessions}" if sessions is not None else "")
    return StudyData(frame, table_frame, simulated, label, names, units)


def _load_sessions(
    path: Path, plan: Mapping[str, Mapping[int, tuple[str, str, int]]], columns: Mapping[str, str]
) -> dict[tuple[str, int], int]:
    rows = _read(path, SESSIONS_COLUMNS, (), columns)
    counts: dict[tuple[str, int], int] = {}
    for row in rows:
        checked = _parse_row(_SessionRow, path, row, columns)
        participant, condition, group, n = (
            checked.participant,
            checked.condition,
            checked.group,
            checked.interventions,
        )
        session = int(checked.session)
        expected = plan.get(participant, {}).get(session)
        if expected is None:
            raise RatingsFileError(
                f"{path}: row {row.line}: participant {participant!r} session {session} has no ratings"
            )
        if expected[:2] != (condition, group):
            raise RatingsFileError(
                f"{path}: row {row.line}: participant {participant!r} session {session} is condition {condition} "
                f"group {group}, but the ratings say condition {expected[0]} group {expected[1]}"
            )
        if (participant, session) in counts:
            raise RatingsFileError(
                f"{path}: row {row.line} repeats participant {participant!r} session {session}"
            )
        counts[(participant, session)] = n
    missing = [
        f"{p} session {s}" for p, ss in sorted(plan.items()) for s in sorted(ss) if (p, s) not in counts
    ]
    if missing:
        raise RatingsFileError(
            f"{path}: no interventions for {missing[0]}"
            + (f" and {len(missing) - 1} more" if len(missing) > 1 else "")
        )
    return counts
