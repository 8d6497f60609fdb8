"""The robot's own IF policy: recipe-aware picks with its own stop rule, scored by the paper's metric."""

from __future__ import annotations

from scone_bt.embedding import load_embedder
from scone_bt.instruction_following.metric import evaluate
from scone_bt.instruction_following.product_policy import RecipeAwarePolicy, fit_selection_options
from scone_bt.instruction_following.states import IfState


def _state(instruction: str, relevant: set[str], recipe: tuple[str, ...]) -> IfState:
    items = ("chickpeas", "tahini", "lemon", "garlic", "salt", "honey", "coffee")
    available = tuple(f"Put {i} on table" for i in items)
    return IfState(
        instruction=instruction,
        available=available,
        relevant=frozenset(f"Put {i} on table" for i in relevant),
        recipe_items=recipe,
    )


RECIPE = ("chickpeas", "tahini", "lemon", "garlic", "salt")


def test_product_policy_picks_every_named_recipe_item_and_stops(tmp_path) -> None:
    emb = load_embedder("onehot", tmp_path)
    states = [
        _state("Blend the chickpeas with the tahini.", {"chickpeas", "tahini"}, RECIPE),
        _state("Season with salt and the juice of the lemon.", {"salt", "lemon"}, RECIPE),
        # the distractor "honey" is named but the recipe does not use it
        _state("Add the garlic, not honey.", {"garlic"}, RECIPE),
    ]
    policy = RecipeAwarePolicy(emb, "product")
    score = evaluate(policy, states)
    assert score.accuracy == 1.0 and score.recall == 1.0
    assert score.picks_per_state == (2 + 2 + 1) / 3


def test_without_the_recipe_a_named_distractor_is_picked(tmp_path) -> None:
    emb = load_embedder("onehot", tmp_path)
    state = _state("Add the garlic, then honey.", {"garlic"}, ())
    assert set(RecipeAwarePolicy(emb, "blind").picks(state)) == {"Put garlic on table", "Put honey on table"}


def test_fitted_options_come_from_the_grid(tmp_path) -> None:
    emb = load_embedder("onehot", tmp_path)
    opts = fit_selection_options(emb, [_state("Blend the chickpeas.", {"chickpeas"}, RECIPE)])
    assert 0.0 < opts.rho < 0.8 and opts.margin in (0.0, 0.05)


def test_similarity_only_ablation_never_picks_outside_the_recipe(tmp_path) -> None:
    from scone_bt.instruction_following.product_policy import RecipeSimilarityPolicy

    emb = load_embedder("onehot", tmp_path)
    state = _state("Put honey on table", {"garlic"}, RECIPE)  # the step text equals a distractor's action
    picks = evaluate(RecipeSimilarityPolicy(emb, "sim", rho=0.0, delta=0.0), [state]).episodes[0].picks
    assert picks and all(p.removeprefix("Put ").removesuffix(" on table") in RECIPE for p in picks)
