"""Entity paths and timelines of a SCONE-BT recording (stable names: tests, blueprints and users rely on them)."""

from __future__ import annotations

__all__ = [
    "TICK",
    "SIM_TIME",
    "WORLD",
    "POSES",
    "SCENE",
    "ROBOT",
    "OBJECTS",
    "CAMERA",
    "IMAGE",
    "RGB",
    "DEPTH",
    "DETECTIONS_2D",
    "DETECTIONS_3D",
    "EE_PATH",
    "EE_EXECUTED",
    "AFFORDANCES",
    "AFFORDANCE_TABLE",
    "AFFORDANCE_RELEVANCE",
    "AFFORDANCE_CONFIDENCE",
    "GATE",
    "GATE_DECISION",
    "GATE_KIND",
    "GATE_CONFIDENCE",
    "GATE_RELEVANCE",
    "TREE",
    "TREE_GRAPH",
    "TREE_TEXT",
    "TREE_STATUS",
    "CONFIDENCE",
    "COUNTERS",
    "TRAJECTORY",
    "PLANNED_POSITION",
    "PLANNED_VELOCITY",
    "EXECUTED_POSITION",
    "RECIPE",
    "LOG",
    "EPISODE_SIM_TIME",
]

TICK = "tick"  # sequence timeline: the behaviour tree's tick counter
SIM_TIME = "sim_time"  # duration timeline: simulated seconds

WORLD = "world"
POSES = f"{WORLD}/poses"  # per tick, one row per moved body: Transform3D tf#/world → robot/<link> or object/<name>
SCENE = f"{WORLD}/scene"  # table, shelf tiers, pedestal, floor (static boxes)
ROBOT = f"{WORLD}/robot"  # one child per link (in frame robot/<link>), its geometry pieces below it
OBJECTS = f"{WORLD}/objects"  # one child per object (in frame object/<name>) with its geometry
CAMERA = f"{WORLD}/camera"  # camera pose (OpenCV axes)
IMAGE = f"{CAMERA}/image"  # pinhole: frustum in 3D, image plane in 2D
RGB = f"{IMAGE}/rgb"
DEPTH = f"{IMAGE}/depth"
DETECTIONS_2D = f"{IMAGE}/detections"
DETECTIONS_3D = f"{WORLD}/detections"
EE_PATH = f"{WORLD}/plan/ee_path"  # planned end-effector trace
EE_EXECUTED = f"{WORLD}/plan/ee_executed"  # where the end effector actually went

AFFORDANCES = "affordances"
AFFORDANCE_TABLE = f"{AFFORDANCES}/table"
AFFORDANCE_RELEVANCE = f"{AFFORDANCES}/relevance"
AFFORDANCE_CONFIDENCE = f"{AFFORDANCES}/confidence"

GATE = "gate"
GATE_DECISION = f"{GATE}/decision"
GATE_KIND = f"{GATE}/kind"  # act / ask / idle as a state lane
GATE_CONFIDENCE = f"{GATE}/confidence"
GATE_RELEVANCE = f"{GATE}/relevance"

TREE = "tree"
TREE_GRAPH = f"{TREE}/graph"
TREE_TEXT = f"{TREE}/text"
TREE_STATUS = f"{TREE}/status"  # one child entity per behaviour, mirroring the tree

CONFIDENCE = "confidence"  # one child per object: κ̂ over time
PERSON_TRUST = "person_trust"  # one child per object: the person's trust as the robot estimates it, over time
COUNTERS = "counters"  # one child per counter

TRAJECTORY = "trajectory"
PLANNED_POSITION = f"{TRAJECTORY}/planned/position"
PLANNED_VELOCITY = f"{TRAJECTORY}/planned/velocity"
EXECUTED_POSITION = f"{TRAJECTORY}/executed/position"

RECIPE = "recipe"
LOG = "log"
EPISODE_SIM_TIME = (
    "episode/sim_time"  # logged every tick (so every tick is in the recording); flat while planning
)
