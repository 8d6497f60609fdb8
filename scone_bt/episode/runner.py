"""The episode: build, loop, summarise.

`run_episode` plans the episode from its files and seed, asks a backend factory (`scone_bt.robot.registry`) for
the robot and its world, builds the human and the tree, then runs the loop over protocols only (`Robot`,
`World`, the human): each control tick ticks the tree once, then advances the world by `tick_period` and lets the
human act. While the motion planner is still computing in its worker thread, time in the world stands still (the
robot is thinking; nothing moves), so a seeded episode repeats exactly whatever the machine's speed. Nothing here
knows which backend runs. What an episode returns is summary.py's `EpisodeSummary`; where its time went,
timing.py's `WallClock`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import py_trees

from scone_bt.behaviours import BehaviourOptions, EpisodeContext, Keys, OutcomeLabels
from scone_bt.behaviours.base import BlackboardError
from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig, load_kitchen, load_robot
from scone_bt.config.grasp import GraspParams
from scone_bt.defaults import EPISODE
from scone_bt.episode.heap import release_free_heap
from scone_bt.episode.printer import LinePrinter, condition_line
from scone_bt.episode.resources import EpisodeResources, ModelPool
from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan, SeedStage
from scone_bt.episode.snapshot import SnapshotBuilder
from scone_bt.episode.summary import EpisodeSummary
from scone_bt.episode.timing import LoopPart, TimedEmbedder, WallClock
from scone_bt.errors import ConfigError
from scone_bt.events import DecisionMade, Event, EventLog, EventSink
from scone_bt.experience.learn_from import BACKEND_KEY
from scone_bt.human import HumanOptions, SimulatedHuman
from scone_bt.recipes import load_recipe
from scone_bt.robot.backend import Backend, BackendFactory, BackendRequest
from scone_bt.robot.registry import DEFAULT_BACKEND, backend_factory
from scone_bt.stocking import StockedRecipe, stock_shelf
from scone_bt.tree import build_tree, load_tree_spec

if TYPE_CHECKING:
    from scone_bt.robot.interface import Robot
    from scone_bt.robot.rig import HumanWorld, World
    from scone_bt.tree import TreeSpec
    from scone_bt.viz.scene import SceneView

__all__ = [
    "NO_TABLE_CAMERA",
    "EpisodeHook",
    "EpisodeOptions",
    "delivered",
    "run_episode",
]


@dataclass(frozen=True)
class EpisodeOptions:
    """Everything that defines an episode.

    Attributes:
        arm: Robot file name in robots/ or a path (``--arm``; the backend is ``backend``, ``--robot``).
        kitchen: Kitchen file name in perception/ or a path.
        catalogues: Extra product files merged into the kitchen's catalogue (a user's own products).
        tree: Tree file name in trees/ or a path.
        recipe: Recipe id ("example:<name>", a corpus id) or a JSON/YAML path.
        seed: Seeds object placement and distractors (directly) and the human (its own SeedSequence stream).
            The robot's own streams (perception, planners, κ̂, the gate's draws) come from ``behaviour.seed``:
            give both to reseed a whole episode, as ``scone-run --seed`` does.
        max_ticks: Limit on control ticks (each advances the world by tick_period).
        tick_period: Simulated seconds per control tick.
        distractors: Objects not in the recipe, spawned on the shelf too.
        behaviour: Settings of the robot's decision making.
        human: Settings of the simulated human.
        save: Write a rerun recording (.rrd) here.
        viewer: Spawn the rerun viewer.
        connect: Stream to a running rerun viewer at this address.
        gui: Open the backend's own window (PyBullet's, for debugging).
        backend: The robot backend's name in `scone_bt.robot.registry.BACKENDS` (``scone-run --robot``).
    """

    arm: str = EPISODE.arm
    kitchen: str = EPISODE.kitchen
    catalogues: tuple[str, ...] = ()
    tree: str = EPISODE.tree
    recipe: str = EPISODE.recipe
    seed: int = EPISODE.seed
    max_ticks: int = EPISODE.max_ticks
    tick_period: float = EPISODE.tick_period
    distractors: int = EPISODE.distractors
    behaviour: BehaviourOptions = field(default_factory=BehaviourOptions)
    human: HumanOptions = field(default_factory=HumanOptions)
    save: Path | None = None
    viewer: bool = False
    connect: str | None = None
    gui: bool = False
    backend: str = DEFAULT_BACKEND


NO_TABLE_CAMERA = (
    "note: {source} has no camera with role: table: the robot cannot see the table, so it waits for what it asked"
    " for until the step moves on, and places without seeing what already stands there"
)
"""Said before the first tick of an episode in a kitchen without a table camera (it runs, less well)."""


def delivered(name: str, world: Any, human: Any) -> bool:
    """Whether a product the recipe needs reached the person: on the table now, or brought and then moved by the
    human (put away after its step to make room, set aside for a later step, or used from their hands because the
    step needed more than the table holds)."""
    return (
        world.is_on_table(name)
        or name in human.put_away_products
        or name in human.set_aside_products
        or name in human.used_in_hand
    )


def _recording(options: EpisodeOptions) -> bool:
    return options.save is not None or options.viewer or options.connect is not None


def _make_recorder(options: EpisodeOptions) -> Any:
    from scone_bt.viz import NullRecorder

    if not _recording(options):
        return NullRecorder()
    from scone_bt.viz import Recorder  # rerun (and scipy with it): only when recording, ~0.65 s otherwise

    return Recorder(
        save=options.save,
        spawn_viewer=options.viewer,
        connect=options.connect,
        recording_id=f"episode-seed{options.seed}",
    )


HumanFactory = Callable[["HumanWorld", StockedRecipe, HumanOptions, int], Any]
"""Builds the human from the world it works in, the recipe, its options and its seed."""


class EpisodeHook(Protocol):
    """A test rig's view of the episode (`scone_bt.scenario`): set the world up, then act between control ticks.

    ``attach`` is called once, after the products are stocked, the human is built and the backend is set up
    (the simulated robot's cameras and motion system built), before the tree's first tick. ``after_tick`` is
    called after every control tick (the world advanced by ``tick_period`` and the human acted), with the number
    of control ticks so far; it may change the world (through ``world``, `scone_bt.robot.rig.World`) and send
    events to ``events``. Both run on the episode's thread, between ticks, so a seeded episode with a hook still
    repeats exactly.
    """

    def attach(self, world: World, robot: Robot, human: Any, events: EventSink) -> None: ...

    def after_tick(self, control_ticks: int) -> None: ...


@dataclass(frozen=True)
class _Plan:
    """What the episode's files and seed decide before any backend exists.

    ``placement`` is the episode seed's generator: `stock_shelf` drew the distractors from it, and the world's
    `stock` draws the products' places next.
    """

    kitchen: KitchenConfig
    robot: RobotConfig
    tree: TreeSpec
    recipe: StockedRecipe
    distractors: tuple[str, ...]
    behaviour: BehaviourOptions
    robot_seeds: SeedPlan
    episode_seeds: SeedPlan
    placement: np.random.Generator

    @property
    def products(self) -> list[ObjectSpec]:
        """What goes on the shelf: the recipe's stocked products, then the distractors."""
        return [self.kitchen.catalogue.get(n) for n in (*self.recipe.needed, *self.distractors)]


def _plan(options: EpisodeOptions) -> _Plan:
    kitchen = load_kitchen(options.kitchen, options.catalogues)
    spec = load_tree_spec(options.tree)
    rng = np.random.default_rng(options.seed)
    # The recipe's products past the slots the distractors leave stay off the shelf: the human brings them.
    shelf = stock_shelf(
        load_recipe(options.recipe), kitchen.catalogue, kitchen.scene, options.distractors, rng
    )
    behaviour = options.behaviour.resolve(spec.parameters)
    return _Plan(
        kitchen=kitchen,
        robot=load_robot(options.arm),
        tree=spec,
        recipe=shelf.recipe,
        distractors=tuple(shelf.distractors),
        behaviour=behaviour,
        # The robot's stages draw from the behaviour seed's streams, the human from the episode seed's.
        robot_seeds=SeedPlan(behaviour.seed),
        episode_seeds=SeedPlan(options.seed),
        placement=rng,
    )


@dataclass
class _Episode:
    """The built episode: what the loop ticks and what the summary reads."""

    plan: _Plan
    backend: Backend
    human: Any
    events: EventLog
    log_lines: LinePrinter
    root: py_trees.behaviour.Behaviour
    tree: py_trees.trees.BehaviourTree


def _build(
    options: EpisodeOptions,
    plan: _Plan,
    backend: Backend,
    resources: EpisodeResources,
    say: Callable[[str], None],
    sinks: tuple[EventSink, ...],
    human_factory: HumanFactory | None,
    hook: EpisodeHook | None,
    clock: WallClock,
) -> _Episode:
    """Stock the world, build the human, the event log and the tree, and set the backend up."""
    recipe, behaviour, robot_cfg = plan.recipe, plan.behaviour, plan.robot
    world = backend.world
    world.stock(plan.products, plan.placement)
    factory = human_factory or (lambda w, r, o, seed: SimulatedHuman(w, r, o, seed=seed))
    human = factory(world, recipe, options.human, plan.episode_seeds.integer(SeedStage.HUMAN))
    log_lines = LinePrinter(say, len(recipe.steps))
    events = EventLog(sinks[0], log_lines, *sinks[1:])
    timed: list[TimedEmbedder] = []

    def embedder() -> Any:
        if not timed:
            timed.append(TimedEmbedder(resources.embedder(), clock))
        return timed[0]

    context = EpisodeContext(
        robot=backend.robot,
        human=human,
        events=events,
        history=events,
        seeds=PlannerSeedStream(plan.robot_seeds),
        recipe=recipe,
        scene=plan.kitchen.scene,
        catalogue=plan.kitchen.catalogue,
        options=behaviour,
        labels=OutcomeLabels(
            embedder=str(behaviour.embedder),
            robot_id=resources.robot_id,
            arm=robot_cfg.name,
            profile=behaviour.profile,
            context={
                "robot": robot_cfg.name,
                BACKEND_KEY: options.backend,
                "seed": options.seed,
                "recipe": recipe.recipe.id,
            },
        ),
        embedder=embedder,
        kappa=resources.estimator,
        recorder=resources.store,
        gripper_opening_m=robot_cfg.gripper.opening_m,
        slide_pinch=GraspParams.of(robot_cfg).slide_pinch,
        trust=_listening_trust(events) if behaviour.trust_aware else None,
    )
    say(
        f"{recipe.recipe.title}: {len(recipe.steps)} steps, needs "
        f"{', '.join(recipe.needed) or 'nothing from the shelf'}; "
        f"distractors: {', '.join(plan.distractors) or 'none'}"
    )
    say(f"condition: {condition_line(behaviour)}")
    if recipe.unstocked or recipe.off_shelf:
        say(f"not stocked (the human brings them): {', '.join((*recipe.unstocked, *recipe.off_shelf))}")
    if plan.kitchen.table_camera is None:
        say(NO_TABLE_CAMERA.format(source=plan.kitchen.source))
    backend.setup()
    if hook is not None:
        hook.attach(world, backend.robot, human, events)
    root = build_tree(plan.tree, context)
    return _Episode(plan, backend, human, events, log_lines, root, py_trees.trees.BehaviourTree(root))


def _loop(
    ep: _Episode,
    options: EpisodeOptions,
    clock: WallClock,
    hook: EpisodeHook | None,
    realtime: bool,
    log_tick: Callable[[int], None] | None,
) -> tuple[int, int]:
    """Tick until the recipe is done and the robot idle, or ``max_ticks`` control ticks; (tree, control) ticks.

    ``log_tick`` records the state after a tree tick (None: nothing is recorded).
    """
    world, human, root = ep.backend.world, ep.human, ep.root
    reader = py_trees.blackboard.Client(name="episode")
    reader.register_key(key=Keys.MOTION_COMPUTING, access=py_trees.common.Access.READ)
    ticks = control_ticks = 0
    next_tick = time.perf_counter() + options.tick_period
    while control_ticks < options.max_ticks:
        with clock(LoopPart.TREE):
            try:
                ep.tree.tick()
            except BlackboardError as exc:  # a miswired tree file: say which file
                raise BlackboardError(f"{ep.plan.tree.source}: {exc}") from None
        ticks += 1
        if human.done and root.status is not py_trees.common.Status.RUNNING:
            if log_tick is not None:
                log_tick(ticks)
            break  # the recipe is done and the robot finished its last cycle
        # While the planner computes, time in the world stands still (the PickAndPlace behaviour reads the typed phase).
        computing = reader.get(Keys.MOTION_COMPUTING) if reader.exists(Keys.MOTION_COMPUTING) else False
        if computing:
            with clock(LoopPart.PLANNING_WAIT):
                time.sleep(0.002)  # give the planner thread the interpreter
        else:
            with clock(LoopPart.PHYSICS):
                world.advance(options.tick_period)
            with clock(LoopPart.HUMAN):
                human_events = human.update()
            for event in human_events:
                ep.events(event)
            control_ticks += 1
            if hook is not None:
                hook.after_tick(control_ticks)
            if realtime:
                time.sleep(max(0.0, next_tick - time.perf_counter()))
                next_tick = max(next_tick + options.tick_period, time.perf_counter())
        if log_tick is not None:
            with clock(LoopPart.LOGGING):
                log_tick(ticks)
    return ticks, control_ticks


def _summarise(
    ep: _Episode,
    ticks: int,
    control_ticks: int,
    clock: WallClock,
    started: float,
    first_decision: float | None,
) -> EpisodeSummary:
    """The summary of the episode that just ended (counts from the events, truth from the world)."""
    ep.log_lines.flush()
    plan, world, human = ep.plan, ep.backend.world, ep.human
    stats, measured = ep.events.stats, ep.backend.stats()
    parts, cpu_parts = dict(clock.seconds), dict(clock.cpu_seconds)
    # Perception and embedding run inside tree ticks: report them on their own and the rest as "tree".
    perception = (measured.perception_wall_s, measured.perception_cpu_s)
    for table, seconds in zip((parts, cpu_parts), perception, strict=True):
        table[LoopPart.PERCEPTION] = seconds
        table[LoopPart.TREE] = table.get(LoopPart.TREE, 0.0) - seconds - table.get(LoopPart.EMBEDDING, 0.0)
    recipe = plan.recipe
    behaviour = plan.behaviour
    # the budget gate's promise, and how it is kept; the paper's gate and the control read neither
    budget = (
        behaviour.target_failure_rate
        if behaviour.use_self_confidence and behaviour.gate == "budget"
        else None
    )
    return EpisodeSummary(
        recipe_id=recipe.recipe.id,
        recipe_title=recipe.recipe.title,
        robot=plan.robot.name,
        completed=human.done,
        steps_completed=human.steps_completed(),
        steps_total=len(recipe.steps),
        attempted=stats.attempted,
        successes=stats.successes,
        failures=stats.failures,
        failures_by_stage=dict(stats.failures_by_stage),
        help_requests=stats.help_requests,
        clarifications=stats.clarifications,
        interventions=stats.interventions,
        takeovers=stats.cancelled,
        set_back=stats.aborted,
        decisions=stats.decisions,
        control_ticks=control_ticks,
        tree_ticks=ticks,
        sim_time=round(world.sim_time, 3),
        wall_time=time.perf_counter() - started,
        needed_on_table={n: delivered(n, world, human) for n in recipe.needed},
        decision_log=tuple(ep.log_lines.lines),
        startup_to_first_decision_s=first_decision,
        wall_breakdown={str(k): round(v, 4) for k, v in sorted(parts.items())},
        cpu_breakdown={str(k): round(v, 4) for k, v in sorted(cpu_parts.items())},
        physics_steps=measured.physics_steps - measured.physics_steps_skipped,
        physics_steps_skipped=measured.physics_steps_skipped,
        renders=measured.renders,
        bodies=measured.bodies,
        constraints=measured.constraints,
        condition=condition_line(plan.behaviour),
        decided_by_rule=dict(ep.log_lines.rules),
        not_stocked=len(recipe.unstocked) + len(recipe.off_shelf),
        failure_budget=budget,
        strict_promise=budget is not None and bool(plan.behaviour.exploration_credit),
    )


def _online_trust() -> Any:
    """The person's trust estimated online for the recording (the fitted model; its ζ loads here, once)."""
    from scone_bt.trust.estimate import OnlineTrust
    from scone_bt.trust.transfer import TransferModel, load_fitted

    return OnlineTrust(TransferModel(load_fitted()))


def _listening_trust(events: EventLog) -> Any:
    """trust_aware: the person's trust estimated online, fed every event of the episode from now on."""
    trust = _online_trust()
    events.listen(trust)
    return trust


def _tick_logger(recorder: Any, scene: SceneView, ep: _Episode, lines: list[str]) -> Callable[[int], None]:
    """Records the state after each tree tick: what changed on the blackboard, the poses, the tick's lines."""
    snapshots = SnapshotBuilder(scene, ep.plan.recipe, ep.human, ep.events, lines, trust=_online_trust())

    def log_tick(tick: int) -> None:
        recorder.log_tick(snapshots.build(tick, ep.root))

    return log_tick


@dataclass
class _Start:
    """The episode's start and what its callbacks share: the wall and CPU clocks at the start (seconds; the wall
    one moves past a wait for the start), the first decision's wall time since, the lines of the tick being
    recorded."""

    printer: Callable[[str], None]
    recording: bool
    wall: float = field(default_factory=time.perf_counter)
    cpu: float = field(default_factory=time.thread_time)
    first_decision: float | None = None
    lines: list[str] = field(default_factory=list)

    def say(self, line: str) -> None:
        """Print a line (and keep it for the tick's recording)."""
        if self.recording:
            self.lines.append(line)
        self.printer(line)

    def timing(self, event: Event) -> None:
        """An event sink that notes when the first decision was made."""
        if isinstance(event, DecisionMade) and self.first_decision is None:
            self.first_decision = time.perf_counter() - self.wall


def run_episode(
    options: EpisodeOptions,
    printer: Callable[[str], None] = print,
    on_event: EventSink | None = None,
    human_factory: HumanFactory | None = None,
    realtime: bool = False,
    models: ModelPool | None = None,
    hook: EpisodeHook | None = None,
    backend: BackendFactory | None = None,
    wait_to_start: Callable[[], None] | None = None,
) -> EpisodeSummary:
    """Run one episode to completion (or to max_ticks) and return its summary: build, loop, summarise.

    Args:
        options: What to run.
        printer: Receives the human-readable log lines.
        on_event: Receives every typed event (`scone_bt.events`) as it happens.
        human_factory: Builds the human (default: SimulatedHuman); the study UI passes a tablet-driven one.
        realtime: Pace control ticks to wall-clock time (needed when a real person takes part).
        models: Share embedders with other episodes (None: this episode loads its own).
        hook: A test rig acting on the world between control ticks (`EpisodeHook`; None: nothing does). The
            scenario runner (`scone_bt.scenario`) passes one; ``scone-run`` does not.
        backend: Builds the robot and its world (None: the factory ``options.backend`` names in
            `scone_bt.robot.registry.BACKENDS`); a test passes a fake.
        wait_to_start: Called once when everything is set up, before the first tick; simulated time and the
            events begin when it returns (the study's start gate). Its wait counts in none of the summary's times.
    """
    start = _Start(printer, _recording(options))
    clock = WallClock()
    plan = _plan(options)
    factory = backend or backend_factory(options.backend)
    built = factory(
        BackendRequest(
            plan.kitchen, plan.robot, plan.robot_seeds.generator(SeedStage.PERCEPTION), gui=options.gui
        )
    )
    resources = EpisodeResources(
        built.robot,
        plan.behaviour,
        plan.behaviour.robot_id or plan.robot.name,
        plan.robot.name,
        start.say,
        models,
        estimator_seed=plan.robot_seeds.integer(SeedStage.ESTIMATORS),
        gripper_opening_m=plan.robot.gripper.opening_m,
        backend=options.backend,
    )
    try:
        with resources:
            if start.recording and built.scene is None:
                raise ConfigError(
                    "this robot backend has no scene to draw: it cannot be recorded (--save, --viewer)"
                )
            sinks = (start.timing, *((on_event,) if on_event is not None else ()))
            ep = _build(options, plan, built, resources, start.say, sinks, human_factory, hook, clock)
            return _run(ep, options, start, clock, hook, realtime, wait_to_start)
    finally:
        # After the resources closed (the world, the planner thread): a process running episodes all day
        # otherwise kept tens of MB of freed heap per episode (episode/heap.py).
        release_free_heap()


def _run(
    ep: _Episode,
    options: EpisodeOptions,
    start: _Start,
    clock: WallClock,
    hook: EpisodeHook | None,
    realtime: bool,
    wait_to_start: Callable[[], None] | None,
) -> EpisodeSummary:
    """Set the tree up, begin the recording, wait for the start, tick to the end and summarise."""
    scene = ep.backend.scene
    recorder = None
    complete = False
    try:
        ep.tree.setup(timeout=120)
        recorder = _make_recorder(options)
        recorder.log_static_scene(scene)
        if wait_to_start is not None:
            waiting = time.perf_counter()
            wait_to_start()
            start.wall += time.perf_counter() - waiting  # the wall times begin at the start
        log_tick = (
            _tick_logger(recorder, scene, ep, start.lines) if start.recording and scene is not None else None
        )
        clock.add(LoopPart.STARTUP, time.perf_counter() - start.wall, time.thread_time() - start.cpu)
        ticks, control_ticks = _loop(ep, options, clock, hook, realtime, log_tick)
        summary = _summarise(ep, ticks, control_ticks, clock, start.wall, start.first_decision)
        ep.tree.shutdown()
        complete = True
        return summary
    finally:
        if recorder is not None:
            # A run that ended early (an interrupt, an error) never replaces an existing recording.
            recorder.close(complete=complete)
        py_trees.blackboard.Blackboard.clear()
