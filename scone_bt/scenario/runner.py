"""The scenario runner: cases loaded on one backend, selected, run in worker processes, counted.

`scone-scenario run` and `scone-bench scenarios` are thin layers over it (arguments in, their report out). So is
the pytest plugin (`pytest scenarios/`): it loads each file with `load_cases`, runs each item with `run_one` into
`default_out_dir`, and turns the case's `Verdict` into pytest's outcome; pytest and pytest-xdist give it their own
selection, workers and JUnit report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import SconeError
from scone_bt.scenario.model import Case
from scone_bt.scenario.run import CaseResult, Verdict, run_case

__all__ = [
    "Selection",
    "Tally",
    "WORKER_DIED",
    "check_jobs",
    "check_outputs",
    "default_out_dir",
    "load_cases",
    "lost_case",
    "lost_names",
    "run_cases",
    "run_one",
    "shared_models",
]


def load_cases(paths: Sequence[Path | str], robot: str | None, arm: str | None = None) -> list[Case]:
    """Every case of the scenario files (or folders of them) `paths`, on the backend `robot` with the robot file
    `arm` (None: each file's)."""
    from scone_bt.scenario import model  # through the module: a test may stand in for the loader

    return [model.on_backend(c, robot, arm) for c in model.load_scenarios(paths)]


def default_out_dir(out: Path | None, junit: Path | None) -> Path:
    """Where failing cases' event logs and recordings go: `out`, else beside the JUnit report, else
    runs/scenarios."""
    if out is not None:
        return out
    return junit.parent if junit is not None else Path("runs/scenarios")


def check_outputs(cases: Sequence[Case], out_dir: Path, force: bool = False) -> None:
    """Before any case runs: the files a failing case would write in `out_dir` (`case_outputs`) replace nothing
    but an earlier event log or recording (unless `force`), and the folder is writable; one line naming the
    file otherwise."""
    from scone_bt.checks import OutputKind, check_output_dir, check_output_file, is_output_kind
    from scone_bt.scenario.run import case_outputs

    check_output_dir(out_dir, "--out")
    for case in cases:
        log, rrd = case_outputs(case.name, out_dir)
        outputs: tuple[tuple[Path, OutputKind, str], ...] = (
            (log, "json", "an event log"),
            (rrd, "rrd", "a rerun recording"),
        )
        for path, kind, what in outputs:
            if not force and path.is_file() and not is_output_kind(path, kind):
                raise SconeError(
                    f"--out {out_dir}: {path.name} exists and is not {what}; case {case.name!r} writes there if "
                    "it fails (give another --out folder, or --force to replace it)"
                )
            check_output_file(path, "--out", force=True)  # a folder or device there, a read-only file


def check_jobs(jobs: int) -> int:
    """`jobs`, refused (one line) below 1."""
    if jobs < 1:
        raise SconeError(f"--jobs {jobs}: give 1 or more")
    return jobs


@dataclass(frozen=True)
class Selection:
    """Which cases run: those whose name contains `name`, tagged with any of `tags` (none: all), and with none of
    `skip_tags`."""

    name: str | None = None
    tags: tuple[str, ...] = ()
    skip_tags: tuple[str, ...] = ()

    def apply(self, cases: Sequence[Case]) -> list[Case]:
        """The selected cases, in order; refused (one line) when a filter leaves none."""
        chosen = list(cases)
        if self.name:
            chosen = [c for c in chosen if self.name in c.name]
            if not chosen:
                raise SconeError(f"-k {self.name!r}: no case name contains it")
        if self.tags:
            chosen = [c for c in chosen if set(c.spec.tags) & set(self.tags)]
        if self.skip_tags:
            chosen = [c for c in chosen if not set(c.spec.tags) & set(self.skip_tags)]
        if not chosen:
            known = sorted({t for c in cases for t in c.spec.tags})
            raise SconeError(
                f"no case left after --tag/--skip-tag; the cases' tags: {', '.join(known) or '(none)'}"
            )
        return chosen


@dataclass(frozen=True)
class Tally:
    """How many cases got each verdict."""

    passed: int
    xfail: int
    failed: int
    xpass: int
    error: int

    @classmethod
    def of(cls, results: Sequence[CaseResult]) -> Tally:
        """The tally of `results`."""
        return cls(*(sum(r.verdict == v for r in results) for v in _ORDER))

    @property
    def total(self) -> int:
        """Every case counted."""
        return self.passed + self.xfail + self.failed + self.xpass + self.error

    @property
    def not_ok(self) -> int:
        """Cases that count as failing: failed, passed unexpectedly, or errors."""
        return self.failed + self.xpass + self.error

    def line(self, wall_s: float) -> str:
        """The summary's last line."""
        return (
            f"{self.total} cases: {self.passed} passed, {self.xfail} failed as expected, "
            f"{self.failed} failed, {self.xpass} passed unexpectedly, {self.error} errors in {wall_s:.1f} s wall"
        )


_ORDER = (Verdict.PASSED, Verdict.XFAIL, Verdict.FAILED, Verdict.XPASS, Verdict.ERROR)

_MODELS: Any = None


def shared_models() -> Any:
    """This process's `ModelPool`: the embedder loads once per process, not once per case."""
    global _MODELS
    if _MODELS is None:
        from scone_bt.episode.resources import ModelPool

        _MODELS = ModelPool()
    return _MODELS


def run_one(
    case: Case, out_dir: Path | None, record_failures: bool = True, force: bool = False
) -> CaseResult:
    """Run one case in this process (`scone_bt.scenario.run.run_case` with this process's models; ``force``:
    a failing case's outputs replace files of another kind in ``out_dir``)."""
    return run_case(case, out_dir, shared_models(), record_failures, force)


def run_cases(
    cases: Sequence[Case],
    jobs: int = 1,
    out_dir: Path | None = None,
    on_result: Callable[[CaseResult], None] | None = None,
    force: bool = False,
) -> list[CaseResult]:
    """Run cases, ``jobs`` at a time in worker processes (each loads the embedder once); results in case order.

    `on_result` sees each result as it comes. A worker process that dies loses only the cases it had not finished:
    each is an error (`WORKER_DIED`).
    """
    if jobs <= 1 or len(cases) <= 1:
        results = []
        for case in cases:
            results.append(run_one(case, out_dir, force=force))
            if on_result is not None:
                on_result(results[-1])
        return results
    return _in_workers(cases, jobs, out_dir, on_result, force)


def _in_workers(
    cases: Sequence[Case],
    jobs: int,
    out_dir: Path | None,
    on_result: Callable[[CaseResult], None] | None,
    force: bool = False,
) -> list[CaseResult]:
    import concurrent.futures as cf
    from concurrent.futures.process import BrokenProcessPool

    from scone_bt.distributed.pool import abort_pool, spawn_pool

    results: dict[int, CaseResult] = {}
    pool = spawn_pool(jobs)  # workers ignore Ctrl-C; here it stops them at once, not after every case
    try:
        futures: dict[cf.Future[CaseResult], int] = {}
        try:
            for i, case in enumerate(cases):
                futures[pool.submit(_worker_run, case, out_dir, force)] = i
        except BrokenProcessPool:
            pass  # a worker died already: the cases not submitted are reported lost below
        for fut in cf.as_completed(futures):
            i = futures[fut]
            try:
                results[i] = fut.result()
            except BrokenProcessPool:
                # one killed worker (kill -9, the out-of-memory killer) breaks the whole pool: the cases
                # that finished keep their results, every other one is an error, not a lost run
                results[i] = lost_case(cases[i])
            if on_result is not None:
                on_result(results[i])
    except BaseException:
        abort_pool(pool)
        raise
    pool.shutdown(wait=True)
    for i, case in enumerate(cases):
        if i not in results:
            results[i] = lost_case(case)
            if on_result is not None:
                on_result(results[i])
    return [results[i] for i in range(len(cases))]


WORKER_DIED = (
    "a worker process died (killed, e.g. by kill -9 or the out-of-memory killer) before this case finished; "
    "it did not run to the end: run it again, with fewer --jobs if memory is short"
)
"""The reason of a case lost with its worker process."""


def lost_case(case: Case) -> CaseResult:
    """The error result of a case whose worker process died before it finished."""
    return CaseResult(case.name, str(case.path), Verdict.ERROR, WORKER_DIED)


def lost_names(results: Sequence[CaseResult]) -> list[str]:
    """The names of the cases lost with their worker process."""
    return [r.name for r in results if r.verdict == Verdict.ERROR and r.reason == WORKER_DIED]


def _worker_run(case: Case, out_dir: Path | None, force: bool = False) -> CaseResult:
    return run_one(case, out_dir, force=force)
