"""Bad input to scone-run: one line on stderr, exit status 2, no traceback."""

import pytest

from scone_bt.cli.run import main


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--arm", "no_such_arm"], "panda"),
        (["--recipe", "example:nope"], "example:tomato-pasta"),
        (["--tree", "no_such_tree"], "assistive_cooking"),
        (["--confidence-threshold", "1.5"], "[0, 1]"),
    ],
)
def test_bad_arguments_give_one_line(argv, expected, capsys):
    assert main(["--robot", "sim", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("scone-run: error:") and expected in err
    assert "\n" not in err and "Traceback" not in err


def test_bad_backend_is_rejected_by_argparse(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--robot", "real"])
    assert exit_.value.code == 2
    assert "sim" in capsys.readouterr().err
