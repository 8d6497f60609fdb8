"""The robot's own step: what it placed itself counts as on the table even when the table camera misses it."""

from __future__ import annotations

from scone_bt.relevance.recipe_aware import SelectionOptions
from scone_bt.relevance.tracker import track_recipe

STEPS = ("Fry the bacon.", "Add macaroni and the milk.", "Serve with applesauce.")
ITEMS = ("bacon", "macaroni", "milk", "applesauce")


def _similarity(step: str) -> dict[str, float]:
    return {}


def _track(shelf, on_table=frozenset(), placed=frozenset(), start=1):
    return track_recipe(
        STEPS, start, shelf, ITEMS, {}, frozenset(on_table), _similarity, SelectionOptions(), placed=placed
    )


def test_items_the_robot_placed_complete_the_step_though_the_camera_misses_them() -> None:
    # milk and macaroni are off the shelf and the table camera sees neither (hidden behind others)
    view = _track(("applesauce",), placed=frozenset({"milk", "macaroni"}))
    assert view.index == 2 and (1, "completed") in view.skipped
    assert view.placed_by_robot == {"milk", "macaroni"}
    assert view.placed_unseen == {"milk", "macaroni"}
    assert view.selection.now == ("applesauce",)


def test_placed_items_are_not_missing_and_unseen_unplaced_ones_are() -> None:
    # the robot placed the milk; the macaroni it never saw anywhere
    view = _track(("applesauce",), placed=frozenset({"milk"}))
    assert view.index == 1 and not view.selection.done
    assert view.missing == ("macaroni",)
    assert "milk" not in view.missing


def test_a_placed_item_seen_on_the_shelf_again_is_not_on_the_table() -> None:
    view = _track(("milk", "applesauce"), on_table={"macaroni"}, placed=frozenset({"milk"}))
    assert view.index == 1 and view.selection.now == ("milk",)
    assert view.placed_by_robot == frozenset()


def test_the_camera_alone_still_completes_a_step() -> None:
    view = _track(("applesauce",), on_table={"milk", "macaroni"})
    assert view.index == 2 and view.placed_by_robot == frozenset() and view.missing == ()


def test_items_meant_by_a_shared_head_noun_are_not_gathered_at_the_first_step() -> None:
    steps = ("Toast the ciabatta.", "Top the toast with the cheese.")
    items = ("ciabatta", "cheddar cheese", "swiss cheese")

    def track(on_table: frozenset[str]):
        shelf = tuple(i for i in items if i not in on_table)
        return track_recipe(steps, 0, shelf, items, {}, on_table, _similarity, SelectionOptions())

    first = track(frozenset())
    assert first.index == 0 and first.selection.now == ("ciabatta",)
    second = track(frozenset({"ciabatta"}))
    assert second.index == 1 and set(second.selection.ambiguous) == {"cheddar cheese", "swiss cheese"}
