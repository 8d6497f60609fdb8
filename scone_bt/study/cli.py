"""scone-study: run a trust study with the tablet, simulate one, analyse it, export it.

Examples:
    scone-study session --db runs/study.db --participant P01 --group A --session 1
    scone-study session --db runs/study.db --participant P01 --group A --session 1 --host 0.0.0.0 --token s3cr3t-tab
    scone-study simulate --participants 31 --fast --db runs/sim.db --analyze runs/sim-analysis
    scone-study simulate --participants 4 --db runs/sim-physics.db            # real PyBullet episodes (slow)
    scone-study analyze --db runs/study.db --out runs/analysis
    scone-study export --db runs/study.db --out runs/csv
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from scone_bt.errors import SconeError

__all__ = ["main", "build_parser"]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="scone-study",
        description="The trust study toolkit: tablet sessions with durable logging, simulated participants, and the paper's Bayesian analysis.",
        epilog="examples:" + __doc__.split("Examples:", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="{session,simulate,analyze,export}")

    s = sub.add_parser(
        "session",
        help="run one real study session with the tablet UI",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    s.add_argument("--db", type=Path, required=True, help="study log (SQLite); sessions are appended")
    s.add_argument("--participant", required=True, help="participant id, e.g. P01")
    s.add_argument(
        "--group", required=True, help="condition order: A (self-confidence on first) or B (off first)"
    )
    s.add_argument("--session", type=int, required=True, help="1 or 2; with --group it sets the condition")
    s.add_argument("--recipe", default="example:tomato-pasta", help="recipe id or file")
    s.add_argument("--arm", default="panda", help="arm model in robots/")
    s.add_argument("--seed", type=int, default=0, help="seeds object placement and the robot")
    s.add_argument("--distractors", type=int, default=6, help="objects not in the recipe on the shelf")
    s.add_argument("--max-ticks", type=int, default=12000, help="limit on 0.1 s control ticks")
    s.add_argument("--experience", type=Path, help="experience store κ̂ is rebuilt from")
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

    m = sub.add_parser(
        "simulate",
        help="run the whole study with simulated participants (output labelled SIMULATED)",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    m.add_argument("--participants", type=int, default=31, help="number of simulated participants")
    m.add_argument("--db", type=Path, required=True, help="new study log to write")
    m.add_argument(
        "--fast", action="store_true", help="synthetic episodes without physics (seconds instead of hours)"
    )
    m.add_argument("--seed", type=int, default=0)
    m.add_argument("--steps", type=int, default=5, help="recipe steps per synthetic episode (--fast)")
    m.add_argument("--recipe", default="example:hummus", help="recipe of physics episodes")
    m.add_argument("--distractors", type=int, default=2, help="distractors in physics episodes")
    m.add_argument(
        "--condition-effect",
        type=float,
        default=0.0,
        help="known shift (logit) of answers with self-confidence on",
    )
    m.add_argument(
        "--static-trust", action="store_true", help="trust ignores the episodes (for effect-recovery checks)"
    )
    m.add_argument("--analyze", type=Path, metavar="DIR", help="analyse the result into DIR afterwards")
    m.add_argument(
        "--jobs", type=int, default=1, help="participants simulated in parallel (processes, or Ray workers with --ray)"
    )
    from scone_bt.distributed import add_engine_arguments

    add_engine_arguments(m)

    a = sub.add_parser(
        "analyze",
        help="the paper's Bayesian analysis: Eq. (3) ordered logit, Eq. (4) Poisson",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    a.add_argument("--db", type=Path, required=True, help="study log")
    a.add_argument(
        "--out",
        type=Path,
        default=Path("runs/analysis"),
        help="folder for results.json, scores.csv, fig3.png",
    )
    for parser in (a, m):
        parser.add_argument("--chains", type=int, default=6, help="MCMC chains")
        parser.add_argument("--tune", type=int, default=500, help="warm-up draws per chain")
        parser.add_argument("--draws", type=int, default=500, help="kept draws per chain")
        parser.add_argument("--cores", type=int, help="processes for the chains (default: PyMC's choice)")
        parser.add_argument(
            "--rope",
            type=float,
            nargs=2,
            default=(-0.18, 0.18),
            metavar=("LOW", "HIGH"),
            help="region of practical equivalence",
        )
        parser.add_argument(
            "--models",
            default="mdmt,tps_hri,interventions",
            help="comma list of mdmt, tps_hri, trust (pooled), interventions",
        )

    e = sub.add_parser("export", help="write sessions, events, responses and scores as CSV")
    e.add_argument("--db", type=Path, required=True)
    e.add_argument("--out", type=Path, required=True)
    return p


def _quiet() -> None:
    from scone_bt.quiet import quiet_backends

    quiet_backends(("pymc", "pytensor", "uvicorn"))


def _open_log(path: Path, expect_existing: bool = True):  # -> StudyLog
    from scone_bt.study.log import StudyLog

    if expect_existing:
        if not path.is_file():
            raise SconeError(f"study log not found: {path}")
        return StudyLog(path, readonly=True)  # reading never changes the file (no WAL switch, no schema)
    return StudyLog(path, simulated=False)  # a SIMULATED log is refused, not mixed with real sessions


def _check_export_out(out: Path) -> None:
    """Export's folder: writable, and none of its CSV files there already (they are never overwritten)."""
    from scone_bt.cli.checks import check_output_dir
    from scone_bt.study.log import EXPORT_FILES

    check_output_dir(out, "--out")
    clash = [name for name in EXPORT_FILES if (out / name).exists()]
    if clash:
        raise SconeError(
            f"--out {out}: {', '.join(clash)} exist already and are never overwritten; give a new folder"
        )


def _analysis_options(args: argparse.Namespace):  # -> AnalysisOptions
    from scone_bt.study.analysis import AnalysisOptions

    models = tuple(x.strip() for x in args.models.split(",") if x.strip())
    return AnalysisOptions(
        chains=args.chains,
        tune=args.tune,
        draws=args.draws,
        cores=args.cores,
        rope=tuple(args.rope),
        models=models,
    )


def _analyze(log, args: argparse.Namespace, out: Path) -> None:  # noqa: ANN001
    from scone_bt.study.analysis import analyze, load_study, write_outputs

    options = _analysis_options(args)
    data = load_study(log)
    result = analyze(data, options, printer=print)
    print(result.format())
    paths = write_outputs(result, data, out)
    print(f"results: {paths['json']}  scores: {paths['scores']}  figure: {paths['figure']}")
    if log.simulated:
        print("NOTE: these results come from SIMULATED participants, not from people.")


def _session(args: argparse.Namespace) -> int:
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.cli import checks
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
    if isinstance(args.experience, Path):
        checks.check_output_file(args.experience, "--experience")
    load_robot(args.arm)
    load_recipe(args.recipe)
    options = EpisodeOptions(
        robot=args.arm,
        recipe=args.recipe,
        seed=args.seed,
        max_ticks=args.max_ticks,
        distractors=args.distractors,
        behaviour=BehaviourOptions(experience_path=args.experience, seed=args.seed),
    )
    log = _open_log(args.db, expect_existing=False)
    if log.simulated:
        raise SconeError(f"{args.db} holds SIMULATED data; record real sessions in another file")
    server = serve_tablet(args.host, args.port, args.token)
    try:
        sid, summary = run_study_session(log, plan, options, server, questionnaires=not args.no_questionnaire)
    finally:
        server.close()
        log.close()
    print(summary.format())
    print(f"session {sid} stored in {args.db}")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.synthetic import SyntheticOptions
    from scone_bt.study.trust import TrustParameters

    trust = TrustParameters(condition_effect=args.condition_effect)
    if args.static_trust:
        trust = TrustParameters(
            success_gain=0.0, failure_loss=0.0, help_gain=0.0, condition_effect=args.condition_effect
        )
    if args.analyze is not None:
        _analysis_options(args)  # fail early on bad analysis settings
    options = SimulationOptions(
        participants=args.participants,
        seed=args.seed,
        fast=args.fast,
        trust=trust,
        synthetic=SyntheticOptions(steps=args.steps),
        recipe=args.recipe,
        distractors=args.distractors,
    )
    from scone_bt.distributed import engine_from_args

    engine = engine_from_args(args, args.jobs) if args.ray or args.jobs > 1 else None
    log = simulate_study(args.db, options, engine=engine)  # the same log on any engine and worker count
    print(f"SIMULATED study written to {args.db}")
    if args.analyze is not None:
        _analyze(log, args, args.analyze)
    log.close()
    return 0


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    _quiet()
    try:
        if args.command == "session":
            return _session(args)
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "export":
            _check_export_out(args.out)
        log = _open_log(args.db)
        try:
            if args.command == "analyze":
                _analyze(log, args, args.out)
            else:
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
