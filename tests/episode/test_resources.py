"""EpisodeResources closes what it owns; a ModelPool loads each embedder once for every episode that shares it."""

from __future__ import annotations

import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.episode import EpisodeResources, ModelPool
from tests.behaviours.fakes import FakeRobot


def _options(tmp_path, **kw) -> BehaviourOptions:
    return BehaviourOptions(embedder="onehot", cache_dir=tmp_path / "cache", **kw).resolve()


def test_a_shared_pool_loads_the_embedder_once(tmp_path) -> None:
    with ModelPool() as pool:
        embedders = []
        for _ in range(3):  # three episodes in one process
            with EpisodeResources(FakeRobot(), _options(tmp_path), "r", "panda", models=pool) as res:
                embedders.append(res.embedder())
        assert pool.loads == 1 and all(e is embedders[0] for e in embedders)


def test_resources_close_the_robot_and_the_store_even_when_the_episode_fails(tmp_path) -> None:
    robot = FakeRobot()
    lines: list[str] = []
    with (
        pytest.raises(RuntimeError),
        EpisodeResources(
            robot, _options(tmp_path, experience_path=tmp_path / "x.db"), "r", "panda", lines.append
        ) as res,
    ):
        store = res.store()
        assert store is not None and res.store() is store
        res.estimator()
        raise RuntimeError("the episode broke")
    assert robot.closed
    with pytest.raises(Exception):  # noqa: B017 - any error: the connection is closed
        len(store)


def test_without_a_store_kappa_learns_in_memory_only(tmp_path) -> None:
    with EpisodeResources(FakeRobot(), _options(tmp_path), "r", "panda") as res:
        assert res.store() is None and res.estimator() is res.estimator()
