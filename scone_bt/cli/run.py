"""scone-run: one assistive-cooking episode in simulation.

Examples:
    scone-run --robot sim                                  # default recipe, seed 0, headless
    scone-run --robot sim --recipe example:pancakes --save runs/pancakes.rrd
    scone-run --robot sim --recipe "nw:asian/Banh Mi Sandwich" --viewer
    scone-run --robot sim --experience runs/panda.db       # learning carries over between runs
    scone-run --robot sim --experience postgresql://robot@fleet-db/scone --robot-id panda-2 --learn-from same-model
    scone-run --robot sim --no-self-confidence             # the paper's control condition: always act
"""

from __future__ import annotations

import os
import re
import signal
import sys
import threading
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable
    from types import FrameType

    from scone_bt.resources import DataKind


class _Interrupts:
    """Ctrl-C (or SIGTERM: `kill`, `timeout`) at any moment of scone-run: one line saying what was saved, exit
    status 130, never a traceback.

    Phases: before `main` runs its work nothing can have been stored, so SIGINT prints the line and exits at once
    (a KeyboardInterrupt raised inside an import would print a traceback); while the run is under way SIGINT
    raises KeyboardInterrupt, which unwinds the episode (the store closes, an unfinished write rolls back) to
    `main`, which counts what is stored and prints the line; once the line is out, another SIGINT (during the
    interpreter's shutdown) ends the process quietly.

    A Ctrl-C that lands inside an import is not raised there but deferred: importlib's own callbacks report an
    exception raised in them as "ignored" and go on (the run then finished and exited 0), and one raised while a
    module lock is held left the next import waiting forever (CI and a stress run saw both). `pending` is set, and
    the episode's next event raises it (`check`, in plain Python); a run that returns with it set ends as
    interrupted all the same. So does one whose KeyboardInterrupt a library swallowed.
    """

    EARLY, RUNNING, REPORTED = "early", "running", "reported"

    def __init__(self) -> None:
        self.phase = self.EARLY
        self.previous: Callable[[int, FrameType | None], Any] | int | None = None  # SIGINT's handler before
        # SIGTERM's handler before, when this took it
        self.previous_term: Callable[[int, FrameType | None], Any] | int | None = None
        self.pending = False  # a Ctrl-C came while running: the run must end as interrupted

    def check(self) -> None:
        """Raise a Ctrl-C that came and was deferred or swallowed; only in the main thread, where the episode
        runs."""
        if self.pending and threading.current_thread() is threading.main_thread():
            self.phase = self.REPORTED  # a second Ctrl-C while this one unwinds ends the process at once
            raise KeyboardInterrupt

    def install(self) -> None:
        if threading.current_thread() is threading.main_thread():  # signals can only be set from there
            if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:  # `kill`, `timeout`: an interrupt too
                signal.signal(signal.SIGTERM, self._handle)  # also for a job started with SIGINT ignored
                self.previous_term = signal.SIG_DFL
            if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
                # Started with SIGINT ignored (`scone-run … &` in a script, nohup): a terminal's Ctrl-C is not
                # meant for this run, and it keeps ignoring it, as such jobs conventionally do.
                return
            previous = signal.signal(signal.SIGINT, self._handle)
            if previous != self._handle:
                self.previous = previous

    def restore(self) -> None:
        """Give SIGINT back to whoever had it (a test runner calling `main`), once the run is over."""
        if self.previous is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, self.previous)
            self.previous = None
        if self.previous_term is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, self.previous_term)
            self.previous_term = None

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.phase == self.RUNNING:
            self.pending = True
            if _inside_import(frame):
                return  # raised here it could be ignored or leave a module lock held: the next event raises it
            self.phase = self.REPORTED  # a second Ctrl-C while the first unwinds ends the process at once
            raise KeyboardInterrupt
        if self.phase == self.EARLY:
            _write_line(f"{_PROG}: interrupted; nothing was stored")
        os._exit(130)


def _inside_import(frame: FrameType | None) -> bool:
    """Whether the interrupted code runs inside importlib's machinery (any frame of the stack)."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _write_line(line: str) -> None:
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed or broken stderr: the exit status still says it
        pass


_PROG = "scone-run"
_INTERRUPTS = _Interrupts()
# Installed before anything heavy is imported, when this process is scone-run itself (not a test importing it).
_IS_PROGRAM = os.path.basename(sys.argv[0] if sys.argv else "").startswith(_PROG)
if _IS_PROGRAM:
    _INTERRUPTS.install()

import argparse  # noqa: E402 - after the SIGINT handler, on purpose
import contextlib  # noqa: E402
import logging  # noqa: E402
import shlex  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from scone_bt.argparsing import OneLineArgumentParser, path_arg, store_arg  # noqa: E402
from scone_bt.checks import internal_error_line  # noqa: E402
from scone_bt.cli.tree_options import add_tree_options, check_flags_take_effect, tree_overrides  # noqa: E402
from scone_bt.defaults import EPISODE as _EPISODE  # noqa: E402
from scone_bt.errors import SconeError  # noqa: E402
from scone_bt.robot.flags import add_robot_options, check_backend  # noqa: E402
from scone_bt.study.ui_args import add_ui_arguments  # noqa: E402 - light: the package loads lazily

__all__ = ["main", "build_parser", "LOG_LEVELS", "viewer_command"]

LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR", "CRITICAL")
"""Values of --log-level (Python logging's level names)."""

# Libraries whose Python log lines go through --log-level (their own defaults print at INFO, or raw).
_LIBRARY_LOGGERS = (
    "uvicorn",
    "uvicorn.error",
    "uvicorn.access",
    "ray",
    "pymc",
    "pytensor",
    "rerun",
    "psycopg",
)
# rerun logs from Rust straight to the terminal; RUST_LOG (read when rerun is imported) is the only control.
# Every condition rerun warns about (a stalled or gone viewer, a full disk) is reported by scone-run itself in
# one line, so its own lines are shown only when a user asks for more than warnings.
_RUST_LOG = {"DEBUG": "debug", "INFO": "warn", "WARNING": "off", "ERROR": "off", "CRITICAL": "off"}


CONNECT_TIMEOUT_S = (
    2.0  # the values of scone_bt.viz.connect and .recorder, kept here so --help imports nothing heavy
)
HANDSHAKE_TIMEOUT_S = 3.0
VIEWER_STALL_TIMEOUT_S = 5.0
PG_CONNECT_TIMEOUT_S = 10  # scone_bt.experience.postgres.CONNECT_TIMEOUT_S


def build_parser() -> argparse.ArgumentParser:
    """`scone-run`'s parser: its option groups, in the order --help lists them."""
    p = OneLineArgumentParser(
        prog="scone-run",
        description=(
            "Run the SCONE assistive-cooking robot: it perceives the shelf, ranks 'Put X on table' actions against "
            "the current recipe step, predicts its own success (self-confidence) and either acts or asks the human "
            "for help. Prints one line per decision and a summary."
        ),
        epilog="examples:" + __doc__.split("Examples:", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_input_options(p)
    _add_run_control_options(p)
    _add_rerun_options(p)
    _add_self_confidence_options(p)
    g = p.add_argument_group(
        "decision settings",
        "the tree file's parameters (trees/*.yaml); one left out takes the tree file's value",
    )
    add_tree_options(g)
    _add_human_options(p)

    # A real person instead of the simulated human: the tablet UI (scone_bt/study).
    add_ui_arguments(p)
    return p


def _add_input_options(p: argparse.ArgumentParser) -> None:
    """What the episode runs: robot, recipe, kitchen, catalogues, tree, distractors."""
    g = p.add_argument_group("input")
    add_robot_options(g, arm_default=_EPISODE.arm)
    g.add_argument(
        "--recipe",
        default=_EPISODE.recipe,
        help="recipe: example:<name> (tomato-pasta, pancakes, hummus), an id from ../shared/data/recipes/recipes.jsonl, "
        "or a JSON/YAML file of the same shape (default: %(default)s)",
    )
    g.add_argument(
        "--kitchen",
        default=_EPISODE.kitchen,
        help="kitchen file in perception/ or a path (default: %(default)s)",
    )
    g.add_argument(
        "--catalogue",
        action="append",
        default=[],
        metavar="FILE",
        help="one more product file (perception/catalogue/*.yaml shape) merged into the catalogue; repeatable",
    )
    g.add_argument(
        "--tree", default=_EPISODE.tree, help="tree file in trees/ or a path (default: %(default)s)"
    )
    g.add_argument(
        "--distractors",
        type=int,
        default=_EPISODE.distractors,
        help="objects not in the recipe put on the shelf (default: %(default)s)",
    )


def _add_run_control_options(p: argparse.ArgumentParser) -> None:
    """Seed, length, windows, printing, logging and --force."""
    g = p.add_argument_group("run control")
    g.add_argument(
        "--seed",
        type=int,
        default=_EPISODE.seed,
        help="seeds everything; a seeded run repeats exactly (default: %(default)s)",
    )
    g.add_argument(
        "--max-ticks",
        type=int,
        default=_EPISODE.max_ticks,
        help=f"limit on {_EPISODE.tick_period:g} s control ticks (default: %(default)s)",
    )
    g.add_argument("--headless", action="store_true", help="no windows (the default; kept for scripts)")
    g.add_argument("--gui", action="store_true", help="open PyBullet's own window (needs a display)")
    g.add_argument("--quiet", action="store_true", help="print only the summary")
    g.add_argument(
        "--log-level",
        default="WARNING",
        type=str.upper,
        choices=LOG_LEVELS,
        help="log lines of scone-run and of other libraries (uvicorn, Ray, PyMC, psycopg) at this level and above go "
        "to stderr as 'scone-run: LEVEL: ...' lines, never into the decision lines; rerun's own (Rust) log is shown "
        "only at INFO (its warnings) or DEBUG (default: %(default)s)",
    )
    g.add_argument(
        "--force",
        action="store_true",
        help="let --save replace an existing file that is not a rerun recording (an input or the store of the run "
        "is never overwritten)",
    )


def _add_rerun_options(p: argparse.ArgumentParser) -> None:
    """Recording and the rerun viewer."""
    g = p.add_argument_group("rerun output")
    g.add_argument(
        "--save",
        type=path_arg,
        metavar="FILE.rrd",
        help="record the episode for the rerun viewer; an existing recording is replaced, any other file is refused "
        "unless --force, and an input or the store of this run is refused even with --force",
    )
    g.add_argument("--viewer", action="store_true", help="spawn the rerun live viewer")
    g.add_argument(
        "--connect",
        metavar="ADDR",
        help="stream to a running rerun viewer (e.g. rerun+http://127.0.0.1:9876/proxy); checked before the first "
        f"decision: no TCP connection within {CONNECT_TIMEOUT_S:g} s or no gRPC answer within {HANDSHAKE_TIMEOUT_S:g} s is "
        f"a one-line error; a viewer that does not take the data within {VIEWER_STALL_TIMEOUT_S:g} s mid-run is "
        "dropped and the episode goes on",
    )


def _robot_id(text: str) -> str:
    """--robot-id: letters, digits, '.', '_' and '-' (an id of spaces was stored as '   ' and matched no query)."""
    if not re.fullmatch(r"[A-Za-z0-9._-]{1,64}", text):
        raise argparse.ArgumentTypeError(
            f"{text!r}: a robot id is 1 to 64 letters, digits, '.', '_' or '-' (e.g. panda-2); leave the option "
            "out for the arm's name"
        )
    return text


def _add_self_confidence_options(p: argparse.ArgumentParser) -> None:
    """The self-confidence switch and the outcome store κ̂ is rebuilt from."""
    g = p.add_argument_group("self-confidence")
    g.add_argument(
        "--no-self-confidence", action="store_true", help="the paper's control condition: always act"
    )
    g.add_argument(
        "--experience",
        type=store_arg,
        metavar="DB|URL",
        help="outcome store κ̂ is rebuilt from at start: an SQLite file (any number of robots may share one), or "
        f"postgresql://user@host/db shared by a fleet (a server that does not answer within {PG_CONNECT_TIMEOUT_S} s "
        "is a one-line error before the robot acts)",
    )
    g.add_argument(
        "--learn-from",
        choices=("self", "same-model", "fleet"),
        help="whose stored outcomes rebuild κ̂ (with --experience): this robot's, every robot's with the same arm "
        "and --profile (both on this --robot engine only), or the whole fleet's on any engine "
        f"(default: {_EPISODE.learn_from})",
    )
    g.add_argument(
        "--robot-id",
        default=None,
        type=_robot_id,
        help="this robot's id in a shared store (with --experience): letters, digits, '.', '_', '-' (default: "
        "the arm's name)",
    )
    g.add_argument(
        "--profile", help="configuration label stored with each outcome (with --experience; default: none)"
    )


def _add_human_options(p: argparse.ArgumentParser) -> None:
    """The simulated human."""
    g = p.add_argument_group("simulated human")
    g.add_argument(
        "--takeover-probability",
        type=float,
        help="chance the simulated human takes over an action (not with --ui, where the person decides; default: "
        f"{_EPISODE.takeover_probability:g})",
    )


def _quiet_backends() -> None:
    from scone_bt.quiet import quiet_backends

    quiet_backends()


class _OneLineFormatter(logging.Formatter):
    """`scone-run: LEVEL: [library: ]message` on one line; a library's traceback becomes its last line only."""

    def format(self, record: logging.LogRecord) -> str:
        message = " ".join(record.getMessage().split())
        if record.exc_info and record.exc_info[1] is not None:
            exc = record.exc_info[1]
            message += f" ({type(exc).__name__}: {' '.join(str(exc).split())})"
        source = "" if record.name.startswith("scone_bt") else f"{record.name}: "
        return f"{_PROG}: {record.levelname.lower()}: {source}{message}"


class _StderrHandler(logging.StreamHandler):
    """Writes to whatever sys.stderr is at the time (pytest swaps it), one line per record."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)
        self.setFormatter(_OneLineFormatter())

    def emit(self, record: logging.LogRecord) -> None:
        self.stream = sys.stderr
        super().emit(record)


def configure_logging(level: str) -> None:
    """Route scone-run's and the libraries' Python log lines to stderr at `level`; set rerun's Rust log level.

    Called before rerun is imported (RUST_LOG is read then); a RUST_LOG the user set is kept.
    """
    root = logging.getLogger()
    for handler in [h for h in root.handlers if isinstance(h, _StderrHandler)]:
        root.removeHandler(handler)
    root.addHandler(_StderrHandler())
    root.setLevel(level)
    for name in _LIBRARY_LOGGERS:
        logger = logging.getLogger(name)
        logger.setLevel(level)
        logger.handlers.clear()  # their own handlers would print a second, differently formatted copy
        logger.propagate = True
    os.environ.setdefault("RUST_LOG", _RUST_LOG[level])


def _check_flags_read(args: argparse.Namespace) -> None:
    """One meaning per flag: an option this run would not read is refused, naming what it needs. A default typed
    out is no other value (as argparsing.refuse_unread): ``--learn-from self`` stays harmless."""
    if args.experience is None:
        for flag, value in (("--robot-id", args.robot_id), ("--learn-from", args.learn_from)):
            if value not in (None, _EPISODE.learn_from):
                raise SconeError(
                    f"{flag} {value}: it only applies to an outcome store; give --experience DB|URL"
                )
        if args.profile:
            raise SconeError(
                f"--profile {args.profile}: it labels the outcomes stored; give --experience DB|URL"
            )
    if args.force and args.save is None:
        raise SconeError("--force: it lets --save replace a file, and no --save was given")
    if args.ui and args.takeover_probability not in (None, _EPISODE.takeover_probability):
        raise SconeError(
            f"--takeover-probability {args.takeover_probability:g}: with --ui the person on the tablet decides "
            "when to take over; leave it out"
        )


def _check_display(args: argparse.Namespace) -> None:
    """--gui and --viewer need a display: without one PyBullet's GUI connect fails without a word and the process
    exits 1, and the spawned rerun viewer dies while the recording waits 5 s for it, then blames --connect."""
    display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    if display or not sys.platform.startswith("linux"):
        return
    if args.gui and args.robot == "sim":
        raise SconeError(
            "--gui: no display to open PyBullet's window on (DISPLAY is not set); run without --gui and watch it "
            "with --viewer, or record it with --save"
        )
    if args.viewer:
        raise SconeError(
            "--viewer: no display to open rerun's viewer on (neither DISPLAY nor WAYLAND_DISPLAY is set); record "
            "with --save and open the file where there is a display, or stream with --connect to a viewer "
            "running elsewhere"
        )


def _experience(spec: str | None) -> Path | str | None:
    """A PostgreSQL URL stays a string; a URL of another scheme is refused; anything else is an SQLite file path
    (`experience.open.store_location`)."""
    from scone_bt.experience.open import store_location

    return None if spec is None else store_location(spec)


def _run_inputs(args: argparse.Namespace) -> dict[str, list[Path]]:
    """The files this run reads or keeps, by flag: what no output of the run may be written over.

    Names that do not resolve are left out here; their own loaders word the error.
    """
    from scone_bt.checks import sqlite_files
    from scone_bt.config.inputs import kitchen_inputs, robot_inputs
    from scone_bt.recipes.recipe import EXAMPLES_DIR, recipe_corpus_path
    from scone_bt.resources import resolve_file

    out: dict[str, list[Path]] = {}

    def resolved(kind: DataKind, name: str) -> Path | None:
        try:
            return resolve_file(kind, name, (".yaml", ".yml"))
        except SconeError:
            return None

    if isinstance(store := _experience(args.experience), Path):
        out["--experience"] = sqlite_files(store)
    kitchen = resolved("perception", args.kitchen)
    if kitchen is not None:  # with the product files it names
        out["--kitchen"] = kitchen_inputs(kitchen)
    recipe = str(args.recipe)
    if recipe.startswith("example:"):
        out["--recipe"] = [EXAMPLES_DIR / f"{recipe.removeprefix('example:')}.yaml"]
    elif Path(recipe).suffix in (".json", ".yaml", ".yml"):
        out["--recipe"] = [Path(recipe)]
    elif (corpus := recipe_corpus_path()) is not None:
        out["--recipe"] = [corpus]
    out["--catalogue"] = [Path(c) for c in args.catalogue]
    if (tree := resolved("trees", args.tree)) is not None:
        out["--tree"] = [tree]
    if (robot := resolved("robots", args.arm)) is not None:  # with its URDF and meshes
        out["--arm"] = robot_inputs(robot)
    return out


def _check_estimator(name: str, flag: str = "--estimator") -> None:
    """--estimator (or ``flag``) against the κ̂ registry (names only: nothing is built or fitted)."""
    import difflib

    from scone_bt.confidence.registry import CALIBRATED_ESTIMATORS, ESTIMATORS, GROUNDED_ESTIMATORS

    valid = (*ESTIMATORS, *GROUNDED_ESTIMATORS, *CALIBRATED_ESTIMATORS, "xgboost")
    if name in valid:
        return
    close = difflib.get_close_matches(name, valid, n=1, cutoff=0.6)
    base = [n for n in ESTIMATORS if not n.startswith("eps-")]
    # names outside the eps-/grounded-/-cal patterns (a registry may add some) are listed as they are
    others = [n for n in GROUNDED_ESTIMATORS if not n.startswith("grounded-")]
    raise SconeError(
        f"{flag} {name!r}: unknown estimator; valid: {', '.join(base + others)}, each of the first "
        f"{len(base)} also as eps-<name>, grounded-<name> (not conformal) or <name>-cal"
        + (f" (did you mean {close[0]}?)" if close else "")
    )


def _check_embedder(name: str) -> None:
    """--embedder against the embedder registry: a known name that is installed, or an existing directory."""
    from scone_bt.embedding.registry import EMBEDDER_NAMES, minilm_dir, mpnet_dir

    if name == "minilm":
        minilm_dir()  # one-line ModelUnavailableError if its package is missing
        return
    if name in ("mpnet", "mpnet-ft"):
        if mpnet_dir() is None:
            raise SconeError(
                f"--embedder {name}: MPNet is not assembled yet; run `scone-models install mpnet`"
            )
        return
    if name in EMBEDDER_NAMES:
        return
    folder = Path(name.removeprefix("finetuned:")).expanduser()
    if folder.is_dir():
        # What the loader reads, checked now rather than after the kitchen is built.
        from scone_bt.embedding.finetuned import HEAD_FILES, is_finetuned_dir
        from scone_bt.embedding.sentence import is_sentence_transformer_dir

        fine_tuned = is_finetuned_dir(folder)
        if name.startswith("finetuned:") and not fine_tuned:
            raise SconeError(
                f"--embedder {name!r}: not a fine-tuned embedder (needs {' and '.join(HEAD_FILES)}); save one "
                "with scone-bench if --save-finetuned DIR"
            )
        if not (fine_tuned or is_sentence_transformer_dir(folder)):
            raise SconeError(
                f"--embedder {name!r}: not a model directory (no modules.json or config.json, nor a fine-tuned "
                f"head); valid: {', '.join(EMBEDDER_NAMES)}, mpnet-ft, finetuned:<dir> or such a directory"
            )
        return
    what = "no such folder" if name.startswith("finetuned:") or os.sep in name else "unknown embedder"
    raise SconeError(
        f"--embedder {name!r}: {what}; valid: {', '.join(EMBEDDER_NAMES)}, mpnet-ft, finetuned:<dir> or a "
        "sentence-transformers model directory"
    )


def _check_input_files(args: argparse.Namespace) -> None:
    """The robot, kitchen and tree files and the extra catalogues: there, and files (not devices)."""
    from scone_bt.config.schema import MAX_FILE_BYTES, check_input_file
    from scone_bt.resources import resolve_file

    # a missing path is named as a file that is not there, not as an unknown robot/kitchen/tree name
    named: tuple[tuple[str, DataKind, str], ...] = (
        ("--arm", "robots", args.arm),
        ("--kitchen", "perception", args.kitchen),
        ("--tree", "trees", args.tree),
    )
    for flag, kind, name in named:
        resolve_file(kind, name, (".yaml", ".yml"), flag=flag)
    for catalogue in args.catalogue:  # a device or FIFO would hang the loader: refused by what it is, unread
        try:
            check_input_file(catalogue, limit=MAX_FILE_BYTES)
        except SconeError as exc:
            raise SconeError(f"--catalogue {exc}") from None


def _check_outputs(args: argparse.Namespace) -> None:
    """The recording, the experience store (or the fleet's server) and the viewer address."""
    from scone_bt import checks

    inputs = _run_inputs(args)
    if args.save is not None:
        # The run's inputs (naming their flag), then any YAML file, then another file (which --force may replace):
        # each message is then the one that holds even with --force.
        checks.check_output_file(args.save, "--save", kind="rrd", inputs=inputs, force=True)
        checks.check_not_yaml(
            args.save, "--save", "a rerun recording", ".rrd", ours=lambda p: checks.is_output_kind(p, "rrd")
        )
        checks.check_output_file(args.save, "--save", kind="rrd", inputs=inputs, force=args.force)
    if isinstance(_experience(args.experience), Path):  # a postgresql:// URL is checked when it is opened
        others = {flag: files for flag, files in inputs.items() if flag != "--experience"}
        checks.check_output_file(Path(args.experience), "--experience", inputs=others)
    elif args.experience is not None:  # probe the fleet's server now, not after the kitchen and models load
        from scone_bt.experience import open_store

        open_store(args.experience).close()
    if args.connect is not None:
        from scone_bt.viz.connect import check_viewer_address

        check_viewer_address(args.connect)


def _decision_settings(args: argparse.Namespace) -> dict[str, Any]:
    """The tree parameters given on the command line, checked: ranges, κ̂ and ζ names, and that this run reads
    each one (`check_flags_take_effect`, against the tree file's gate where the line names none)."""

    from scone_bt.config.tree_parameters import TreeParameters
    from scone_bt.tree import load_tree_spec

    tree = tree_overrides(args)  # the decision settings given, checked by the tree file's model
    if args.estimator is not None:
        _check_estimator(args.estimator)
    if args.embedder is not None:
        _check_embedder(args.embedder)
    spec = load_tree_spec(args.tree)  # validated now (types and ranges), before the kitchen is built
    gate = tree.get("gate") or spec.parameters.get("gate") or TreeParameters().gate
    probe = {**spec.parameters.get("probe", {}), **tree.get("probe", {})}
    enabled = probe.get("enabled", TreeParameters().probe.enabled)
    check_flags_take_effect(tree, gate, self_confidence=not args.no_self_confidence, probe_enabled=enabled)
    return tree


def options_from_args(args: argparse.Namespace):  # -> EpisodeOptions
    from scone_bt import checks
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.episode import EpisodeOptions
    from scone_bt.human import HumanOptions

    # Every value is checked here, before the kitchen is built or a model is loaded.
    check_backend(args.robot)  # before anything else: a robot file given to --robot says to use --arm
    checks.check_seed(args.seed)
    checks.check_positive_int(args.max_ticks, "--max-ticks")
    if args.distractors < 0:
        raise SconeError(f"--distractors {args.distractors}: must be 0 or more")
    _check_flags_read(args)
    takeover = (
        _EPISODE.takeover_probability if args.takeover_probability is None else args.takeover_probability
    )
    checks.check_range(takeover, "--takeover-probability", 0.0, 1.0)
    _check_input_files(args)
    tree = _decision_settings(args)
    _check_outputs(args)
    _check_display(args)
    # Options not given on the command line come from the tree file's parameters (one source of defaults).
    behaviour = BehaviourOptions(
        **tree,
        use_self_confidence=not args.no_self_confidence,
        experience_path=_experience(args.experience),
        robot_id=args.robot_id or "",  # "": the arm's name (BehaviourOptions)
        learn_from=args.learn_from or _EPISODE.learn_from,
        profile=args.profile or "",  # "": no label (BehaviourOptions)
        seed=args.seed,
    )
    return EpisodeOptions(
        arm=args.arm,
        kitchen=args.kitchen,
        catalogues=tuple(args.catalogue),
        tree=args.tree,
        recipe=args.recipe,
        seed=args.seed,
        max_ticks=args.max_ticks,
        distractors=args.distractors,
        behaviour=behaviour,
        human=HumanOptions(takeover_probability=takeover),
        save=args.save,
        viewer=args.viewer,
        connect=args.connect,
        gui=args.gui,
        backend=args.robot,
    )


def viewer_command(recording: Path) -> str:
    """A command that opens `recording` from a fresh shell (where this venv is not activated).

    The venv's own `rerun` is preferred (its version matches the recording's), shown relative to the current
    folder when it lies under it; `rerun` from PATH otherwise.
    """
    beside = Path(sys.executable).parent / "rerun"  # not resolved: a venv's python is a symlink out of it
    if beside.is_file():
        exe = beside.absolute()
        try:
            shown = str(exe.relative_to(Path.cwd()))
        except ValueError:
            shown = str(exe)
        if os.sep not in shown:
            shown = f".{os.sep}{shown}"
    else:
        shown = "rerun"  # from PATH (a system-wide install)
    return f"{shlex.quote(shown)} {shlex.quote(str(recording))}"


def _interrupted_line(args: argparse.Namespace | None) -> str:
    """What an interrupt leaves: nothing (no store), or how many outcomes of this run the store holds; and where
    the recording so far is (with --save)."""
    return _stored_clause(args) + _recording_clause(args)


def _recording_clause(args: argparse.Namespace | None) -> str:
    """With --save: where the recording of the interrupted run went (`Recorder.close(complete=False)`: to the
    path, or beside a recording already there), or that none was begun."""
    save = getattr(args, "save", None) if args is not None else None
    if save is None:
        return ""
    from scone_bt.viz.save import unfinished_path

    for path in (unfinished_path(save), save):
        try:
            written = path.stat().st_mtime >= _STARTED_AT
        except OSError:
            continue
        if written:
            kept = f" ({save}, the recording before it, is untouched)" if path != save else ""
            return f"; the recording so far is in {path}{kept}"
    return "; no recording was begun"


_STARTED_AT = time.time()
"""When this process started (a recording newer than this is this run's)."""


def _stored_clause(args: argparse.Namespace | None) -> str:
    spec = getattr(args, "experience", None) if args is not None else None
    if spec is None:
        return f"{_PROG}: interrupted; nothing was stored (no --experience store)"
    try:
        from scone_bt.experience import attempted_outcome_ids, count_stored, is_postgres_url, redact_url

        location = redact_url(spec) if is_postgres_url(spec) else str(Path(spec))
        n = count_stored(spec, attempted_outcome_ids(location))
    except Exception:  # noqa: BLE001 - the line must come out whatever state the interrupt left
        location, n = str(spec), None
    if n is None:
        return f"{_PROG}: interrupted; outcomes stored before the interrupt are in {location} (it could not be counted)"
    return f"{_PROG}: interrupted; {n} outcome{'' if n == 1 else 's'} of this run {'is' if n == 1 else 'are'} in {location}"


def main(argv: list[str] | None = None) -> int:
    """Entry point of scone-run: 0 done, 1 stopped early, 2 bad input, 3 program error, 130 interrupted."""
    _INTERRUPTS.install()  # first: a Ctrl-C during the imports below is reported, not a traceback
    _INTERRUPTS.phase = _Interrupts.RUNNING
    parsed: list[argparse.Namespace] = []  # filled as soon as the arguments are parsed (the store's name)
    try:
        code = _run(argv, parsed)
        _INTERRUPTS.check()  # a Ctrl-C whose KeyboardInterrupt something swallowed: still an interrupt
        return code
    except KeyboardInterrupt:
        sys.unraisablehook = lambda _unraisable: None  # half-built objects' __del__ noise is not for the user
        line = _interrupted_line(parsed[0] if parsed else None)
        if not _IS_PROGRAM:
            _write_line(line)
            return 130
        # The episode has unwound (store closed, recording flushed): the line is the last word. Skipping the
        # interpreter's shutdown keeps it so: no exit handler or thread can print after it or hang.
        _INTERRUPTS.phase = _Interrupts.REPORTED
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        _write_line(line)
        os._exit(130)
    finally:
        _INTERRUPTS.phase = _Interrupts.REPORTED
        if not _IS_PROGRAM:  # called from Python (tests): Ctrl-C is the caller's again
            _INTERRUPTS.pending = False
            _INTERRUPTS.restore()


def _checked(on_event: Callable[[Any], None] | None) -> Callable[[Any], None]:
    """The episode's event callback, first raising a Ctrl-C that something swallowed (`_Interrupts.check`)."""

    def seen(event: Any) -> None:
        _INTERRUPTS.check()
        if on_event is not None:
            on_event(event)

    return seen


def _run(argv: list[str] | None, parsed: list[argparse.Namespace]) -> int:
    args = build_parser().parse_args(argv)
    parsed.append(args)
    configure_logging(args.log_level)
    try:
        _quiet_backends()
        from scone_bt.episode import run_episode
        from scone_bt.instruction_following import embedder as _mpnet_ft  # noqa: F401 (registers mpnet-ft)
        from scone_bt.study.ui import tablet_from_args

        options = options_from_args(args)
        if args.save is not None:
            args.save.parent.mkdir(parents=True, exist_ok=True)
        server = tablet_from_args(args)  # None without --ui
        try:
            if server is not None:
                print(f"tablet: {server.url}")
            summary = run_episode(
                options,
                printer=(lambda _line: None) if args.quiet else print,
                on_event=_checked(server.on_event if server is not None else None),
                human_factory=server.human_factory if server is not None else None,
                realtime=server is not None,
            )
        finally:
            if server is not None:
                server.close()
    except SconeError as exc:
        print(f"{_PROG}: error: {exc}", file=sys.stderr)
        return 2
    except (
        Exception
    ) as exc:  # a bug, not an outcome: stop with its message (SCONE_BT_DEBUG=1 shows the traceback)
        if os.environ.get("SCONE_BT_DEBUG"):
            raise
        print(f"{_PROG}: internal error: {internal_error_line(exc)}", file=sys.stderr)
        return 3
    print(summary.format())
    if args.save is not None:
        print(f"recording: {args.save}  (open with: {viewer_command(args.save)})")
    return 0 if summary.completed else 1


if __name__ == "__main__":
    sys.exit(main())
