"""Outputs never destroy inputs (issue 27): every output path is checked before the robot acts, against the run's
inputs and store (resolved paths and inodes, symlinks followed) and against what the existing file is."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from scone_bt.checks import write_atomic
from scone_bt.cli import bench
from scone_bt.cli.run import build_parser, main, options_from_args, viewer_command
from scone_bt.experience import ExperienceStore, Outcome
from scone_bt.resources import data_dir

REPO = Path(__file__).resolve().parents[2]


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _refused(argv: list[str], capsys) -> str:  # noqa: ANN001
    code = main(["--quiet", "--max-ticks", "1", *argv])
    out = capsys.readouterr()
    err = out.err.strip()
    assert code == 2, (code, err)
    assert err.startswith("scone-run: error:") and "\n" not in err and "Traceback" not in err, err
    assert out.out == ""  # nothing was built or printed: no header, no decision
    return err


@pytest.fixture
def store(tmp_path) -> Path:
    path = tmp_path / "runs" / "panda.db"
    with ExperienceStore(path) as s:
        s.append(Outcome(1.0, "Put salt on table", "salt", "minilm", success=True, robot_id="panda"))
    return path


def test_save_over_the_store_is_refused_and_the_store_is_byte_identical(store, capsys):
    before = {p.name: _digest(p) for p in store.parent.iterdir()}
    err = _refused(["--experience", str(store), "--save", str(store)], capsys)
    assert "is the --experience store of this run" in err
    # the same file by another name: a symlink, a hard link, a relative path with ..
    link = store.parent / "link.db"
    link.symlink_to(store)
    hard = store.parent / "hard.db"
    os.link(store, hard)
    for other in (link, hard, store.parent / ".." / "runs" / "panda.db"):
        assert "--experience store" in _refused(["--experience", str(store), "--save", str(other)], capsys)
    # SQLite's own files beside the store are the store too
    assert "--experience store" in _refused(
        ["--experience", str(store), "--save", str(store) + "-wal"], capsys
    )
    assert {p.name: _digest(p) for p in store.parent.iterdir() if p.name == store.name} == {
        store.name: before[store.name]
    }
    with ExperienceStore(store) as s:
        assert len(s) == 1


@pytest.mark.parametrize(
    ("flag", "source"),
    [
        ("--kitchen", data_dir("perception") / "kitchen.yaml"),
        ("--recipe", REPO / "scone_bt" / "recipes" / "examples" / "hummus.yaml"),
        ("--tree", data_dir("trees") / "assistive_cooking.yaml"),
        ("--arm", data_dir("robots") / "panda.yaml"),
        ("--catalogue", data_dir("perception") / "catalogue" / "herbs.yaml"),
    ],
)
def test_save_over_an_input_is_refused_even_with_force(flag, source, tmp_path, capsys):
    copy = tmp_path / source.name
    shutil.copyfile(source, copy)
    digest = _digest(copy)
    err = _refused([flag, str(copy), "--save", str(copy), "--force"], capsys)
    assert f"is the {flag} input of this run" in err
    assert _digest(copy) == digest


def test_save_over_a_file_the_kitchen_names_is_refused(capsys):
    catalogue = data_dir("perception") / "catalogue" / "herbs.yaml"
    digest = _digest(catalogue)
    assert "--kitchen input" in _refused(["--save", str(catalogue), "--force"], capsys)
    assert _digest(catalogue) == digest


def test_an_existing_file_of_another_kind_is_kept_unless_forced(tmp_path, capsys):
    notes = tmp_path / "notes.json"
    notes.write_text('{"mine": true}\n')
    err = _refused(["--save", str(notes)], capsys)
    assert "exists and is not a rerun recording" in err and "--force" in err
    assert notes.read_text() == '{"mine": true}\n'
    # with --force (or onto an earlier recording) the checks pass: the episode may write it
    options_from_args(build_parser().parse_args(["--save", str(notes), "--force"]))
    old = tmp_path / "old.rrd"
    old.write_bytes(b"RRF2" + bytes(60))
    options_from_args(build_parser().parse_args(["--save", str(old)]))


@pytest.mark.parametrize("target", ["/dev/full", "fifo"])
def test_a_device_or_fifo_is_refused_at_once(target, tmp_path, capsys):
    if target == "fifo":
        target = str(tmp_path / "fifo.rrd")
        os.mkfifo(target)
    err = _refused(["--save", target], capsys)
    assert ("is a device" in err) if target == "/dev/full" else ("is a FIFO" in err)


def test_bench_json_is_checked_before_the_benchmark_runs(tmp_path, capsys):
    demo = tmp_path / "demo.rrd"
    demo.write_bytes(b"RRF2" + bytes(60))
    assert bench.main(["viz", "--ticks", "2", "--save-demo", str(demo), "--json", str(demo)]) == 2
    assert "--save-demo input" in capsys.readouterr().err
    assert demo.read_bytes() == b"RRF2" + bytes(60)
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    assert bench.main(["viz", "--ticks", "2", "--json", str(notes)]) == 2
    err = capsys.readouterr().err
    assert "exists and is not a benchmark report" in err and "\n" not in err.strip()
    assert notes.read_text() == "my notes\n"
    assert bench.main(["viz", "--ticks", "2", "--frame-every", "2", "--json", str(notes), "--force"]) == 0
    assert json.loads(notes.read_text())["ticks"] == 2
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary file left


def test_a_report_is_replaced_whole_or_not_at_all(tmp_path):
    report = tmp_path / "r.json"
    report.write_text('{"old": 1}\n')
    os.chmod(report, 0o640)

    with pytest.raises(TypeError):
        write_atomic(report, 12345)  # type: ignore[arg-type]  # fails while writing the temporary file
    assert report.read_text() == '{"old": 1}\n'
    write_atomic(report, '{"new": 2}\n')
    assert json.loads(report.read_text()) == {"new": 2}
    assert oct(report.stat().st_mode & 0o777) == oct(0o640)  # the old file's permissions are kept
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]


def test_the_viewer_command_works_from_a_fresh_shell(monkeypatch):
    monkeypatch.chdir(REPO)
    command = viewer_command(Path("runs/episode.rrd"))
    exe, arg = command.split(" ")
    assert arg == "runs/episode.rrd"
    venv_rerun = Path(sys.executable).parent / "rerun"
    if not venv_rerun.is_file():
        pytest.skip("no rerun beside this interpreter")
    assert exe == os.path.relpath(venv_rerun, REPO) or exe == str(venv_rerun)
    # a fresh shell: no venv on PATH
    done = subprocess.run(
        [exe, "--version"],
        cwd=REPO,
        env={"PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0 and "rerun" in done.stdout.lower()


@pytest.mark.skipif(not Path("/proc/self").exists(), reason="needs Linux's /proc")
def test_a_folder_where_no_file_can_be_made_is_refused_even_for_root(tmp_path) -> None:
    """os.access says yes to root on /proc and /sys: the check makes (and removes) a file to find out."""
    from scone_bt.checks import check_output_dir, check_output_file
    from scone_bt.errors import SconeError

    with pytest.raises(SconeError, match=r"--save /proc/x/a.rrd: cannot write in /proc \(read-only"):
        check_output_file(Path("/proc/x/a.rrd"), "--save")
    with pytest.raises(SconeError, match="--out /proc/x: cannot write in /proc"):
        check_output_dir(Path("/proc/x"), "--out")
    assert check_output_file(tmp_path / "a" / "b.json", "--json") == tmp_path / "a" / "b.json"
    assert list(tmp_path.iterdir()) == []  # the probe left nothing behind


def test_save_over_the_urdf_or_a_mesh_the_arm_file_reads_is_refused_even_with_force(tmp_path, capsys):
    robots = tmp_path / "robots"
    shutil.copytree(data_dir("robots") / "iiwa7", robots / "iiwa7")
    arm = robots / "mine.yaml"
    shutil.copyfile(data_dir("robots") / "iiwa7.yaml", arm)
    urdf = robots / "iiwa7" / "iiwa7_gripper.urdf"
    beside = robots / "iiwa7" / "notes.txt"
    beside.write_text("a mesh or a note beside the URDF\n")
    before = {p: _digest(p) for p in (urdf, beside)}
    for target in (urdf, beside):
        err = _refused(["--arm", str(arm), "--save", str(target), "--force"], capsys)
        assert "is the --arm input of this run" in err
    assert {p: _digest(p) for p in (urdf, beside)} == before


def test_a_benchmark_report_is_never_written_over_a_product_file_the_kitchen_names(tmp_path, capsys):
    """A JSON product file (a kitchen may name one) passes the report's own JSON check: only the kitchen's
    list of product files protects it."""
    products = tmp_path / "mine.json"
    products.write_text(
        json.dumps(
            {
                "family": "mine",
                "source": "a test",
                "defaults": {"shape": "box", "material": "cardboard", "friction": 0.5},
                "products": [
                    {"name": "widget flour", "size": [0.07, 0.05, 0.1], "mass": 0.3, "marker_id": 900},
                ],
            }
        )
    )
    kitchen = tmp_path / "k.yaml"
    text = (data_dir("perception") / "kitchen.yaml").read_text()
    kitchen.write_text(
        text.replace(
            "catalogue: [catalogue]", f"catalogue: [{data_dir('perception') / 'catalogue'}, mine.json]"
        )
    )
    assert str(products.name) in kitchen.read_text()
    digest = _digest(products)
    code = bench.main(["perception", "--kitchen", str(kitchen), "--scenes", "1", "--json", str(products)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "is the --kitchen input of this run" in err, err
    assert _digest(products) == digest
    # A kitchen named by its name protects its product files too; the subcommand's name is no path.
    herbs = data_dir("perception") / "catalogue" / "herbs.yaml"
    assert bench.main(["perception", "--kitchen", "kitchen", "--json", str(herbs)]) == 2
    err = capsys.readouterr().err
    assert "is the --kitchen input of this run" in err and "--command" not in err, err
