"""--learn-from on a shared PostgreSQL store: whose outcomes rebuild κ̂, and scone-run's one-line errors."""

from __future__ import annotations

import socket

import numpy as np
import pytest

from scone_bt.confidence import make_estimator, rebuild_estimator
from scone_bt.experience import LearnFrom, Outcome, open_store


class _WordEmbedder:
    """A tiny deterministic embedder: one dimension per object word (enough to tell actions apart)."""

    dim = 4
    _words = ("salt", "eggs", "honey", "pasta")

    def embed(self, texts):
        return np.array([[float(w in t) for w in self._words] for t in texts], dtype=np.float32)


def _fleet(url: str) -> None:
    with open_store(url) as store:
        rows = [("panda-1", "panda", "nominal")] * 4 + [("panda-2", "panda", "nominal")] * 3
        rows += [("panda-3", "panda", "weak")] * 2 + [("iiwa-1", "iiwa7", "nominal")] * 5
        for i, (robot, arm, profile) in enumerate(rows):
            obj = ("salt", "eggs", "honey", "pasta")[i % 4]
            store.append(
                Outcome(
                    float(i),
                    f"Put {obj} on table",
                    obj,
                    "minilm",
                    obj != "eggs",
                    robot_id=robot,
                    arm=arm,
                    profile=profile,
                )
            )


def test_learn_from_selects_whose_outcomes_rebuild_kappa(pg_url):
    _fleet(pg_url)
    counts = {}
    with open_store(pg_url) as store:
        for choice in LearnFrom:
            est = make_estimator("knn", seed=0)
            counts[choice.value] = rebuild_estimator(
                est, store, _WordEmbedder(), **choice.filters("panda-2", "panda", "nominal")
            )
            assert est.n_observations == counts[choice.value]
    assert counts == {"self": 3, "same-model": 7, "fleet": 14}


def test_unreachable_fleet_store_stops_scone_run_before_the_robot_acts(capsys):
    from scone_bt.cli.run import main

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # nothing listens here once the socket is closed
    code = main(
        ["--robot", "sim", "--quiet", "--experience", f"postgresql://robot:pw@127.0.0.1:{port}/fleet"]
    )
    out = capsys.readouterr()
    err = out.err.strip()
    assert code == 2 and "cannot connect to experience store" in err and "pw@" not in err
    assert "\n" not in err and "Traceback" not in err and "ACT" not in out.out


def test_bad_learn_from_is_rejected_by_argparse(capsys):
    from scone_bt.cli.run import main

    with pytest.raises(SystemExit) as exit_:
        main(["--robot", "sim", "--learn-from", "everyone"])
    assert exit_.value.code == 2 and "same-model" in capsys.readouterr().err
