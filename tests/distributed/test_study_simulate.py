"""scone-study simulate on Ray writes the same study log as the default in-process run."""

from __future__ import annotations

import sqlite3

from scone_bt.distributed import EngineKind, EngineOptions
from scone_bt.study.cli import main as study_main
from scone_bt.study.simulate import SimulationOptions, simulate_study

_QUERIES = {  # every column but the wall-clock timestamps
    "sessions": "SELECT id, participant, grp, session_index, condition, simulated, info, summary FROM sessions",
    "events": "SELECT id, session_id, kind, data FROM events",
    "responses": "SELECT session_id, questionnaire, item, item_index, value FROM responses",
}


def _content(path) -> dict[str, list[tuple]]:
    conn = sqlite3.connect(path)
    try:
        return {name: conn.execute(q + " ORDER BY 1, 2, 3").fetchall() for name, q in _QUERIES.items()}
    finally:
        conn.close()


def test_simulated_study_is_identical_on_ray_and_in_process(ray_runtime, tmp_path):
    options = SimulationOptions(participants=5, seed=4, fast=True)
    simulate_study(tmp_path / "serial.db", options, printer=lambda _l: None).close()
    engine = EngineOptions(EngineKind.RAY, workers=2, address="auto")
    simulate_study(tmp_path / "ray.db", options, printer=lambda _l: None, engine=engine).close()
    serial, on_ray = _content(tmp_path / "serial.db"), _content(tmp_path / "ray.db")
    assert len(serial["sessions"]) == 10 and len(serial["events"]) > 50 and serial["responses"]
    assert serial == on_ray


def test_simulate_command_takes_jobs(tmp_path, capsys):
    assert (
        study_main(
            ["simulate", "--participants", "4", "--fast", "--jobs", "2", "--db", str(tmp_path / "p.db")]
        )
        == 0
    )
    assert "SIMULATED study written" in capsys.readouterr().out
    from scone_bt.study.trust import trust_parameters

    fitted = SimulationOptions(
        participants=4, fast=True, trust=trust_parameters("fitted")
    )  # the CLI's default
    simulate_study(tmp_path / "s.db", fitted, printer=lambda _l: None).close()
    assert _content(tmp_path / "p.db") == _content(tmp_path / "s.db")
