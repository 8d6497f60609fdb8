"""The trust questionnaires, with items, scales and scoring as published.

- MDMT, performance dimension (Ullman & Malle, Multi-Dimensional Measure of Trust v2): 8 items, subscales Reliable
  and Capable, each rated 0 ("not at all") to 7 ("very"), or "does not fit". Score: mean of the answered items.
- TPS-HRI, 14-item version (Schaefer, Trust Perception Scale-HRI): "What percentage of the time will this robot
  be/do ...", 0 % to 100 % in steps of 10 %. Items 9, 11 and 12 are reverse-scored. Score: mean of the 14 items
  after reversal, a percentage.

For the ordered-logit analysis each answer becomes a category 0..K-1 oriented so that higher always means more trust
(reverse-scored items are flipped).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from scone_bt.errors import SconeError, UnknownNameError

__all__ = [
    "Item",
    "Questionnaire",
    "MDMT_PERFORMANCE",
    "TPS_HRI_14",
    "QUESTIONNAIRES",
    "get_questionnaire",
    "QuestionnaireError",
    "validate_answers",
]


class QuestionnaireError(SconeError):
    """An answer outside an item's scale, or a missing item."""


@dataclass(frozen=True)
class Item:
    """One Likert item.

    Attributes:
        key: Stable identifier ("mdmt_reliable").
        text: What the participant reads.
        reverse: Reverse-scored (a high answer means low trust).
        subscale: Subscale name, or "".
    """

    key: str
    text: str
    reverse: bool = False
    subscale: str = ""


@dataclass(frozen=True)
class Questionnaire:
    """A questionnaire and its response scale.

    Attributes:
        name: Identifier ("mdmt", "tps_hri").
        title: Display title.
        prompt: Shown above the items.
        items: The items in published order.
        values: Allowed numeric answers, ascending (0..7 or 0, 10, ..., 100).
        labels: Label per allowed value (same length as values).
        allow_not_applicable: Offer "does not fit" (stored as a missing value).
        unit: Unit of the score ("" or "%").
    """

    name: str
    title: str
    prompt: str
    items: tuple[Item, ...]
    values: tuple[float, ...]
    labels: tuple[str, ...]
    allow_not_applicable: bool = False
    unit: str = ""

    @property
    def n_categories(self) -> int:
        return len(self.values)

    def item(self, key: str) -> Item:
        for it in self.items:
            if it.key == key:
                return it
        raise UnknownNameError(f"{self.name} item", key, [i.key for i in self.items])

    def validate(self, key: str, value: float | None) -> float | None:
        """Check one answer; None means "does not fit" where allowed."""
        self.item(key)
        if value is None:
            if not self.allow_not_applicable:
                raise QuestionnaireError(f"{self.name}: item {key!r} needs an answer; valid: {self._valid()}")
            return None
        v = float(value)
        if v not in self.values:
            raise QuestionnaireError(
                f"{self.name}: answer {value!r} to {key!r} is not on the scale; valid: {self._valid()}"
            )
        return v

    def _valid(self) -> str:
        vals = ", ".join(f"{v:g}" for v in self.values)
        return vals + (", or none (does not fit)" if self.allow_not_applicable else "")

    def category(self, key: str, value: float) -> int:
        """Ordinal category 0..K-1, flipped for reverse-scored items so that higher means more trust."""
        idx = self.values.index(float(value))
        return self.n_categories - 1 - idx if self.item(key).reverse else idx

    def score(self, answers: Mapping[str, float | None]) -> float | None:
        """The published score: mean of answered items after reversal (MDMT 0-7, TPS-HRI in %)."""
        lo, hi = self.values[0], self.values[-1]
        vals = []
        for it in self.items:
            v = answers.get(it.key)
            if v is None:
                continue
            vals.append(lo + hi - float(v) if it.reverse else float(v))
        return sum(vals) / len(vals) if vals else None

    def subscale_scores(self, answers: Mapping[str, float | None]) -> dict[str, float | None]:
        """Mean per subscale (MDMT: reliable, capable); empty when the questionnaire has none."""
        out: dict[str, float | None] = {}
        for sub in sorted({it.subscale for it in self.items if it.subscale}):
            vals = [answers.get(it.key) for it in self.items if it.subscale == sub]
            got = [float(v) for v in vals if v is not None]
            out[sub] = sum(got) / len(got) if got else None
        return out

    def as_json(self) -> dict:
        """What the tablet page needs to render the questionnaire."""
        return {
            "name": self.name,
            "title": self.title,
            "prompt": self.prompt,
            "items": [{"key": i.key, "text": i.text} for i in self.items],
            "values": list(self.values),
            "labels": list(self.labels),
            "allow_not_applicable": self.allow_not_applicable,
        }


def _mdmt_item(word: str, sub: str) -> Item:
    return Item("mdmt_" + word.lower().replace(" ", "_"), word, subscale=sub)


MDMT_PERFORMANCE = Questionnaire(
    name="mdmt",
    title="Multi-Dimensional Measure of Trust (performance)",
    prompt="How much does each word describe the robot you just cooked with? 0 = not at all, 7 = very.",
    items=(
        _mdmt_item("Reliable", "reliable"),
        _mdmt_item("Predictable", "reliable"),
        _mdmt_item("Someone you can count on", "reliable"),
        _mdmt_item("Consistent", "reliable"),
        _mdmt_item("Capable", "capable"),
        _mdmt_item("Skilled", "capable"),
        _mdmt_item("Competent", "capable"),
        _mdmt_item("Meticulous", "capable"),
    ),
    values=tuple(float(v) for v in range(8)),
    labels=("0 not at all", "1", "2", "3", "4", "5", "6", "7 very"),
    allow_not_applicable=True,
)

_TPS_TEXTS = (
    ("function_successfully", "Function successfully", False),
    ("act_consistently", "Act consistently", False),
    ("reliable", "Be reliable", False),
    ("predictable", "Be predictable", False),
    ("dependable", "Be dependable", False),
    ("follow_directions", "Follow directions", False),
    ("meet_needs", "Meet the needs of the task", False),
    ("perform_as_instructed", "Perform exactly as instructed", False),
    ("have_errors", "Have errors", True),
    ("provide_information", "Provide appropriate information", False),
    ("unresponsive", "Be unresponsive", True),
    ("malfunction", "Malfunction", True),
    ("communicate", "Communicate with people", False),
    ("provide_feedback", "Provide feedback", False),
)

TPS_HRI_14 = Questionnaire(
    name="tps_hri",
    title="Trust Perception Scale-HRI (14 items)",
    prompt="What percentage of the time will this robot ...",
    items=tuple(Item("tps_" + k, t, reverse=r) for k, t, r in _TPS_TEXTS),
    values=tuple(float(v) for v in range(0, 101, 10)),
    labels=tuple(f"{v}%" for v in range(0, 101, 10)),
    unit="%",
)

QUESTIONNAIRES: dict[str, Questionnaire] = {q.name: q for q in (MDMT_PERFORMANCE, TPS_HRI_14)}


def get_questionnaire(name: str) -> Questionnaire:
    try:
        return QUESTIONNAIRES[name]
    except KeyError:
        raise UnknownNameError("questionnaire", name, QUESTIONNAIRES) from None


def validate_answers(
    questionnaire: Questionnaire, answers: Mapping[str, float | None]
) -> dict[str, float | None]:
    """Every item answered (or "does not fit" where allowed) and on the scale; unknown keys rejected."""
    unknown: Sequence[str] = [k for k in answers if k not in {i.key for i in questionnaire.items}]
    if unknown:
        raise UnknownNameError(f"{questionnaire.name} item", unknown[0], [i.key for i in questionnaire.items])
    missing = [i.key for i in questionnaire.items if i.key not in answers]
    if missing:
        raise QuestionnaireError(
            f"{questionnaire.name}: {len(missing)} items unanswered, first {missing[0]!r}"
        )
    return {k: questionnaire.validate(k, v) for k, v in answers.items()}
