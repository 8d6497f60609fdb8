"""PDDL baseline: each instruction becomes a goal, and LAMA (Fast Downward) plans the fetches.

The translation is lexical: the goal puts on the table every kitchen item the instruction names (whole name, or
its head noun when no other item shares it). The domain has a one-handed robot that picks an item from its shelf
slot and places it on the table. The plan comes from Fast Downward's ``lama-first`` through unified-planning and
``up-fast-downward``; the policy's picks are the plan's placements in order. Like the paper's PDDL baseline it
cannot judge relevance beyond what the goal says, and it knows nothing about its own failures.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from scone_bt.instruction_following.states import IfState, item_of_action, mentioned_items

__all__ = ["PddlOptions", "PddlPlan", "PddlPolicy", "instruction_goal", "plan_fetches"]


@dataclass(frozen=True)
class PddlOptions:
    """Planner settings.

    Attributes:
        alias: Fast Downward alias ("lama-first" is LAMA's first, greedy iteration).
        head_nouns: Let "the sugar" name "brown sugar" when no other item ends in "sugar".
    """

    alias: str = "lama-first"
    head_nouns: bool = True


@dataclass(frozen=True)
class PddlPlan:
    """A solved fetch problem.

    Attributes:
        goal: Items the goal puts on the table.
        actions: The plan, one action per entry ("pick(salt, s_1_3)", "place(salt)").
        placed: Items in the order the plan places them.
        status: The planner's status name ("SOLVED_SATISFICING", ...; "EMPTY_GOAL" when nothing was asked).
    """

    goal: tuple[str, ...]
    actions: tuple[str, ...]
    placed: tuple[str, ...]
    status: str


def _symbol(text: str, used: set[str]) -> str:
    base = re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_") or "x"
    name = f"i_{base}"
    k = 1
    while name in used:
        k += 1
        name = f"i_{base}_{k}"
    used.add(name)
    return name


def instruction_goal(instruction: str, items: Sequence[str], head_nouns: bool = True) -> list[str]:
    """The items an instruction asks for (the lexical translation into a goal)."""
    return mentioned_items(instruction, items, head_nouns=head_nouns)


class _FetchDomain(NamedTuple):
    """The fetch domain's types, fluents and actions (unified_planning objects)."""

    item_t: Any
    place_t: Any
    at: Any
    holding: Any
    on_table: Any
    hand_empty: Any
    pick: Any
    place: Any


def _fetch_domain(ups: Any) -> _FetchDomain:
    """Items at slots, one hand: pick an item from its slot into the empty hand, place the held item on the table."""
    item_t, place_t = ups.UserType("Item"), ups.UserType("Slot")
    at = ups.Fluent("at", ups.BoolType(), i=item_t, s=place_t)
    holding = ups.Fluent("holding", ups.BoolType(), i=item_t)
    on_table = ups.Fluent("on_table", ups.BoolType(), i=item_t)
    hand_empty = ups.Fluent("hand_empty", ups.BoolType())

    pick = ups.InstantaneousAction("pick", i=item_t, s=place_t)
    i, s = pick.parameter("i"), pick.parameter("s")
    pick.add_precondition(at(i, s))
    pick.add_precondition(hand_empty())
    pick.add_effect(at(i, s), False)
    pick.add_effect(holding(i), True)
    pick.add_effect(hand_empty(), False)

    place = ups.InstantaneousAction("place", i=item_t)
    j = place.parameter("i")
    place.add_precondition(holding(j))
    place.add_effect(holding(j), False)
    place.add_effect(on_table(j), True)
    place.add_effect(hand_empty(), True)
    return _FetchDomain(item_t, place_t, at, holding, on_table, hand_empty, pick, place)


def plan_fetches(
    items: Sequence[str],
    locations: dict[str, tuple[int, int]],
    goal: Sequence[str],
    options: PddlOptions | None = None,
) -> PddlPlan:
    """Plan with LAMA to put every ``goal`` item on the table.

    Args:
        items: Every item in the kitchen.
        locations: Item → (shelf tier, slot); items without one get a slot of their own.
        goal: Items to put on the table (a subset of ``items``).
        options: Planner settings.

    Returns:
        The plan; an empty goal gives an empty plan without calling the planner.
    """
    opts = options or PddlOptions()
    if not goal:
        return PddlPlan(goal=(), actions=(), placed=(), status="EMPTY_GOAL")
    missing = [g for g in goal if g not in items]
    if missing:
        raise ValueError(f"goal items not in the kitchen: {', '.join(missing)}")
    import unified_planning.shortcuts as ups
    from unified_planning.engines import PlanGenerationResultStatus

    env = ups.get_environment()
    env.credits_stream = None  # the engines' credits banner would go to stdout
    item_t, place_t, at, holding, on_table, hand_empty, pick, place = _fetch_domain(ups)

    problem = ups.Problem("fetch")
    for f in (at, holding, on_table, hand_empty):
        problem.add_fluent(f, default_initial_value=False)
    problem.add_action(pick)
    problem.add_action(place)
    used: set[str] = set()
    item_obj = {it: ups.Object(_symbol(it, used), item_t) for it in items}
    slot_names: dict[tuple[int, int], object] = {}
    spare = 1000
    for it in items:
        loc = locations.get(it)
        if loc is None:
            loc, spare = (spare, 0), spare + 1
        if loc not in slot_names:
            slot_names[loc] = ups.Object(f"s_{loc[0]}_{loc[1]}", place_t)
        problem.set_initial_value(at(item_obj[it], slot_names[loc]), True)
    problem.add_objects(list(item_obj.values()))
    problem.add_objects(list(slot_names.values()))
    problem.set_initial_value(hand_empty(), True)
    for g in goal:
        problem.add_goal(on_table(item_obj[g]))

    by_symbol = {o.name: it for it, o in item_obj.items()}
    with ups.OneshotPlanner(name="fast-downward", params={"fast_downward_alias": opts.alias}) as planner:
        result = planner.solve(problem)
    if result.status not in (
        PlanGenerationResultStatus.SOLVED_SATISFICING,
        PlanGenerationResultStatus.SOLVED_OPTIMALLY,
    ):
        return PddlPlan(goal=tuple(goal), actions=(), placed=(), status=result.status.name)
    actions, placed = [], []
    for a in result.plan.actions:
        args = [str(p) for p in a.actual_parameters]
        actions.append(f"{a.action.name}({', '.join(args)})")
        if a.action.name == "place":
            placed.append(by_symbol[args[0]])
    return PddlPlan(goal=tuple(goal), actions=tuple(actions), placed=tuple(placed), status=result.status.name)


@dataclass
class PddlPolicy:
    """Picks what the LAMA plan for the instruction's goal places, in plan order, then stops."""

    options: PddlOptions = field(default_factory=PddlOptions)
    name: str = "PDDL (LAMA)"
    _plans: dict[tuple[str, tuple[str, ...]], tuple[str, ...]] = field(default_factory=dict, repr=False)

    def plan(self, state: IfState) -> tuple[str, ...]:
        """Action texts the plan places, in order (cached per state)."""
        key = (state.instruction, state.available)
        if key not in self._plans:
            items = [item_of_action(a) for a in state.available]
            locations = {item_of_action(a): loc for a, loc in state.locations.items()}
            goal = instruction_goal(state.instruction, items, self.options.head_nouns)
            result = plan_fetches(items, locations, goal, self.options)
            by_item = dict(zip(items, state.available, strict=True))
            self._plans[key] = tuple(by_item[i] for i in result.placed)
        return self._plans[key]

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        """The plan's next placement, or None when the plan is done."""
        plan = self.plan(state)
        return plan[len(picked)] if len(picked) < len(plan) else None
