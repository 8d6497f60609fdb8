"""The import graph of scone_bt, read with `ast` (imports at module level and inside functions alike).

- No cycle between subpackages (scone_bt.X ↔ scone_bt.Y, through any chain), nor between modules, inside a
  package included: a submodule that imports a name from its own package's `__init__` (which re-exports its
  submodules) is an edge like any other.
- No submodule imports its own package's `__init__`: it imports from the submodule that defines the name. The
  `__init__` re-exports are for users of the package (`from scone_bt.motion import MotionSystem`).
- No stage of the robot imports the command line, the benchmarks or the study: the lab bench sits on top of the
  product, never inside it.

Imports under `if TYPE_CHECKING:` are left out (they never run). Importing a submodule initialises its parent
packages first; that implicit edge is left out too, so that a package may re-export its submodules.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import scone_bt

PACKAGE = Path(scone_bt.__file__).resolve().parent

# The stages of the robot and what they run on; the lab bench (cli, benchmarks, instruction_following, study,
# scenario) may import them, never the reverse.
STAGES = (
    "affordances",
    "behaviours",
    "confidence",
    "config",
    "distributed",
    "embedding",
    "episode",
    "events",
    "experience",
    "gate",
    "human",
    "motion",
    "perception",
    "recipes",
    "relevance",
    "robot",
    "stocking",
    "tree",
    "trust",
    "viz",
    "world",
)
LAB_BENCH = ("cli", "benchmarks", "instruction_following", "study", "scenario")

# Known upward imports, left out of the cycle check until an issue removes them. The test fails when one of them is
# gone, so that this list only shrinks. (Issue 30's backend seam removed perception → world: the marker layout and
# the footprints now live in config.)
KNOWN_UPWARD: set[tuple[str, str]] = set()


def _module_name(path: Path) -> str:
    parts = ["scone_bt", *path.relative_to(PACKAGE).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "_data" not in p.parts}


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _imports(tree: ast.AST) -> Iterator[ast.Import | ast.ImportFrom]:
    """Every import statement, in functions too, but not under `if TYPE_CHECKING:`."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and _is_type_checking(node):
            yield from (n for child in node.orelse for n in _imports_in(child))
            continue
        yield from _imports_in(node)


def _imports_in(node: ast.AST) -> Iterator[ast.Import | ast.ImportFrom]:
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        yield node
    else:
        yield from _imports(node)


def _targets(module: str, path: Path, node: ast.Import | ast.ImportFrom, known: set[str]) -> Iterator[str]:
    if isinstance(node, ast.Import):
        yield from (a.name for a in node.names)
        return
    if node.level:
        package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
        base = ".".join([*package[: len(package) - node.level + 1], *([node.module] if node.module else [])])
    else:
        base = node.module or ""
    for alias in node.names:
        sub = f"{base}.{alias.name}"
        yield sub if sub in known else base  # `from pkg import submodule` imports the submodule


def module_graph() -> dict[str, dict[str, list[str]]]:
    """module → imported scone_bt module → where ("file:line"); `from pkg import sub` is an edge to pkg.sub."""
    modules = _modules()
    known = set(modules)
    graph: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for node in _imports(tree):
            for target in _targets(module, path, node, known):
                while target not in known and "." in target:  # `import a.b.name` of a non-module: its module
                    target = target.rsplit(".", 1)[0]
                if target not in known or target == module:
                    continue
                where = f"{path.relative_to(PACKAGE.parent)}:{node.lineno}"
                if where not in graph[module][target]:
                    graph[module][target].append(where)
    return graph


def _subpackage(module: str) -> str:
    return module.split(".")[1] if "." in module else ""


def subpackage_graph() -> dict[str, dict[str, list[str]]]:
    """scone_bt.X → scone_bt.Y (X ≠ Y) → the import lines behind the edge."""
    out: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for module, targets in module_graph().items():
        for target, where in targets.items():
            a, b = _subpackage(module), _subpackage(target)
            if a and b and a != b:
                out[a][b].extend(w for w in where if w not in out[a][b])
    return out


def cycles(graph: dict[str, dict[str, list[str]]]) -> list[list[str]]:
    """The strongly connected components with more than one node (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def _describe(graph: dict[str, dict[str, list[str]]], component: list[str]) -> str:
    members = set(component)
    lines = [" ↔ ".join(component) + ":"]
    for a in component:
        for b, where in sorted(graph.get(a, {}).items()):
            if b in members:
                lines.append(f"  {a} → {b}  ({', '.join(where[:4])}{' …' if len(where) > 4 else ''})")
    return "\n".join(lines)


def test_the_graph_sees_imports_inside_functions_and_skips_type_checking():
    graph = module_graph()
    # cli/run.py imports the tablet UI inside a function
    assert "scone_bt.study.ui" in graph["scone_bt.cli.run"]
    # world/arm_io.py names Kitchen only under TYPE_CHECKING
    assert "scone_bt.world.kitchen" not in graph["scone_bt.world.arm_io"]
    assert "scone_bt.world.arm_io" in graph["scone_bt.world.kitchen"]


def test_no_import_cycle_between_subpackages():
    graph = subpackage_graph()
    missing = sorted(edge for edge in KNOWN_UPWARD if edge[1] not in graph.get(edge[0], {}))
    assert not missing, f"these known upward imports are gone; remove them from KNOWN_UPWARD: {missing}"
    for a, b in KNOWN_UPWARD:
        del graph[a][b]
    found = cycles(graph)
    assert not found, "import cycles between subpackages of scone_bt:\n" + "\n".join(
        _describe(graph, c) for c in found
    )


def test_no_import_cycle_between_modules():
    graph = module_graph()
    found = cycles(graph)
    assert not found, "import cycles between modules of scone_bt:\n" + "\n".join(
        _describe(graph, c) for c in found
    )


def typed_module_graph() -> dict[str, dict[str, list[str]]]:
    """As `module_graph`, with the imports under `if TYPE_CHECKING:` too."""
    modules = _modules()
    known = set(modules)
    graph: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for module, path in modules.items():
        for node in _every_import(path):
            for target in _targets(module, path, node, known):
                while target not in known and "." in target:
                    target = target.rsplit(".", 1)[0]
                if target in known and target != module:
                    graph[module][target].append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    return graph


def test_no_cycle_even_through_type_only_imports():
    # Even the types point one way: where an owner hands itself to its helpers (a simulated kitchen to its arm I/O
    # and cameras, the simulated robot to the test rig), the helpers name a Protocol of what they read
    # (`world.parts`, `robot.rig.RigRobot`), not the owner's class.
    graph = typed_module_graph()
    found = cycles(graph)
    assert not found, (
        "import cycles between modules of scone_bt, TYPE_CHECKING imports included:\n"
        + "\n".join(_describe(graph, c) for c in found)
    )


def own_package_imports() -> list[str]:
    """'module → package (file:line)' for each import of a module's own (parent or higher) package `__init__`."""
    return sorted(
        f"  {module} → {target}  ({', '.join(where)})"
        for module, targets in module_graph().items()
        for target, where in targets.items()
        if module.startswith(target + ".") and target != "scone_bt"
    )


def test_the_cycle_check_sees_a_cycle_through_an_init():
    # a submodule that imports from its package's __init__, which re-exports it, closes a cycle
    graph = {
        "p": {"p.a": ["p/__init__.py:1"], "p.b": ["p/__init__.py:2"]},
        "p.a": {"p": ["p/a.py:3"]},
        "p.b": {},
    }
    assert cycles(graph) == [["p", "p.a"]]
    assert "p.a → p  (p/a.py:3)" in _describe(graph, ["p", "p.a"])


def test_no_module_imports_its_own_package_init():
    found = own_package_imports()
    assert not found, (
        "modules import their own package's __init__; import from the submodule that defines the name:\n"
        + "\n".join(found)
    )


def test_no_stage_imports_the_lab_bench():
    graph = subpackage_graph()
    bad = [
        f"  scone_bt.{stage} → scone_bt.{bench}  ({', '.join(graph[stage][bench])})"
        for stage in STAGES
        for bench in LAB_BENCH
        if bench in graph.get(stage, {})
    ]
    assert not bad, "stages of the robot import the command line, a benchmark or the study:\n" + "\n".join(
        bad
    )


def test_every_subpackage_is_a_stage_or_on_the_bench():
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file() and p.name != "_data"}
    unclassified = packages - set(STAGES) - set(LAB_BENCH)
    assert not unclassified, f"classify the new subpackages in STAGES or LAB_BENCH: {sorted(unclassified)}"


# The simulated backends' modules, the stage modules that may build a simulated kitchen (`scone_bt.world`): PyBullet's
# (``--robot sim``) and MuJoCo's (``--robot mujoco``).
SIM_BACKENDS = frozenset({"scone_bt.robot.sim", "scone_bt.robot.mujoco_sim"})


def test_only_the_sim_backend_imports_the_simulated_world():
    found = sorted(
        (module, target)
        for module, targets in module_graph().items()
        for target in targets
        if _subpackage(module) in STAGES
        and _subpackage(module) != "world"
        and _subpackage(target) == "world"
        and module not in SIM_BACKENDS
    )
    assert not found, (
        "stages import the simulated world (only robot/sim.py and robot/mujoco_sim.py, behind the backend "
        "registry, may):\n" + "\n".join(f"  {m} → {t}  ({', '.join(module_graph()[m][t])})" for m, t in found)
    )


def _every_import(path: Path) -> Iterator[ast.Import | ast.ImportFrom]:
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    yield from (n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom)))


def test_perception_never_names_the_simulated_world():
    # perception runs on real cameras too: not even a type of it comes from the simulated kitchen
    modules = _modules()
    found = [
        f"  {module} → {target}  ({modules[module].relative_to(PACKAGE.parent)}:{node.lineno})"
        for module, path in modules.items()
        if _subpackage(module) == "perception"
        for node in _every_import(path)
        for target in _targets(module, path, node, set(modules))
        if _subpackage(target) == "world"
    ]
    assert not found, "perception imports the simulated world (TYPE_CHECKING included):\n" + "\n".join(found)


# The simulator backend (`scone-run --robot sim`): the simulated kitchen package and the backend module that builds
# it. These modules, and no other, may import the simulator's packages; docs/robot_interface.md names the same list.
SIM_BACKEND_MODULES = frozenset(
    {
        "scone_bt.world",
        "scone_bt.world.arm_io",
        "scone_bt.world.camera",
        "scone_bt.world.kitchen",
        "scone_bt.world.render_cache",
        "scone_bt.world.visuals",
        "scone_bt.robot.sim",
    }
)
SIMULATOR_PACKAGES = ("pybullet", "pybullet_data", "pybullet_utils", "pybullet_envs")


def _external_imports(path: Path) -> Iterator[tuple[str, int]]:
    """(top-level package, line) of every absolute import in the file, TYPE_CHECKING blocks left out."""
    for node in _imports(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            yield from ((a.name.split(".")[0], node.lineno) for a in node.names)
        elif not node.level and node.module:
            yield node.module.split(".")[0], node.lineno


def simulator_imports() -> dict[str, list[str]]:
    """scone_bt module → 'package (file:line)' for each import of a simulator package."""
    found: dict[str, list[str]] = defaultdict(list)
    for module, path in _modules().items():
        for package, line in _external_imports(path):
            if package in SIMULATOR_PACKAGES:
                found[module].append(f"{package} ({path.relative_to(PACKAGE.parent)}:{line})")
    return found


def test_the_simulator_scan_sees_the_sim_backend():
    assert set(_modules()) >= SIM_BACKEND_MODULES, "SIM_BACKEND_MODULES names a module that is gone"
    found = simulator_imports()
    # the kitchen connects to PyBullet inside a function; the scan must see that import
    assert any(i.startswith("pybullet ") for i in found["scone_bt.world.kitchen"])


def test_only_the_sim_backend_imports_pybullet():
    outside = {m: where for m, where in simulator_imports().items() if m not in SIM_BACKEND_MODULES}
    assert not outside, "modules outside the sim backend import the simulator:\n" + "\n".join(
        f"  {m}: {', '.join(w)}" for m, w in sorted(outside.items())
    )


# The MuJoCo backend (`scone-run --robot mujoco`): its kitchen, model and cameras, and the backend module. These
# modules, and no other, may import mujoco; none of them imports PyBullet (`test_only_the_sim_backend_imports_pybullet`
# keeps PyBullet out of them, and tests/episode/test_mujoco_episode.py checks both at run time).
MUJOCO_BACKEND_MODULES = frozenset(
    {
        "scone_bt.world.mj_camera",
        "scone_bt.world.mj_kitchen",
        "scone_bt.world.mj_model",
        "scone_bt.robot.mujoco_sim",
    }
)


def _imports_of(packages: tuple[str, ...]) -> dict[str, list[str]]:
    found: dict[str, list[str]] = defaultdict(list)
    for module, path in _modules().items():
        for package, line in _external_imports(path):
            if package in packages:
                found[module].append(f"{package} ({path.relative_to(PACKAGE.parent)}:{line})")
    return found


def test_only_the_mujoco_backend_imports_mujoco():
    assert set(_modules()) >= MUJOCO_BACKEND_MODULES, "MUJOCO_BACKEND_MODULES names a module that is gone"
    found = _imports_of(("mujoco",))
    assert any(i.startswith("mujoco ") for i in found["scone_bt.world.mj_model"])
    outside = {m: where for m, where in found.items() if m not in MUJOCO_BACKEND_MODULES}
    assert not outside, "modules outside the MuJoCo backend import mujoco:\n" + "\n".join(
        f"  {m}: {', '.join(w)}" for m, w in sorted(outside.items())
    )


def test_the_mujoco_backend_never_imports_pybullet():
    found = simulator_imports()
    assert not {m: w for m, w in found.items() if m in MUJOCO_BACKEND_MODULES}
