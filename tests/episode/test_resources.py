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


def _store_from_two_engines(path) -> None:
    from scone_bt.experience import BACKEND_KEY, Outcome, open_store

    labelled = [("sim", "salt", True)] * 3 + [("mujoco", "eggs", False)] * 2
    with open_store(path) as store:
        for i, (backend, obj, ok) in enumerate(labelled):
            context = {BACKEND_KEY: backend, "seed": i}
            store.append(
                Outcome(float(i), f"Put {obj} on table", obj, "onehot", ok, context=context, robot_id="r")
            )
        # stored before outcomes named their backend
        store.append(Outcome(9.0, "Put honey on table", "honey", "onehot", True, robot_id="r", arm="panda"))


@pytest.mark.parametrize(
    ("backend", "learn_from", "expected"),
    [
        (
            "mujoco",
            "self",
            "κ̂ rebuilt from 3 stored outcomes of robot 'r' on the 'mujoco' backend (1 stored before",
        ),
        (
            "sim",
            "self",
            "κ̂ rebuilt from 4 stored outcomes of robot 'r' on the 'sim' backend (1 stored before",
        ),
        ("mujoco", "fleet", "κ̂ rebuilt from 6 stored outcomes of the whole fleet, every backend's"),
    ],
)
def test_kappa_learns_only_from_its_own_backend_unless_it_asks_for_the_fleet(
    tmp_path, backend, learn_from, expected
) -> None:
    path = tmp_path / "x.db"
    _store_from_two_engines(path)
    lines: list[str] = []
    opts = _options(tmp_path, experience_path=path, learn_from=learn_from)
    with EpisodeResources(FakeRobot(), opts, "r", "panda", lines.append, backend=backend) as res:
        n = res.estimator().n_observations
    assert len(lines) == 1 and lines[0].startswith(expected)
    assert n == int(expected.split()[3])
