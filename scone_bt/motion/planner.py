"""Joint-space planning with OMPL (adapter): typed options in, a typed PlanResult out.

Determinism: OMPL draws every sampler's seed from one process-wide generator; it is reseeded from
`PlannerOptions.rng_seed` before each query and queries are serialised by a lock, so the same query with the same
seed yields the same path. Path simplification runs a fixed number of shortcut rounds (not a wall-time budget) for
the same reason.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from scone_bt.config.grasp import PLANNERS
from scone_bt.config.robot import PlannerSpec
from scone_bt.errors import UnknownNameError
from scone_bt.motion.segments import MOTION_RESOLUTION, motion_step, segment_times
from scone_bt.motion.types import PlanResult, PlanStatus

_ROBOT_FILE = PlannerSpec()  # what a robot file states is defaulted there, once

__all__ = [
    "BACKENDS",
    "MOTION_RESOLUTION",
    "PlannerOptions",
    "direct_path",
    "motion_step",
    "path_free",
    "plan_joint_path",
    "segment_times",
    "silence_ompl",
]

BACKENDS = ("ompl", "vamp")


_LOCK = threading.Lock()

ITERATIONS_PER_S = 2000.0
"""Planner iterations one second of `time_limit_s` buys. The budget is counted in iterations so that a seeded run
repeats on any machine, however loaded. In the kitchen RRTConnect ran 3,000-19,000 iterations per CPU second on the
development machine, and the hardest carries of the motion benchmark needed about 2,500: the robots' 2 s budget
(4,000) covers them, and a 0.02 s budget (40) still fails hard queries as the rushed-planner profile intends."""
WALL_CAP_FACTOR = 20.0
"""A search is also stopped after this many times its time limit in wall seconds (a guard, never reached normally)."""


@dataclass(frozen=True)
class PlannerOptions:
    """Settings of one planning query.

    Attributes:
        name: OMPL planner, one of PLANNERS.
        time_limit_s: Budget for finding a first solution, seconds, counted as `ITERATIONS_PER_S` planner
            iterations per second so that it does not depend on the machine's load.
        simplify: Shortcut and prune the path afterwards.
        rng_seed: Seed of OMPL's samplers.
        resolution: Motion-checking step as a fraction of the joint space's largest extent.
        simplify_rounds: Shortcutting rounds when simplifying.
        try_direct: First check the straight joint-space segment to each goal (at the same resolution OMPL's
            motion validator uses) and return it when it is collision-free, as MoveIt's planners do; OMPL runs
            only when no goal is directly reachable.
        backend: "ompl", or "vamp": where no goal is directly reachable, VAMP plans first (`plan_vamp`, seeded
            by `rng_seed`, its path re-checked with the mesh checker), and OMPL only when VAMP cannot: an arm
            VAMP has no model of, VAMP not installed, no path, or a path that fails the mesh check (e.g. tilts a
            carried object). VAMP needs `is_valid` to be a `CollisionWorld`'s.
    """

    name: str = _ROBOT_FILE.name
    time_limit_s: float = _ROBOT_FILE.time_limit_s
    simplify: bool = _ROBOT_FILE.simplify
    rng_seed: int = _ROBOT_FILE.rng_seed
    resolution: float = MOTION_RESOLUTION
    simplify_rounds: int = 3
    try_direct: bool = True
    backend: str = _ROBOT_FILE.backend

    @classmethod
    def of(cls, spec: PlannerSpec) -> PlannerOptions:
        """The options a robot file's ``planner:`` section states (the rest at their defaults)."""
        return cls(
            name=spec.name,
            time_limit_s=spec.time_limit_s,
            simplify=spec.simplify,
            rng_seed=spec.rng_seed,
            backend=spec.backend,
        )


def silence_ompl() -> None:
    """Keep OMPL's info/debug chatter off the user's terminal; failures reach users as typed results."""
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_NONE)


def _planner(name: str, si: object) -> object:
    from ompl import geometric as og

    if name not in PLANNERS:
        raise UnknownNameError("planner", name, PLANNERS)
    return getattr(og, name)(si)


def plan_joint_path(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    is_valid: Callable[[np.ndarray], bool],
    options: PlannerOptions = PlannerOptions(),
) -> PlanResult:
    """Plan a collision-free joint path from start to a goal, or to any goal of a set, with OMPL (radians).

    A (k, dof) `goal` is a goal set: the valid ones are handed to OMPL together (`ompl.base.GoalStates`), so the
    planner grows towards all of them at once and stops at the first it connects; `PlanResult.goal_index` says
    which.

    Args:
        start: (dof,) start configuration.
        goal: (dof,) goal configuration, or (k, dof) goal set.
        lower: (dof,) lower joint limits.
        upper: (dof,) upper joint limits.
        is_valid: Returns True for a collision-free configuration within limits.
        options: Planner name, time limit, simplification and seed.

    Returns:
        SUCCESS with an (N, dof) path, or the reason it failed (START_INVALID, GOAL_INVALID, TIMED_OUT, ...).

    Raises:
        UnknownNameError: the planner name is not one of PLANNERS (a configuration error, not an outcome).
    """
    t0 = time.perf_counter()
    start = np.asarray(start, dtype=float)
    goals = np.atleast_2d(np.asarray(goal, dtype=float))
    if options.name not in PLANNERS:
        raise UnknownNameError("planner", options.name, PLANNERS)
    if options.backend not in BACKENDS:
        raise UnknownNameError("planner backend", options.backend, BACKENDS)
    if not is_valid(start):
        return PlanResult(
            PlanStatus.START_INVALID, None, time.perf_counter() - t0, "start configuration is in collision"
        )
    valid = [i for i, g in enumerate(goals) if is_valid(g)]
    if not valid:
        what = "goal configuration is" if len(goals) == 1 else f"all {len(goals)} goal configurations are"
        return PlanResult(PlanStatus.GOAL_INVALID, None, time.perf_counter() - t0, f"{what} in collision")
    if options.try_direct:
        for i in valid:
            direct = _direct(start, goals[i], lower, upper, is_valid, options, t0)
            if direct is not None:
                return replace(direct, goal_index=i)
    why_not_vamp = ""
    if options.backend == "vamp":
        vamp, why_not_vamp = _plan_vamp(start, goals[valid], is_valid, options, t0)
        if vamp is not None:
            return replace(vamp, goal_index=valid[vamp.goal_index])
    with _LOCK:
        result = _solve(start, goals[valid], lower, upper, is_valid, options, t0)
    if why_not_vamp:
        result = replace(result, message=f"{result.message} ({why_not_vamp}: planned with OMPL)")
    if result.success:
        return replace(result, goal_index=valid[result.goal_index])
    return result


def direct_path(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    is_valid: Callable[[np.ndarray], bool],
    options: PlannerOptions = PlannerOptions(),
) -> PlanResult | None:
    """The straight joint-space segment from a valid `start` to one valid `goal` (radians), checked as
    `plan_joint_path` checks it before OMPL runs; None where a state on it is invalid.

    A caller that builds a goal set goal by goal (`path_search`) asks this first and builds the set, and runs
    OMPL, only where no goal so far is directly reachable: `plan_joint_path` with that set then returns what it
    would have returned with the whole set built up front (it tries the straight segments in goal order).
    """
    return _direct(
        np.asarray(start, dtype=float),
        np.asarray(goal, dtype=float),
        lower,
        upper,
        is_valid,
        options,
        time.perf_counter(),
    )


def _direct(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    is_valid: Callable[[np.ndarray], bool],
    options: PlannerOptions,
    t0: float,
) -> PlanResult | None:
    step = motion_step(lower, upper, options.resolution)
    if not _segment_free(is_valid, start, goal, segment_times(start, goal, step)[1:-1]):
        return None
    return PlanResult(
        PlanStatus.SUCCESS,
        np.array([start, goal]),
        time.perf_counter() - t0,
        "direct: the straight joint-space segment is collision-free",
    )


def path_free(is_valid: Callable[[np.ndarray], bool], path: np.ndarray, step: float) -> bool:
    """True if every segment of `path` (its waypoints, radians) is free, checked every ``step`` (rad, L2) between
    its ends, as `_segment_free` checks one."""
    path = np.asarray(path, dtype=float)
    return all(
        _segment_free(is_valid, qa, qb, segment_times(qa, qb, step)[1:-1])
        for qa, qb in zip(path[:-1], path[1:], strict=True)
    )


def _segment_free(
    is_valid: Callable[[np.ndarray], bool], qa: np.ndarray, qb: np.ndarray, times: np.ndarray
) -> bool:
    """True if every state qa + (qb - qa) t, t in `times`, is valid (checked in order up to the first invalid).

    A `CollisionWorld`'s checker checks them as one batch (`CollisionWorld.states_valid`: the same answers and
    count of checks); any other callable state by state.
    """
    from scone_bt.motion.collision import CollisionWorld, interpolated

    world = getattr(is_valid, "__self__", None)
    if isinstance(world, CollisionWorld) and getattr(is_valid, "__func__", None) is CollisionWorld.is_valid:
        return world.states_valid(interpolated(qa, qb, times))
    return all(is_valid(qa + (qb - qa) * t) for t in times)


def _plan_vamp(
    start: np.ndarray,
    goals: np.ndarray,
    is_valid: Callable[[np.ndarray], bool],
    options: PlannerOptions,
    t0: float,
) -> tuple[PlanResult | None, str]:
    """VAMP's mesh-checked path (goal_index into `goals`), or None and why OMPL plans instead."""
    from scone_bt.motion.collision import CollisionWorld
    from scone_bt.motion.vamp_planner import VAMP_ROBOTS, VampOptions, plan_vamp, vamp_available

    world = getattr(is_valid, "__self__", None)
    if not isinstance(world, CollisionWorld):
        return None, "VAMP needs a CollisionWorld's validity checker"
    if world.arm.config.name not in VAMP_ROBOTS:
        return None, f"VAMP has no model of {world.arm.config.name}"
    if not vamp_available():
        return None, "VAMP is not installed (make vamp)"
    plan = plan_vamp(
        start,
        goals,
        world,
        VampOptions(rng_seed=options.rng_seed, simplify=options.simplify, resolution=options.resolution),
    )
    if not plan.success:
        return None, plan.result.message
    if not plan.mesh_valid:
        assert plan.mesh is not None
        return None, f"VAMP's path fails the mesh check ({plan.mesh.why})"
    return replace(plan.result, planning_time=time.perf_counter() - t0), ""


def _solve(
    start: np.ndarray,
    goals: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    is_valid: Callable[[np.ndarray], bool],
    options: PlannerOptions,
    t0: float,
) -> PlanResult:
    """OMPL's answer for a valid start and valid goals: seeded, bounded by iterations, then simplified."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    silence_ompl()
    ou.RNG.setSeed(int(options.rng_seed) % 2_147_483_646 + 1)  # OMPL treats 0 as "pick a random seed"
    space, si = _space_information(lower, upper, is_valid, options.resolution)
    ss = og.SimpleSetup(si)
    _set_start_and_goals(ss, space, si, start, goals)
    ss.setPlanner(_planner(options.name, si))
    status = ss.solve(ob.PlannerTerminationCondition(_iteration_budget(options)))
    kind = status.getStatus().name
    if kind != "EXACT_SOLUTION":
        reason = {
            "TIMEOUT": PlanStatus.TIMED_OUT,
            "APPROXIMATE_SOLUTION": PlanStatus.TIMED_OUT,
            "INVALID_START": PlanStatus.START_INVALID,
            "INVALID_GOAL": PlanStatus.GOAL_INVALID,
        }.get(kind, PlanStatus.NO_SOLUTION)
        return PlanResult(reason, None, time.perf_counter() - t0, f"OMPL {options.name}: {status.asString()}")
    path = ss.getSolutionPath()
    if options.simplify:
        _simplify(og.PathSimplifier(si), path, options.simplify_rounds)
    dof = len(start)
    points = np.array([[path.getState(k)[i] for i in range(dof)] for k in range(path.getStateCount())])
    index = int(np.argmin(np.max(np.abs(goals - points[-1]), axis=1)))
    points[0], points[-1] = start, goals[index]
    return PlanResult(
        PlanStatus.SUCCESS,
        points,
        time.perf_counter() - t0,
        f"{options.name}: {len(points)} waypoints",
        goal_index=index,
    )


def _space_information(
    lower: np.ndarray, upper: np.ndarray, is_valid: Callable[[np.ndarray], bool], resolution: float
) -> tuple[Any, Any]:
    """OMPL's joint space within the limits, and its space information checking states with `is_valid`."""
    from ompl import base as ob

    dof = len(lower)
    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for i in range(dof):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    # The callback must not hold OMPL objects: a C++ -> Python -> C++ cycle would leak (and nanobind reports it).
    # map over the state's __getitem__ rather than a generator: the same floats, a third cheaper per check.
    si.setStateValidityChecker(lambda s: is_valid(np.fromiter(map(s.__getitem__, range(dof)), float, dof)))
    si.setStateValidityCheckingResolution(resolution)
    si.setup()
    return space, si


def _set_start_and_goals(ss: Any, space: Any, si: Any, start: np.ndarray, goals: np.ndarray) -> None:
    """The query's start, and its one goal or its goal set (OMPL copies the states)."""
    from ompl import base as ob

    dof = len(start)
    a = space.allocState()
    for i in range(dof):
        a[i] = float(start[i])
    if len(goals) == 1:
        b = space.allocState()
        for i in range(dof):
            b[i] = float(goals[0][i])
        ss.setStartAndGoalStates(a, b)
        return
    ss.setStartState(a)
    goal_set = ob.GoalStates(si)
    for g in goals:
        b = space.allocState()
        for i in range(dof):
            b[i] = float(g[i])
        goal_set.addState(b)
    goal_set.setThreshold(1e-9)
    ss.setGoal(goal_set)


def _iteration_budget(options: PlannerOptions) -> Callable[[], bool]:
    """The search's stop condition: true once its iterations are spent (or, as a guard, its wall-clock cap).

    The budget counts planner iterations, not wall seconds: on a busy machine a wall-clock limit would cut a
    search short in one run and not in the next, and a seeded run would not repeat. time_limit_s converts at
    ITERATIONS_PER_S; a wall-clock cap far above it only guards against a pathological validity checker.
    """
    budget = max(1, int(np.ceil(float(options.time_limit_s) * ITERATIONS_PER_S)))
    deadline = time.perf_counter() + WALL_CAP_FACTOR * float(options.time_limit_s) + 1.0
    calls = [0]

    def stop() -> bool:
        calls[0] += 1
        return calls[0] > budget or time.perf_counter() > deadline

    return stop


def _simplify(simplifier: Any, path: Any, rounds: int) -> None:
    """Shortcut and prune the path in place, a fixed number of rounds at most (not a wall-time budget)."""
    for _ in range(rounds):
        changed = simplifier.reduceVertices(path)
        changed = simplifier.partialShortcutPath(path) or changed
        changed = simplifier.collapseCloseVertices(path) or changed
        if not changed:
            break
