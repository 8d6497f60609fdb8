"""scone-study: run a trust study with the tablet, simulate one, analyse it, export it.

Examples:
    scone-study session --db runs/study.db --participant P01 --group A --session 1
    scone-study session --db runs/study.db --participant P01 --group A --session 1 --host 0.0.0.0 --token s3cr3t-tab
    scone-study simulate --participants 31 --fast --db runs/sim.db --analyze runs/sim-analysis
    scone-study simulate --participants 4 --db runs/sim-physics.db            # real PyBullet episodes (slow)
    scone-study analyze --db runs/study.db --out runs/analysis
    scone-study analyze --ratings ratings.csv --sessions sessions.csv --out runs/lab-analysis
    scone-study power --n 10,20,31,50 --repetitions 20 --effect 1.0 --out runs/power
    scone-study export --db runs/study.db --out runs/csv
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from scone_bt.argparsing import DefaultsHelpFormatter, OneLineArgumentParser, path_arg, store_arg
from scone_bt.defaults import EPISODE
from scone_bt.errors import SconeError
from scone_bt.robot.flags import add_robot_options, check_backend

if TYPE_CHECKING:
    from scone_bt.study.memory import MemoryProbe

__all__ = ["main", "build_parser"]


def build_parser() -> argparse.ArgumentParser:
    """`scone-study`'s parser: one sub-command each, declared in its own function."""
    p = OneLineArgumentParser(
        prog="scone-study",
        description="The trust study toolkit: tablet sessions with durable logging, simulated participants, and the paper's Bayesian analysis.",
        epilog="examples:" + __doc__.split("Examples:", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="{session,simulate,analyze,power,export}")
    _add_session_parser(sub)
    m = _add_simulate_parser(sub)
    a = _add_analyze_parser(sub)
    _add_power_parser(sub)
    for parser in (a, m):
        _add_analysis_options(parser)
    e = sub.add_parser("export", help="write sessions, events, responses and scores as CSV")
    e.add_argument("--db", type=path_arg, required=True)
    e.add_argument("--out", type=path_arg, required=True)
    return p


def _add_session_parser(sub: argparse._SubParsersAction) -> None:
    """`session`: one real study session with the tablet UI."""
    s = sub.add_parser(
        "session",
        help="run one real study session with the tablet UI",
        formatter_class=DefaultsHelpFormatter,
    )
    s.add_argument("--db", type=path_arg, required=True, help="study log (SQLite); sessions are appended")
    s.add_argument("--participant", required=True, help="participant id, e.g. P01")
    s.add_argument(
        "--group", required=True, help="condition order: A (self-confidence on first) or B (off first)"
    )
    s.add_argument("--session", type=int, required=True, help="1 or 2; with --group it sets the condition")
    s.add_argument("--recipe", default=EPISODE.recipe, help="recipe id or file")
    add_robot_options(s, arm_default=EPISODE.arm)
    s.add_argument("--seed", type=int, default=EPISODE.seed, help="seeds object placement and the robot")
    s.add_argument(
        "--distractors", type=int, default=EPISODE.distractors, help="objects not in the recipe on the shelf"
    )
    s.add_argument("--max-ticks", type=int, default=12000, help="limit on 0.1 s control ticks")
    s.add_argument(
        "--experience",
        type=store_arg,
        help="experience store κ̂ is rebuilt from: an SQLite file, or postgresql://… for a fleet's shared store",
    )
    s.add_argument(
        "--host",
        default="127.0.0.1",
        help="address the tablet UI binds to; anything but localhost needs --token",
    )
    s.add_argument("--port", type=int, default=8765, help="tablet UI port")
    s.add_argument("--token", help="session token the tablet must present (required off localhost)")
    s.add_argument(
        "--no-questionnaire", action="store_true", help="skip the questionnaires after the episode"
    )
    s.add_argument(
        "--autostart",
        action="store_true",
        help="start the episode at once instead of waiting for Start on the tablet or the researcher's page",
    )
    s.add_argument(
        "--show-trust",
        action="store_true",
        help="show the person's estimated trust on the participant's tablet from the start (default: hidden; "
        "the researcher's page always shows it and has a switch for the participant's view)",
    )


def _add_simulate_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """`simulate`: the whole study with simulated participants (its analysis options added by the caller)."""
    m = sub.add_parser(
        "simulate",
        help="run the whole study with simulated participants (output labelled SIMULATED)",
        formatter_class=DefaultsHelpFormatter,
    )
    m.add_argument("--participants", type=int, default=31, help="number of simulated participants")
    m.add_argument("--db", type=path_arg, required=True, help="new study log to write")
    m.add_argument(
        "--fast", action="store_true", help="synthetic episodes without physics (seconds instead of minutes)"
    )
    m.add_argument("--seed", type=int, default=0)
    m.add_argument("--steps", type=int, default=5, help="recipe steps per synthetic episode (--fast)")
    m.add_argument("--recipe", default="example:hummus", help="recipe of physics episodes")
    m.add_argument("--distractors", type=int, default=2, help="distractors in physics episodes")
    add_robot_options(m, arm_help="robot file of physics episodes: a name in robots/ or a YAML path")
    m.add_argument(
        "--condition-effect",
        type=float,
        default=0.0,
        help="known shift (logit) of answers with self-confidence on",
    )
    m.add_argument(
        "--static-trust", action="store_true", help="trust ignores the episodes (for effect-recovery checks)"
    )
    _add_trust_params(m)
    m.add_argument("--analyze", type=path_arg, metavar="DIR", help="analyse the result into DIR afterwards")
    m.add_argument(
        "--memory",
        type=path_arg,
        metavar="FILE",
        help="write the process's memory, descriptors and threads after each participant to FILE (JSON; one "
        "process: not with --jobs or --ray)",
    )
    m.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="participants simulated in parallel (processes, or Ray workers with --ray)",
    )
    from scone_bt.distributed import add_engine_arguments

    add_engine_arguments(m)
    return m


def _add_analyze_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """`analyze`: the study log or the ratings CSV in (its analysis options added by the caller)."""
    a = sub.add_parser(
        "analyze",
        help="the paper's Bayesian analysis: Eq. (3) ordered logit, Eq. (4) Poisson",
        formatter_class=DefaultsHelpFormatter,
    )
    source = a.add_mutually_exclusive_group(required=True)
    source.add_argument("--db", type=path_arg, help="study log")
    source.add_argument(
        "--ratings",
        type=path_arg,
        help="ratings CSV: participant, condition (on/off), session (1/2), group (A/B), question, rating, "
        "categories[, questionnaire]",
    )
    a.add_argument(
        "--sessions",
        type=path_arg,
        help="with --ratings: sessions CSV (participant, condition, session, group, interventions)",
    )
    a.add_argument(
        "--columns", help="with --ratings: the files' column names, e.g. participant=subject,rating=answer"
    )
    a.add_argument(
        "--out",
        type=path_arg,
        default=Path("runs/analysis"),
        help="folder for results.json, scores.csv, fig3.png, fig3.pdf",
    )
    a.add_argument("--force", action="store_true", help="overwrite earlier results in --out")
    return a


def _add_analysis_options(parser: argparse.ArgumentParser) -> None:
    """The model, its priors and the sampler; the defaults are `AnalysisOptions`' (the paper's)."""
    from scone_bt.study.analysis import AnalysisOptions
    from scone_bt.study.models import SPECIFICATIONS

    defaults = AnalysisOptions  # its fields' defaults
    parser.add_argument(
        "--model",
        choices=SPECIFICATIONS,
        default=defaults.specification,
        help="paper: Eq. (3)/(4) as published; extended: adds group A/B, single-difference coding",
    )
    parser.add_argument(
        "--effect-prior-sd", type=float, help="prior sd of the effects (unset: the model's, 1)"
    )
    parser.add_argument(
        "--cutpoint-prior-sd",
        type=float,
        help="prior sd of the cut-points (unset: the model's; paper 1, extended 1.5)",
    )
    parser.add_argument(
        "--scale-prior-sd",
        type=float,
        help="scale of the participant/question sd priors (unset: the model's, 1)",
    )
    parser.add_argument("--chains", type=int, default=defaults.chains, help="MCMC chains")
    parser.add_argument("--tune", type=int, default=defaults.tune, help="warm-up draws per chain")
    parser.add_argument("--draws", type=int, default=defaults.draws, help="kept draws per chain")
    parser.add_argument("--cores", type=int, help="processes for the chains (default: PyMC's choice)")
    parser.add_argument(
        "--rope",
        type=float,
        nargs=2,
        default=defaults.rope,
        metavar=("LOW", "HIGH"),
        help="region of practical equivalence",
    )
    parser.add_argument(
        "--models",
        help="comma list of questionnaires (mdmt, tps_hri, ...), trust (pooled), interventions "
        "(default: every questionnaire, and interventions where known)",
    )


def _quiet() -> None:
    from scone_bt.quiet import quiet_backends

    quiet_backends(("pymc", "pytensor", "uvicorn"))


def _open_log(path: Path, expect_existing: bool = True):  # -> StudyLog
    from scone_bt.study.log import StudyLog

    if expect_existing:
        if path.is_dir():
            raise SconeError(f"--db {path}: is a folder; give a file path")
        if not path.is_file():
            raise SconeError(f"study log not found: {path}")
        return StudyLog(path, readonly=True)  # reading never changes the file (no WAL switch, no schema)
    return StudyLog(path, simulated=False)  # a SIMULATED log is refused, not mixed with real sessions


def _check_export_out(out: Path) -> None:
    """Export's folder: writable, and none of its CSV files there already (they are never overwritten)."""
    from scone_bt.checks import check_output_dir
    from scone_bt.study.log import EXPORT_FILES

    check_output_dir(out, "--out")
    clash = [name for name in EXPORT_FILES if (out / name).exists()]
    if clash:
        raise SconeError(
            f"--out {out}: {', '.join(clash)} {'exists' if len(clash) == 1 else 'exist'} already and {'is' if len(clash) == 1 else 'are'} never overwritten; give a new folder"
        )


def _analysis_options(
    args: argparse.Namespace, available: tuple[str, ...] | None = None
):  # -> AnalysisOptions
    from scone_bt.checks import comma_list
    from scone_bt.study.analysis import MODELS, AnalysisOptions, check_models
    from scone_bt.study.models import Priors

    models = None
    if args.models is not None:
        models = comma_list(args.models, "--models", "mdmt,trust")
        check_models(models, available if available is not None else MODELS, "--models")
    defaults = Priors.defaults(args.model)
    priors = Priors(
        effect_sd=defaults.effect_sd if args.effect_prior_sd is None else args.effect_prior_sd,
        cutpoint_sd=defaults.cutpoint_sd if args.cutpoint_prior_sd is None else args.cutpoint_prior_sd,
        scale_sd=defaults.scale_sd if args.scale_prior_sd is None else args.scale_prior_sd,
    )
    return AnalysisOptions(
        specification=args.model,
        priors=priors,
        chains=args.chains,
        tune=args.tune,
        draws=args.draws,
        cores=args.cores,
        rope=tuple(args.rope),
        models=models,
    )


MAX_SIMULATED_PARTICIPANTS = 100_000
"""Most participants `simulate` accepts: every one is held in memory until the log is written."""


def _check_analysis_out(
    out: Path, flag: str, force: bool, inputs: dict[str, list[Path]] | None = None
) -> None:
    """The analysis' output folder, before any sampling: writable (a file is made there and removed), none of its
    result files one of the run's `inputs` (never replaced, even with --force), earlier results kept unless
    `force`. Every message names `flag`."""
    from scone_bt.checks import check_output_dir, same_file
    from scone_bt.study.analysis import check_outputs, output_paths

    check_output_dir(out, flag)
    for path in output_paths(out).values():
        for other_flag, files in (inputs or {}).items():
            for other in files:
                if other.exists() and same_file(path, other):
                    raise SconeError(
                        f"{flag} {out}: its {path.name} would replace the {other_flag} input ({other}); "
                        f"inputs are never overwritten, give another {flag} folder"
                    )
    try:
        check_outputs(out, force)
    except SconeError as exc:
        if flag == "--out":
            raise
        raise SconeError(
            str(exc).replace("--out", flag).replace(" or pass --force to overwrite", "")
        ) from None


def _analysis_inputs(args: argparse.Namespace) -> dict[str, list[Path]]:
    """The files `analyze` reads, by flag (a study log with the files SQLite keeps beside it)."""
    from scone_bt.checks import sqlite_files

    inputs: dict[str, list[Path]] = {}
    if getattr(args, "db", None) is not None:
        inputs["--db"] = sqlite_files(args.db)
    for flag, dest in (("--ratings", "ratings"), ("--sessions", "sessions")):
        if getattr(args, dest, None) is not None:
            inputs[flag] = [Path(getattr(args, dest))]
    return inputs


def _analyze(data, args: argparse.Namespace, out: Path, force: bool = False) -> None:  # noqa: ANN001
    """Check options and output folder, then sample (the slow part), then write."""
    from scone_bt.study.analysis import analyze
    from scone_bt.study.outputs import write_outputs

    for note in getattr(data, "notes", ()):
        print(f"scone-study: warning: {note}", file=sys.stderr)
    options = _analysis_options(args, data.available_models())
    _check_analysis_out(
        out, "--out" if args.command == "analyze" else "--analyze", force, _analysis_inputs(args)
    )
    result = analyze(data, options, printer=print)
    print(result.format())
    paths = write_outputs(result, data, out, force=True)
    print(
        f"results: {paths['json']}  scores: {paths['scores']}  figure: {paths['figure']}, {paths['figure_pdf']}"
    )
    print(f"analysis time {result.seconds:.0f} s")
    if data.simulated:
        print("NOTE: these results come from SIMULATED participants, not from people.")


def _analyze_command(args: argparse.Namespace) -> int:
    from scone_bt.study.analysis import load_study
    from scone_bt.study.ratings_csv import load_ratings_csv, parse_column_map

    if args.ratings is None:
        if args.sessions is not None or args.columns:
            raise SconeError("--sessions and --columns go with --ratings (a study log has its own sessions)")
        log = _open_log(args.db)
        try:
            data = load_study(log)
        finally:
            log.close()
    else:
        data = load_ratings_csv(args.ratings, args.sessions, parse_column_map(args.columns))
    _analyze(data, args, args.out, args.force)
    return 0


def _add_power_parser(sub) -> None:  # noqa: ANN001 - argparse's private subparsers type
    """`power`: study planning by simulation; the defaults are `PowerOptions`'."""
    from scone_bt.distributed import add_engine_arguments
    from scone_bt.study.models import SPECIFICATIONS
    from scone_bt.study.power import PowerOptions

    d = PowerOptions  # its fields' defaults, read without building (and checking) options
    w = sub.add_parser(
        "power",
        help="study planning: P(HDI excludes the ROPE) against the number of participants, by simulation",
        formatter_class=DefaultsHelpFormatter,
    )
    n = ",".join(map(str, d.participants))
    w.add_argument("--n", default=n, help="comma list of participant numbers")
    w.add_argument(
        "--repetitions", type=int, default=d.repetitions, help="simulated studies per participant number"
    )
    w.add_argument(
        "--effect", type=float, default=d.effect, help="true condition effect (logit, or log-rate)"
    )
    w.add_argument(
        "--measure",
        default=d.measure,
        help="mdmt or tps_hri (simulated participants' answers) or interventions (Eq. 4 counts)",
    )
    w.add_argument("--model", choices=SPECIFICATIONS, default=d.specification, help="model fitted")
    w.add_argument("--rope", type=float, nargs=2, default=d.rope, metavar=("LOW", "HIGH"), help="ROPE")
    w.add_argument("--chains", type=int, default=d.chains, help="MCMC chains per analysis")
    w.add_argument("--tune", type=int, default=d.tune, help="warm-up draws per chain")
    w.add_argument("--draws", type=int, default=d.draws, help="kept draws per chain")
    w.add_argument(
        "--answer-noise-sd",
        type=float,
        default=d.response_noise_sd,
        help="per-session noise of the simulated answers, logit (0: answers drawn from Eq. 3)",
    )
    w.add_argument("--workers", type=int, help="processes (default: CPU count), or Ray workers with --ray")
    add_engine_arguments(w)
    w.add_argument("--seed", type=int, default=d.seed, help="seeds every simulated study and its sampler")
    _add_trust_params(w)
    w.add_argument(
        "--out", type=path_arg, default=Path("runs/power"), help="folder for power.json, power.png"
    )
    w.add_argument("--force", action="store_true", help="overwrite earlier results in --out")


def _add_trust_params(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--trust-params",
        choices=("fitted", "hand"),
        default="fitted",
        help="simulated participants' trust: fitted to human ratings (Soh et al., transfer across actions "
        "through ζ; help requests and take-overs assumed) or the hand-set model (docs/study.md)",
    )


def _power(args: argparse.Namespace) -> int:
    from scone_bt.study.power import PowerOptions, run_power, write_power

    options = PowerOptions.from_text(
        n=args.n,
        repetitions=args.repetitions,
        effect=args.effect,
        measure=args.measure,
        specification=args.model,
        rope=tuple(args.rope),
        chains=args.chains,
        tune=args.tune,
        draws=args.draws,
        workers=args.workers,
        seed=args.seed,
        ray=args.ray,
        response_noise_sd=args.answer_noise_sd,
        trust_params=args.trust_params,
    )
    from scone_bt.checks import check_output_dir, check_seed
    from scone_bt.study.power import check_power_outputs

    check_seed(args.seed)
    check_output_dir(args.out, "--out")
    check_power_outputs(args.out, args.force)
    result = run_power(options, printer=print)
    print(result.format())
    paths = write_power(result, args.out, force=True)
    print(f"results: {paths['json']}  plot: {paths['plot']}")
    print("NOTE: power comes from SIMULATED participants.")
    return 0


def _check_host(host: str, token: str | None) -> None:
    """`session`'s --host and --token, in this command's words (the tablet server names scone-run's --ui flags)."""
    from scone_bt.study.ui import _is_local
    from scone_bt.study.ui_args import MIN_TOKEN_LENGTH

    if token is not None and len(token) < MIN_TOKEN_LENGTH:
        raise SconeError(f"--token: must have at least {MIN_TOKEN_LENGTH} characters")
    if token is None and not _is_local(host):
        raise SconeError(
            f"--host {host}: makes the tablet UI reachable from the network and needs --token (at least "
            f"{MIN_TOKEN_LENGTH} characters); without one, use --host 127.0.0.1"
        )


_SYNTHETIC_ONLY = {"steps": "--steps"}
"""`simulate`'s options only the synthetic episodes (--fast) read."""
_PHYSICS_ONLY = {"recipe": "--recipe", "distractors": "--distractors", "robot": "--robot", "arm": "--arm"}
"""`simulate`'s options only the physics episodes (without --fast) read."""
_ANALYSIS_ONLY = {
    "model": "--model",
    "effect_prior_sd": "--effect-prior-sd",
    "cutpoint_prior_sd": "--cutpoint-prior-sd",
    "scale_prior_sd": "--scale-prior-sd",
    "chains": "--chains",
    "tune": "--tune",
    "draws": "--draws",
    "cores": "--cores",
    "rope": "--rope",
    "models": "--models",
}
"""`simulate`'s options only its analysis (--analyze) reads."""


def _check_simulate_flags_read(args: argparse.Namespace) -> None:
    """One meaning per flag: an option `simulate` would not read in this mode is refused, naming what reads it."""
    from scone_bt.argparsing import refuse_unread

    defaults = build_parser().parse_args(["simulate", "--db", "-"])
    if not args.fast:
        refuse_unread(args, defaults, _SYNTHETIC_ONLY, "only the synthetic episodes read it; give --fast")
    else:
        refuse_unread(
            args, defaults, _PHYSICS_ONLY, "only the physics episodes read it, and --fast runs synthetic ones"
        )
    if args.analyze is None:
        refuse_unread(args, defaults, _ANALYSIS_ONLY, "only the analysis reads it; give --analyze DIR")


def _check_simulate(args: argparse.Namespace) -> None:
    """`simulate`'s options, before any participant is simulated or file made: one line naming the flag."""
    from scone_bt import checks

    _check_simulate_flags_read(args)
    checks.check_seed(args.seed)
    if not 2 <= args.participants <= MAX_SIMULATED_PARTICIPANTS:
        raise SconeError(
            f"--participants {args.participants}: must be an integer in 2..{MAX_SIMULATED_PARTICIPANTS} "
            "(at least 2 participants: one per group)"
        )
    checks.check_positive_int(args.jobs, "--jobs", maximum=1024)
    checks.check_positive_int(args.steps, "--steps", maximum=1000)
    if args.distractors < 0:
        raise SconeError(f"--distractors {args.distractors}: must be 0 or more")
    checks.check_range(args.condition_effect, "--condition-effect", -10.0, 10.0)
    check_backend(args.robot)
    # a bad robot file or recipe is one line now, not after the first participant (with --fast, where the
    # synthetic episodes do not use them, only the defaults get here: another value was refused above)
    from scone_bt.config import load_robot
    from scone_bt.recipes import load_recipe

    for flag, load, value in (("--arm", load_robot, args.arm), ("--recipe", load_recipe, args.recipe)):
        try:
            load(value)
        except SconeError as exc:
            raise SconeError(f"{flag}: {exc}") from None
    checks.check_output_file(args.db, "--db", must_not_exist=True)
    _check_memory(args)


def _session(args: argparse.Namespace) -> int:
    from scone_bt import checks
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.config import load_robot
    from scone_bt.episode import EpisodeOptions
    from scone_bt.recipes import load_recipe
    from scone_bt.study.design import plan_session
    from scone_bt.study.session import run_study_session
    from scone_bt.study.ui import serve_tablet

    plan = plan_session(args.participant, args.group, args.session)
    # everything is checked before a session row exists: a configuration error is not a session
    checks.check_seed(args.seed)
    checks.check_port(args.port)
    checks.check_positive_int(args.max_ticks, "--max-ticks")
    if args.distractors < 0:
        raise SconeError(f"--distractors {args.distractors}: must be 0 or more")
    checks.check_output_file(args.db, "--db")
    _check_design(args.db, plan)
    _check_host(args.host, args.token)
    if args.experience is not None:
        from scone_bt.experience.open import store_location

        args.experience = store_location(args.experience)
    if isinstance(args.experience, Path):
        # The study log and the robot's store are two databases: one file cannot be both.
        checks.check_output_file(
            args.experience, "--experience", inputs={"--db": checks.sqlite_files(args.db)}
        )
        if args.experience.exists():  # a file of another kind is refused now, not after the session began
            from scone_bt.experience import open_store

            try:
                open_store(args.experience).close()
            except SconeError as exc:
                raise SconeError(f"--experience {exc}") from None
    check_backend(args.robot)
    load_robot(args.arm)
    load_recipe(args.recipe)
    options = EpisodeOptions(
        arm=args.arm,
        backend=args.robot,
        recipe=args.recipe,
        seed=args.seed,
        max_ticks=args.max_ticks,
        distractors=args.distractors,
        behaviour=BehaviourOptions(experience_path=args.experience, seed=args.seed),
    )
    log = _open_log(args.db, expect_existing=False)
    if log.simulated:
        raise SconeError(f"{args.db} holds SIMULATED data; record real sessions in another file")
    server = serve_tablet(
        args.host, args.port, args.token, start_gate=not args.autostart, trust_shown=args.show_trust
    )
    try:
        sid, summary = run_study_session(log, plan, options, server, questionnaires=not args.no_questionnaire)
    finally:
        server.close()
        log.close()
    print(summary.format())
    print(f"session {sid} stored in {args.db}")
    return 0


def _check_design(db: Path, plan) -> None:  # noqa: ANN001 - a SessionPlan
    """The session against the participant's earlier sessions in the study log (`check_next_session`), read
    without changing the file; a new log has none."""
    from scone_bt.study.design import check_next_session

    if not db.is_file():
        return
    log = _open_log(db)
    try:
        if log.simulated:
            raise SconeError(f"{db} holds SIMULATED data; record real sessions in another file")
        check_next_session(plan, log.sessions(), str(db))
    finally:
        log.close()


def _check_memory(args: argparse.Namespace) -> None:
    """``--memory FILE`` before any participant is simulated: one process, a writable path that is not the study
    log or an --analyze result, and no file there but an earlier memory report (replaced; anything else is kept:
    `simulate` overwrites none of its outputs' files of another kind)."""
    if args.memory is None:
        return
    if args.ray or args.jobs > 1:
        raise SconeError(
            "--memory: it samples this process, so the participants must run in it (no --jobs, --ray)"
        )
    from scone_bt.checks import check_output_file, same_file, sqlite_files
    from scone_bt.study.memory import is_memory_report

    path: Path = args.memory
    check_output_file(path, "--memory", inputs={"--db": sqlite_files(args.db)})
    if args.analyze is not None:
        from scone_bt.study.analysis import output_paths

        if any(same_file(path, other) for other in output_paths(args.analyze).values()):
            raise SconeError(
                f"--memory {path}: is a result file of --analyze {args.analyze}; give another path"
            )
    if path.exists() and not is_memory_report(path):
        raise SconeError(
            f"--memory {path}: exists and is not a memory report of scone-study simulate; it is not overwritten, "
            "give another path"
        )


def _memory_probe(args: argparse.Namespace) -> MemoryProbe | None:
    """With ``--memory`` (checked by `_check_memory`): the probe sampling this process after each participant,
    its folder made now so that no sample is lost to a missing one (None without it)."""
    if args.memory is None:
        return None
    from scone_bt.study.memory import MemoryProbe

    folder = args.memory.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SconeError(f"--memory {args.memory}: cannot create {folder} ({exc.strerror or exc})") from None
    settings = {"participants": args.participants, "mode": "fast" if args.fast else "physics"}
    settings |= {"recipe": args.recipe, "robot": args.robot, "arm": args.arm, "seed": args.seed}
    return MemoryProbe(args.memory, settings)


def _simulate(args: argparse.Namespace) -> int:
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.synthetic import SyntheticOptions
    from scone_bt.study.trust import trust_parameters

    _check_simulate(args)
    trust = trust_parameters(args.trust_params, condition_effect=args.condition_effect)
    if args.static_trust:
        trust = trust.static()
    if args.analyze is not None:
        _analysis_options(args)  # fail early on bad analysis settings
        _check_analysis_out(args.analyze, "--analyze", False, {"--db": [args.db]})
    options = SimulationOptions(
        participants=args.participants,
        seed=args.seed,
        fast=args.fast,
        trust=trust,
        synthetic=SyntheticOptions(steps=args.steps),
        recipe=args.recipe,
        distractors=args.distractors,
        robot=args.arm,
        backend=args.robot,
    )
    from scone_bt.distributed import engine_from_args

    engine = engine_from_args(args, args.jobs) if args.ray or args.jobs > 1 else None
    from scone_bt.checks import sqlite_files

    probe = _memory_probe(args)
    try:
        # the same log on any engine and worker count
        log = simulate_study(
            args.db, options, engine=engine, after_participant=probe.sample if probe is not None else None
        )
    except Exception:
        # A failed simulation stores nothing: the file it began (checked above not to exist) is removed, so the
        # same command can be run again.
        for path in sqlite_files(args.db):
            path.unlink(missing_ok=True)
        raise
    print(f"SIMULATED study written to {args.db}; {trust.label}")
    if probe is not None:
        from scone_bt.reporting import emit_report

        emit_report(probe.report(), args.memory)
    if args.analyze is not None:
        from scone_bt.study.analysis import load_study

        _analyze(load_study(log), args, args.analyze, force=True)  # the folder was checked before simulating
    log.close()
    return 0


def main(argv: list[str] | None = None) -> int:
    from scone_bt.signals import terminate_as_interrupt

    try:
        with terminate_as_interrupt():  # `kill` ends a command as Ctrl-C does: one line, never a traceback
            return _main(argv)
    except KeyboardInterrupt:  # before _main's own handler (parsing the arguments)
        print("scone-study: interrupted; nothing was recorded yet", file=sys.stderr)
        return 130


def _main(argv: list[str] | None) -> int:
    args = build_parser().parse_args(argv)
    _quiet()
    try:
        from scone_bt.extras import require

        require("study", "scone-study")
        if args.command == "session":
            return _session(args)
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "analyze":
            return _analyze_command(args)
        if args.command == "power":
            return _power(args)
        _check_export_out(args.out)
        log = _open_log(args.db)
        try:
            paths = log.export_csv(args.out)
            label = "SIMULATED data" if log.simulated else "real data"
            print(f"{label}: " + "  ".join(str(p) for p in paths.values()))
        finally:
            log.close()
    except SconeError as exc:
        print(f"scone-study: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("scone-study: interrupted; everything recorded so far is in the study log", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug, not data: one line (SCONE_BT_DEBUG=1 shows the traceback)
        import os

        if os.environ.get("SCONE_BT_DEBUG"):
            raise
        from scone_bt.checks import internal_error_line

        print(f"scone-study: internal error: {internal_error_line(exc)}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
