"""One seed split per stage with SeedSequence: repeatable, independent streams; planner seeds per attempt."""

from __future__ import annotations

import numpy as np

from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan, SeedStage


def test_each_stage_has_its_own_repeatable_stream() -> None:
    plan = SeedPlan(7)
    ints = {stage: plan.integer(stage) for stage in SeedStage}
    assert len(set(ints.values())) == len(SeedStage)  # no two stages share a stream
    assert ints == {stage: SeedPlan(7).integer(stage) for stage in SeedStage}
    assert ints != {stage: SeedPlan(8).integer(stage) for stage in SeedStage}
    a = plan.generator(SeedStage.PERCEPTION).normal(size=3)
    assert np.array_equal(a, SeedPlan(7).generator(SeedStage.PERCEPTION).normal(size=3))


def test_drawing_more_in_one_stage_leaves_the_others_alone() -> None:
    plan = SeedPlan(3)
    plan.generator(SeedStage.PERCEPTION).random(10_000)  # a camera that renders a lot
    assert plan.integer(SeedStage.HUMAN) == SeedPlan(3).integer(SeedStage.HUMAN)


def test_planner_seeds_are_distinct_per_attempt_and_repeat_per_episode() -> None:
    first = PlannerSeedStream(SeedPlan(0))
    seeds = [first.next_seed() for _ in range(5)]
    assert len(set(seeds)) == 5 and all(0 <= s < 2**32 for s in seeds)
    again = PlannerSeedStream(SeedPlan(0))
    assert [again.next_seed() for _ in range(5)] == seeds and first.issued == 5
