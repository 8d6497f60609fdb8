"""A whole seeded episode on the MuJoCo backend (``scone-run --robot mujoco``): it serves the recipe, repeats
exactly, and never loads PyBullet (nor a PyBullet episode MuJoCo)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
pytest.importorskip("mujoco")

from scone_bt.behaviours import BehaviourOptions  # noqa: E402
from scone_bt.episode import EpisodeOptions, run_episode  # noqa: E402

pytestmark = pytest.mark.slow


def _options(seed: int = 0) -> EpisodeOptions:
    return EpisodeOptions(
        recipe="example:tomato-pasta",
        seed=seed,
        backend="mujoco",
        distractors=2,
        behaviour=BehaviourOptions(seed=seed),
    )


def test_a_mujoco_episode_serves_the_recipe_and_repeats_exactly():
    first = run_episode(_options(), printer=lambda _line: None)
    assert first.completed and first.steps_completed == first.steps_total
    assert all(first.needed_on_table.values()), first.needed_on_table
    assert first.successes >= 3, "the robot should fetch most ingredients itself"
    assert first.attempted == first.successes + first.failures + first.takeovers
    second = run_episode(_options(), printer=lambda _line: None)
    assert second.deterministic_part() == first.deterministic_part()


_ENGINES = (
    "import sys\n"
    "from scone_bt.episode import EpisodeOptions, run_episode\n"
    "s = run_episode(EpisodeOptions(recipe='example:tomato-pasta', backend=sys.argv[1], distractors=0,"
    " max_ticks=3), printer=lambda _l: None)\n"
    "print('pybullet' in sys.modules, 'mujoco' in sys.modules)\n"
)


@pytest.mark.parametrize(("backend", "loaded"), [("mujoco", "False True"), ("sim", "True False")])
def test_an_episode_loads_only_its_own_engine(backend: str, loaded: str):
    out = subprocess.run(
        [sys.executable, "-c", _ENGINES, backend],
        capture_output=True,
        text=True,
        env={**os.environ},
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split()[-2:] == loaded.split(), out.stdout


def test_without_the_extra_the_backend_names_it_in_one_line():
    code = (
        "import sys\n"
        "sys.modules['mujoco'] = None  # as if the extra were not installed\n"
        "from scone_bt.errors import SconeError\n"
        "from scone_bt.world.mj_model import import_mujoco\n"
        "try:\n"
        "    import_mujoco()\n"
        "except SconeError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "--robot mujoco needs the mujoco package: pip install -e '.[mujoco]'", out


def test_a_renderer_that_cannot_load_is_one_line_naming_the_debian_packages(tmp_path):
    db, rrd = tmp_path / "outcomes.db", tmp_path / "run.rrd"
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "scone_bt.cli.run",
            "--robot",
            "mujoco",
            "--headless",
            "--seed",
            "0",
            "--experience",
            str(db),
            "--save",
            str(rrd),
        ],
        capture_output=True,
        text=True,
        env={**os.environ, "MUJOCO_GL": "bogus"},
        timeout=300,
    )
    lines = (out.stdout + out.stderr).strip().splitlines()
    assert out.returncode == 2 and len(lines) == 1, out.stdout + out.stderr
    assert "MUJOCO_GL=bogus" in lines[0] and "libegl1 libegl-mesa0 libgl1-mesa-dri" in lines[0]
    assert not db.exists() and not rrd.exists()  # nothing is stored


@pytest.mark.parametrize(
    ("mesh", "content", "says"),
    [
        ("junk.obj", "v 0 0 0\nf garbage here\n", "could not parse OBJ file"),
        ("link3.dae", '<?xml version="1.0"?><COLLADA/>\n', "no decoder found for mesh file"),
    ],
)
def test_a_model_mujoco_cannot_load_is_one_line_naming_the_files_and_nothing_is_stored(
    tmp_path, capsys, mesh, content, says
):
    """A mesh MuJoCo cannot read (the planner's Pinocchio never opens it): the robot file, the URDF and the mesh
    are named in one line, before an outcome store or a recording is created."""
    import pybullet_data

    from scone_bt.cli.run import main

    panda = os.path.join(pybullet_data.getDataPath(), "franka_panda")
    (tmp_path / "meshes").symlink_to(os.path.join(panda, "meshes"))
    (tmp_path / mesh).write_text(content, encoding="utf-8")
    with open(os.path.join(panda, "panda.urdf"), encoding="utf-8") as f:
        urdf = f.read().replace("package://meshes/collision/link3.obj", f"package://{mesh}", 1)
    (tmp_path / "panda.urdf").write_text(urdf, encoding="utf-8")
    with open(
        os.path.join(os.path.dirname(__file__), "..", "..", "robots", "panda.yaml"), encoding="utf-8"
    ) as f:
        robot = "".join(
            f"urdf: {tmp_path / 'panda.urdf'}\n" if line.startswith("urdf:") else line for line in f
        )
    (tmp_path / "arm.yaml").write_text(robot, encoding="utf-8")
    db, rrd = tmp_path / "outcomes.db", tmp_path / "run.rrd"
    argv = ["--robot", "mujoco", "--arm", str(tmp_path / "arm.yaml"), "--headless", "--quiet"]
    assert main([*argv, "--experience", str(db), "--save", str(rrd)]) == 2
    out = capsys.readouterr()
    err = out.err.strip()
    assert "\n" not in err and "Traceback" not in err and out.out == "", out
    assert str(tmp_path / "arm.yaml") in err and str(tmp_path / "panda.urdf") in err
    assert str(tmp_path / mesh) in err and says in err
    assert not db.exists() and not rrd.exists()
