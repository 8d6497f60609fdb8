from scone_bt.human import HumanOptions, SimulatedHuman
from scone_bt.recipes import load_recipe, stock_recipe


def test_human_works_through_steps_with_help(kitchen, kitchen_cfg, rng):
    recipe = stock_recipe(load_recipe("example:tomato-pasta"), kitchen_cfg.catalogue)
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in recipe.needed], rng)
    human = SimulatedHuman(kitchen, recipe, HumanOptions(fetch_time_s=1.0, cook_time_s=0.5, patience_s=1e9))
    assert human.current_instruction == recipe.steps[0].instruction
    for _ in range(30):  # nobody fetches anything: the human waits on step 1
        kitchen.advance(0.1)
        human.update()
    assert human.step_index == 0 and not human.done
    for name in recipe.needed:
        human.request_help(name)
        assert human.help_pending(name)
    for _ in range(80):
        kitchen.advance(0.1)
        human.update()
    assert human.done and human.help_given == len(recipe.needed) and human.interventions == 0


def test_patience_leads_to_intervention(kitchen, kitchen_cfg, rng):
    recipe = stock_recipe(load_recipe("example:tomato-pasta"), kitchen_cfg.catalogue)
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in recipe.needed], rng)
    human = SimulatedHuman(kitchen, recipe, HumanOptions(fetch_time_s=0.5, patience_s=2.0))
    for _ in range(40):
        kitchen.advance(0.1)
        human.update()
    assert human.interventions >= 1 and kitchen.is_on_table("salt")
