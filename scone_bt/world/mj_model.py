"""The kitchen as a MuJoCo model (MuJoCo adapter): the robot file's URDF, the kitchen file's boxes and cameras, and
the episode's products, built in memory with `mujoco.MjSpec`.

The arm is read from the same URDF Pinocchio plans with (MuJoCo's URDF reader, with static bodies kept apart so
every link and the end-effector frame stay bodies of their own); its joints get position actuators with gravity
compensation, its fingers force-limited position actuators and an equality that couples them. Products look as in
PyBullet: a coloured box or cylinder, a white cap and the ArUco marker drawn as flat boxes (`world.visuals`); only
the collision shape collides. Finger pads meet products through explicit contact pairs whose friction is the product
of both coefficients, as Bullet combines them (MuJoCo's default would take the larger one and ignore the product's).
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.config.catalogue import Shape
from scone_bt.config.markers import CAP_THICKNESS_M, INK_THICKNESS_M, LAYER_GAP_M, MARKER_CELLS, lid_marker
from scone_bt.errors import ConfigError
from scone_bt.world.scene_boxes import FLOOR_FRICTION, SCENE_FRICTION, StaticBox, box_colour, static_boxes

if TYPE_CHECKING:
    import mujoco

__all__ = [
    "ARM_GAINS",
    "COVER_SLOTS",
    "NOSLIP_ITERATIONS",
    "SUBSTEP_S",
    "EGL_PACKAGES",
    "ArmGains",
    "ModelParts",
    "StaticBox",
    "build_model",
    "import_mujoco",
    "arm_spec",
]

EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri"
"""The Debian packages MuJoCo's headless renderer needs (Mesa's software EGL)."""
SUBSTEP_S = 1.0 / 480.0
"""Longest MuJoCo step, seconds: a control step (1 / physics_hz) is split into equal steps no longer than this (the
stiff joint servos and the finger contacts stay stable with the implicit integrator at this step)."""
NOSLIP_ITERATIONS = 4
"""Iterations of MuJoCo's no-slip solver pass per step (see `build_model`)."""
PAD_TORSION_M = 0.01
"""Torsional friction of a finger pad per unit of its sliding friction, metres: a pad's contact patch resists
twisting (about (2/3) of a 1.5 cm patch radius). MuJoCo gives a mesh finger one or two contact points where Bullet
keeps a manifold of several; without this a held jar pivots about the line between the two fingers and falls out."""
PAD_SOLREF_S = 0.005
"""Time constant of the finger pads' contacts, seconds (MuJoCo's solref; over twice the physics step)."""
COVER_SLOTS = 8
"""Covers (a hand over a lid, a cloth over a lens) the model keeps ready: adding one then needs no recompile."""
PARK_Z_M = -5.0
"""Where an unused cover waits: far below the floor, out of every camera's view."""
ROBOT_GROUP = 1 << 1
"""Contact type of the arm's links: they meet products and the fixed scene, not each other (as in PyBullet, which
loads the URDF without self-collision)."""
FINGER_GROUP = 1 << 2
"""Contact type of the finger pads: they meet the fixed scene, and products only through explicit pairs
(`_finger_pairs`)."""
PRODUCT_GROUP = 1 << 3
"""Contact type of the products: they meet the arm's links, and the fixed scene, the pads and each other only
through explicit pairs whose friction is the product of both coefficients, as Bullet's (`_product_pairs`)."""


@dataclass(frozen=True)
class ArmGains:
    """Joint servo of the arm: stiffness (N m / rad), damping (N m s / rad), rotor armature (kg m²)."""

    stiffness: float = 4000.0
    damping: float = 400.0
    armature: float = 0.1
    finger_stiffness: float = 2000.0
    """Finger servo stiffness, N / m (closing on an object 2 cm short of the target pushes 40 N)."""
    finger_damping: float = 40.0
    """Finger servo damping, N s / m."""


ARM_GAINS = ArmGains()


@dataclass(frozen=True)
class ModelParts:
    """What a compiled kitchen model is made of, by name (the ids are the compiled model's).

    Attributes:
        boxes: The fixed scene's boxes.
        products: Product names in the order their bodies were added.
        cameras: Camera names (the kitchen file's), each a model camera of the same name.
        root_inertial: The arm's root link's inertial origin in its link frame, as the URDF gives it: position
            (m) and quaternion (w, x, y, z). The compiled model turns that frame to the principal axes of inertia;
            PyBullet reports the base pose in the URDF's frame (`MjKitchen.link_poses` does the same).
    """

    boxes: tuple[StaticBox, ...]
    products: tuple[str, ...]
    cameras: tuple[str, ...]
    root_inertial: tuple[tuple[float, float, float], tuple[float, float, float, float]]


def import_mujoco() -> Any:
    """The `mujoco` module, with headless EGL rendering unless MUJOCO_GL says otherwise.

    Raises:
        ConfigError: mujoco is not installed (names the extra).
    """
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco
    except ImportError as exc:
        if exc.name is not None and exc.name.split(".")[0] == "mujoco":
            raise ConfigError("--robot mujoco needs the mujoco package: pip install -e '.[mujoco]'") from None
        raise _no_rendering(exc) from None
    except Exception as exc:  # noqa: BLE001 (a GL backend that cannot load fails inside PyOpenGL, any type)
        raise _no_rendering(exc) from None
    return mujoco


def _no_rendering(exc: BaseException) -> ConfigError:
    """The one line for a MuJoCo that cannot load its OpenGL backend (MUJOCO_GL)."""
    detail = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return ConfigError(
        f"MuJoCo cannot load its MUJOCO_GL={os.environ.get('MUJOCO_GL')} renderer ({detail}); headless rendering "
        f"needs MUJOCO_GL=egl and Mesa's EGL: apt-get install {EGL_PACKAGES}"
    )


def _urdf_text(robot: RobotConfig) -> str:
    """The robot's URDF with absolute mesh paths and MuJoCo's import settings (keep static links as bodies)."""
    urdf = Path(robot.urdf)
    try:
        text = urdf.read_text()
    except OSError as exc:
        raise ConfigError(f"{robot.source}: cannot read URDF {urdf} ({exc.strerror})") from None

    def absolute(match: re.Match[str]) -> str:
        name = match.group(1)
        if name.startswith("package://"):
            name = name[len("package://") :]
        path = (urdf.parent / name).resolve()
        if not path.is_file():
            raise ConfigError(f"{robot.source}: mesh {match.group(1)} of {urdf} not found at {path}")
        return f'filename="{path}"'

    text = re.sub(r'filename="([^"]+)"', absolute, text)
    settings = (
        '<mujoco><compiler strippath="false" fusestatic="false" discardvisual="true" '
        'balanceinertia="true"/></mujoco>'
    )
    text, n = re.subn(r"(<robot\b[^>]*>)", lambda m: m.group(1) + settings, text, count=1)
    if not n:
        raise ConfigError(f"{robot.source}: {urdf} has no <robot> element")
    return text


def arm_spec(robot: RobotConfig) -> mujoco.MjSpec:
    """The arm alone as an MjSpec: the URDF's links and joints, no actuators (the FK test compiles this).

    Raises:
        ConfigError: the URDF or a mesh cannot be read, or MuJoCo rejects it (one line naming the file).
    """
    mujoco = import_mujoco()
    try:
        spec = mujoco.MjSpec.from_string(_urdf_text(robot))
        spec.compile()  # reports a bad mesh or joint now, naming the file
    except ValueError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ConfigError(f"{robot.source}: MuJoCo could not load URDF {robot.urdf} ({first})") from None
    # The URDF's visual meshes (the Panda's 116k triangles) are left out, as PyBullet's cameras leave them out
    # (robots/*.yaml camera_shapes: collision); the products' looks added later must stay, so MuJoCo's own
    # discarding of contact-free geoms is switched off once they are gone.
    for geom in list(spec.geoms):
        if geom.contype == 0 and geom.conaffinity == 0:
            spec.delete(geom)
    spec.compiler.discardvisual = False
    names = {j.name for j in spec.joints}
    for joint in (*robot.arm_joints, *robot.gripper.joints):
        if joint not in names:
            raise ConfigError(f"{robot.source}: joint {joint!r} is not in {robot.urdf} as MuJoCo reads it")
    return spec


def _matte(spec: mujoco.MjSpec) -> str:
    """A material without highlights, as the PyBullet renderer is set up (white lids would bleach)."""
    material = spec.add_material()
    material.name = "matte"
    material.specular = 0.0
    material.shininess = 0.0
    material.reflectance = 0.0
    return "matte"


def _add_arm(spec: mujoco.MjSpec, robot: RobotConfig, gains: ArmGains) -> None:
    """Actuators, gravity compensation, finger coupling and contact bits on the arm already in ``spec``."""
    mujoco = import_mujoco()
    root = spec.worldbody.first_body()
    root.pos = [float(c) for c in robot.base_position]
    finger_joints = set(robot.gripper.joints)
    finger_bodies = {j.parent.name for j in spec.joints if j.name in finger_joints}
    for body in spec.bodies:
        if body.name == "world":
            continue
        body.gravcomp = 1.0
        for geom in body.geoms:
            bits = FINGER_GROUP if body.name in finger_bodies else ROBOT_GROUP
            geom.contype = bits
            geom.conaffinity = 0
            geom.group = 2
            geom.material = "matte"
            geom.rgba = [0.85, 0.85, 0.87, 1.0]
            if body.name in finger_bodies:
                geom.friction = [robot.gripper.finger_friction, 0.005, 0.0001]
                geom.rgba = [0.25, 0.25, 0.27, 1.0]
    effort = robot.control.max_joint_force
    for joint in spec.joints:
        # The robot file's force limits apply, as PyBullet's motors apply them (the URDF's efforts do not: the
        # Panda's fingers would squeeze with 20 N instead of the gripper's max_force).
        joint.actfrclimited = 0
        if joint.name in robot.arm_joints:
            joint.armature = gains.armature
            _add_servo(spec, joint.name, gains.stiffness, gains.damping, effort)
        elif joint.name in finger_joints:
            joint.armature = 0.01
            _add_servo(
                spec, joint.name, gains.finger_stiffness, gains.finger_damping, robot.gripper.max_force
            )
    fingers = list(robot.gripper.joints)
    coupled = any(
        eq.type == mujoco.mjtEq.mjEQ_JOINT and {eq.name1, eq.name2} == set(fingers) for eq in spec.equalities
    )
    if len(fingers) == 2 and not coupled:  # the Panda's URDF couples them already (<mimic>)
        # A parallel gripper's gearing: both fingers at the same opening (`world.arm_io.couple_fingers`).
        eq = spec.add_equality()
        eq.type = mujoco.mjtEq.mjEQ_JOINT
        eq.name1, eq.name2 = fingers
        eq.data[:5] = [0.0, 1.0, 0.0, 0.0, 0.0]
        eq.name = "finger_coupling"


def _add_servo(spec: mujoco.MjSpec, joint: str, stiffness: float, damping: float, force_limit: float) -> None:
    """A position actuator on ``joint``: stiffness (per rad or m), damping, force limit (N m or N) both ways."""
    mujoco = import_mujoco()
    act = spec.add_actuator()
    act.name = joint
    act.target = joint
    act.trntype = mujoco.mjtTrn.mjTRN_JOINT
    act.gainprm[0] = stiffness
    act.biasprm[:3] = [0.0, -stiffness, -damping]
    act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
    act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
    act.forcelimited = 1
    act.forcerange = [-force_limit, force_limit]
    act.ctrllimited = 0


def _add_scene(spec: mujoco.MjSpec, kitchen: KitchenConfig, boxes: Sequence[StaticBox]) -> None:
    mujoco = import_mujoco()
    scene = kitchen.scene
    world = spec.worldbody
    static_bits = ROBOT_GROUP | FINGER_GROUP  # products: `_product_pairs`
    for box in boxes:
        geom = world.add_geom()
        geom.name = box.name
        geom.type = mujoco.mjtGeom.mjGEOM_BOX
        geom.size = [s / 2 for s in box.size]
        geom.pos = list(box.center)
        geom.rgba = list(box_colour(box.name))
        geom.friction = [SCENE_FRICTION, 0.005, 0.0001]
        geom.contype = 1
        geom.conaffinity = static_bits
        geom.material = "matte"
    floor = world.add_geom()
    floor.name = "floor"
    floor.type = mujoco.mjtGeom.mjGEOM_PLANE
    floor.size = [0.0, 0.0, 1.0]
    floor.pos = [0.0, 0.0, scene.floor_z]
    floor.rgba = [0.9, 0.9, 0.9, 1.0]
    floor.friction = [FLOOR_FRICTION, 0.005, 0.0001]
    floor.contype = 1
    floor.conaffinity = static_bits
    floor.material = "matte"
    for cam in kitchen.cameras:
        from scone_bt.perception.camera import world_from_camera

        pose = world_from_camera(cam)
        # OpenCV's camera axes (x right, y down, z forward) to OpenGL's (x right, y up, looking along -z).
        rotation = pose[:3, :3] @ np.diag([1.0, -1.0, -1.0])
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, rotation.flatten())
        camera = world.add_camera()
        camera.name = cam.name
        camera.pos = pose[:3, 3].tolist()
        camera.quat = quat.tolist()
        camera.fovy = cam.fov_deg
    for i in range(COVER_SLOTS):
        cover = world.add_body()
        cover.name = f"cover{i}"
        cover.mocap = True
        cover.pos = [0.0, 0.0, PARK_Z_M - i]
        geom = cover.add_geom()
        geom.name = f"cover{i}"
        geom.type = mujoco.mjtGeom.mjGEOM_BOX
        geom.size = [0.01, 0.01, 0.01]
        geom.contype = geom.conaffinity = 0
        geom.rgba = [0.2, 0.2, 0.2, 1.0]
        geom.material = "matte"


def _add_product(spec: mujoco.MjSpec, product: ObjectSpec, index: int) -> None:
    """A free body: the collision shape (the catalogue's mass), then its look (no mass, no contacts)."""
    from scone_bt.world.visuals import marker_layers

    mujoco = import_mujoco()
    body = spec.worldbody.add_body()
    body.name = product.name
    body.pos = [0.4 * index, 3.0, 1.0]  # anywhere: `spawn_planned` puts it on the shelf
    body.add_freejoint()
    sx, sy, sz = product.size
    box = product.shape == Shape.BOX
    solid = body.add_geom()
    solid.name = product.name
    solid.type = mujoco.mjtGeom.mjGEOM_BOX if box else mujoco.mjtGeom.mjGEOM_CYLINDER
    solid.size = [sx / 2, sy / 2, sz / 2] if box else [sx / 2, sz / 2, 0.0]
    solid.mass = product.mass
    solid.friction = [product.friction, 0.001, 0.0005]
    solid.condim = 4
    solid.contype = PRODUCT_GROUP
    solid.conaffinity = ROBOT_GROUP
    solid.rgba = list(product.rgba)
    solid.material = "matte"

    def look(kind: Any, size: Sequence[float], pos: Sequence[float], rgba: Sequence[float]) -> None:
        g = body.add_geom()
        g.type = kind
        g.size = list(size)
        g.pos = list(pos)
        g.rgba = list(rgba)
        g.contype = g.conaffinity = 0
        g.mass = 0.0
        g.density = 0.0
        g.material = "matte"

    cap = (0.97, 0.97, 0.97, 1.0)
    ink = (0.03, 0.03, 0.03, 1.0)
    top_of_cap = (0.0, 0.0, sz / 2 + CAP_THICKNESS_M / 2)
    if box:
        look(mujoco.mjtGeom.mjGEOM_BOX, (sx / 2, sy / 2, CAP_THICKNESS_M / 2), top_of_cap, cap)
    else:
        look(mujoco.mjtGeom.mjGEOM_CYLINDER, (sx / 2, CAP_THICKNESS_M / 2, 0.0), top_of_cap, cap)
    marker = lid_marker(product)
    cell = marker.side / MARKER_CELLS
    black, white = marker_layers(product.marker_id)
    top = sz / 2 + marker.lift
    for rects, rgba, surface in ((black, ink, top - (LAYER_GAP_M if white else 0.0)), (white, cap, top)):
        for row, col, rows, cols in rects:
            cx = (col + cols / 2) * cell - marker.side / 2
            cy = marker.side / 2 - (row + rows / 2) * cell
            look(
                mujoco.mjtGeom.mjGEOM_BOX,
                (cols * cell / 2, rows * cell / 2, INK_THICKNESS_M / 2),
                (cx, cy, surface - INK_THICKNESS_M / 2),
                rgba,
            )


def _product_pairs(spec: mujoco.MjSpec, products: Sequence[ObjectSpec]) -> None:
    """Product × fixed scene and product × product contacts with Bullet's friction (the product of both
    coefficients). MuJoCo's own rule takes the larger: a product held its shelf with 0.8 where PyBullet gives
    0.8 × its own (0.44 for the catalogue's 0.55), so what slides on one engine stood still on the other."""
    statics = [g for g in spec.worldbody.geoms if g.contype and g.conaffinity]
    solids = [spec.geom(p.name) for p in products]

    def pair(a: Any, b: Any) -> None:
        mu = float(a.friction[0]) * float(b.friction[0])
        twist = max(float(a.friction[1]), float(b.friction[1]))
        roll = max(float(a.friction[2]), float(b.friction[2]))
        contact = spec.add_pair()
        contact.name = f"{a.name}|{b.name}"
        contact.geomname1 = a.name
        contact.geomname2 = b.name
        contact.condim = max(int(a.condim), int(b.condim))
        contact.friction = [mu, mu, twist, roll, roll]

    for i, solid in enumerate(solids):
        for other in (*statics, *solids[i + 1 :]):
            pair(solid, other)


def _finger_pairs(spec: mujoco.MjSpec, robot: RobotConfig, products: Sequence[ObjectSpec]) -> None:
    """Finger pad × product contacts with Bullet's friction (the product of both coefficients)."""
    finger_joints = set(robot.gripper.joints)
    fingers = [
        g.name
        for body in spec.bodies
        if any(j.name in finger_joints for j in body.joints)
        for g in body.geoms
    ]
    for product in products:
        mu = product.friction * robot.gripper.finger_friction
        for finger in fingers:
            pair = spec.add_pair()
            pair.name = f"{finger}|{product.name}"
            pair.geomname1 = finger
            pair.geomname2 = product.name
            pair.condim = 4
            pair.friction = [mu, mu, mu * PAD_TORSION_M, 0.0001, 0.0001]
            # Stiffer than MuJoCo's default contact (0.02 s): squeezed with 40 N the default lets a pad sink
            # 2.4 mm into a jar, and the jar creeps along the pads through the carry (1.6 cm in 3 s).
            pair.solref = [PAD_SOLREF_S, 1.0]
            pair.solimp = [0.95, 0.99, 0.001, 0.5, 2.0]


def build_model(
    kitchen: KitchenConfig,
    robot: RobotConfig,
    products: Sequence[ObjectSpec],
    time_step: float,
    gains: ArmGains = ARM_GAINS,
) -> tuple[mujoco.MjModel, ModelParts]:
    """The compiled kitchen: arm, fixed scene, cameras, cover slots and ``products`` (each a free body).

    Args:
        kitchen: Scene, cameras.
        robot: The arm.
        products: The products of the episode (all of them: the model is compiled once per stocking).
        time_step: The control step, seconds; MuJoCo steps it in equal parts no longer than SUBSTEP_S.
        gains: The joint servos.
    """
    mujoco = import_mujoco()
    spec = arm_spec(robot)
    spec.modelname = "scone_kitchen"
    spec.compiler.autolimits = True
    _matte(spec)
    # The URDF's geoms need unique names for the contact pairs.
    for k, geom in enumerate(spec.geoms):
        if not geom.name:
            geom.name = f"{geom.parent.name}_geom{k}"
    _add_arm(spec, robot, gains)
    boxes = static_boxes(kitchen)
    _add_scene(spec, kitchen, boxes)
    for i, product in enumerate(products):
        _add_product(spec, product, i)
    _finger_pairs(spec, robot, products)
    _product_pairs(spec, products)
    substeps = max(1, int(np.ceil(time_step / SUBSTEP_S - 1e-9)))
    spec.option.timestep = time_step / substeps
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    # MuJoCo's soft contacts let a held product creep through the fingers under the carry's accelerations (a
    # 0.35 kg jar slid 1.6 cm in 3 s with four times its weight in friction to spare); the no-slip pass removes
    # that creep, as Bullet's rigid friction has none.
    spec.option.noslip_iterations = NOSLIP_ITERATIONS
    spec.option.gravity = [0.0, 0.0, -9.81]
    if hasattr(mujoco.mjtEnableBit, "mjENBL_SLEEP"):
        # Resting products sleep until something awake touches them (MuJoCo 3.4+): most products stand still
        # on the shelf all episode, and their contacts are most of the solver's work (PyBullet's kitchen freezes
        # them for the same reason).
        spec.option.enableflags |= int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    width = max(c.width for c in kitchen.cameras)
    height = max(c.height for c in kitchen.cameras)
    spec.visual.global_.offwidth = int(width)
    spec.visual.global_.offheight = int(height)
    # No multisampling: PyBullet's TinyRenderer has none either, and resolving 4 samples made reading an image
    # back cost more than drawing it on the software renderer.
    spec.visual.quality.offsamples = 0
    # A soft, mostly ambient light without highlights (as PyBullet's renders: white lids must not bleach).
    spec.visual.headlight.ambient = [0.6, 0.6, 0.6]
    spec.visual.headlight.diffuse = [0.4, 0.4, 0.4]
    spec.visual.headlight.specular = [0.0, 0.0, 0.0]
    light = spec.worldbody.add_light()
    light.name = "ceiling"
    light.pos = [0.3, 0.2, 3.0]
    light.dir = [-0.3, -0.2, -1.0]
    light.diffuse = [0.0, 0.0, 0.0]
    light.specular = [0.0, 0.0, 0.0]
    light.ambient = [0.0, 0.0, 0.0]
    light.castshadow = False
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ConfigError(f"MuJoCo could not compile the kitchen model ({str(exc).strip()})") from None
    first_arm_body = model.jnt_bodyid[model.joint(robot.arm_joints[0]).id]
    root = spec.body(model.body(model.body_parentid[first_arm_body]).name)
    ipos, iquat = (float(c) for c in root.ipos), (float(c) for c in root.iquat)
    parts = ModelParts(
        tuple(boxes),
        tuple(p.name for p in products),
        tuple(c.name for c in kitchen.cameras),
        root_inertial=(tuple(ipos), tuple(iquat)),  # type: ignore[arg-type]
    )
    return model, parts
