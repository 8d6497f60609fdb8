"""The documentation site's reference pages, generated from the code each time `mkdocs build` runs.

mkdocs-gen-files runs this script (mkdocs.yml, `plugins: gen-files`); it writes three virtual pages into the
site: `reference/cli.md` (every command's `--help`, from the real argparse parsers), `reference/config.md` (every
key of the configuration files, from the pydantic models) and `reference/scenario-schema.md` (the scenario file's
JSON Schema), and `changelog.md` from CHANGELOG.md. Nothing is copied by hand, so the pages cannot drift from the code. Run it alone to print them:
`python tools/docs_reference.py` (no network; it imports scone_bt only).
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import os
import pkgutil
import sys
import types
import typing
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # mkdocs runs from the checkout; its scone_bt, not an installed copy
    sys.path.insert(0, str(ROOT))

__all__ = ["cli_page", "config_page", "scenario_schema_page", "PAGES"]

# (command, module, the parser functions that module may define: the first one found is used)
COMMANDS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("scone-run", "scone_bt.cli.run", ("build_parser", "_parser")),
    ("scone-scenario", "scone_bt.scenario.cli", ("build_parser", "_parser")),
    ("scone-bench", "scone_bt.cli.bench", ("build_parser", "_parser")),
    ("scone-study", "scone_bt.study.cli", ("build_parser", "_parser")),
    ("scone-models", "scone_bt.cli.models", ("build_parser", "_parser")),
)


def _parser_of(module: str, names: tuple[str, ...]) -> argparse.ArgumentParser:
    mod = importlib.import_module(module)
    for name in names:
        make = getattr(mod, name, None)
        if callable(make):
            return make()
    raise SystemExit(f"docs_reference: {module} defines none of {', '.join(names)}; update COMMANDS")


def _walk(parser: argparse.ArgumentParser, path: str) -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """The parser and every subcommand's parser below it, depth first, with the command line that reaches it."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _walk(sub, f"{path} {name}")


def cli_page() -> str:
    """Every command's and subcommand's `--help`, as argparse prints it at 100 columns."""
    os.environ["COLUMNS"] = "100"  # the same wrapping on every machine
    out = [
        "# Command line",
        "",
        "Generated at build time from the commands' own argparse parsers: what `--help` prints. Each command is",
        "installed into `.venv/bin` by `make`; `python -m scone_bt.cli.run` and so on work too.",
        "",
    ]
    for command, module, names in COMMANDS:
        out += [f"## {command}", ""]
        for path, parser in _walk(_parser_of(module, names), command):
            if path != command:
                out += [f"### {path}", ""]
            parser.prog = path
            out += ["```text", parser.format_help().rstrip(), "```", ""]
    from scone_bt.environment import VARIABLES

    out += [
        "## Environment variables",
        "",
        "Every command checks these as it reads its command line: a bad value is one line before any work.",
        "",
        "| variable | meaning |",
        "|---|---|",
        *(f"| `{name}` | {meaning} |" for name, meaning in VARIABLES.items()),
        "",
    ]
    return "\n".join(out)


# ---------------------------------------------------------------------------------------------- config keys
# The files a user edits, each with the model that validates it; every other model of scone_bt.config follows.
FILE_MODELS: tuple[tuple[str, str, str, str, str, tuple[str, ...]], ...] = (
    # (title, module, model, what the file is, the shipped file whose comments describe the keys, its section)
    (
        "Tree parameters",
        "scone_bt.config.tree_parameters",
        "TreeParameters",
        "The `parameters:` section of a tree file (`trees/assistive_cooking.yaml`): the robot's decision "
        "defaults. `scone-run`'s flags override them for one run.",
        "trees/assistive_cooking.yaml",
        ("parameters",),
    ),
    (
        "Robot file",
        "scone_bt.config.robot",
        "RobotFile",
        "`robots/<name>.yaml`: the arm, its gripper and planner.",
        "robots/panda.yaml",
        (),
    ),
    (
        "Grasp section",
        "scone_bt.config.grasp",
        "_GraspSection",
        "The `grasp:` section of a robot file; every key is optional.",
        "robots/panda.yaml",
        ("grasp",),
    ),
    (
        "Catalogue family file",
        "scone_bt.config.catalogue",
        "_FamilyFile",
        "`perception/catalogue/<family>.yaml`, and a file given to `--catalogue`: products and their defaults.",
        "",
        (),
    ),
)


def yaml_comments(path: Path) -> dict[tuple[str, ...], str]:
    """Each key's comment in a shipped YAML file, by its path of keys: the comment at the end of its line, else
    the comment lines just above it (at its indentation). The shipped files explain every key this way."""
    found: dict[tuple[str, ...], str] = {}
    stack: list[tuple[int, str]] = []
    above: list[str] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        text = line.strip()
        indent = len(line) - len(line.lstrip())
        if text.startswith("#"):
            above.append(text.lstrip("#").strip())
            continue
        head = text.split("#", 1)[0]
        if not text or text.startswith("-") or ":" not in head:
            above = []
            continue
        key = head.split(":", 1)[0].strip()
        while stack and stack[-1][0] >= indent:
            stack.pop()
        stack.append((indent, key))
        trailing = text.split(" #", 1)[1].strip() if " #" in text else ""
        words = trailing or " ".join(above)
        if words:
            found[tuple(k for _, k in stack)] = words
        above = []
    return found


def _type_name(annotation: Any) -> str:
    """A field's type as a reader writes it: `float`, `list[str]`, `"budget" | "paper"`."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        return _type_name(args[0])
    if origin is typing.Literal:
        return " | ".join(json.dumps(a) for a in args)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in args)
    if origin is not None:
        name = getattr(origin, "__name__", str(origin))
        return f"{name}[{', '.join(_type_name(a) for a in args)}]" if args else name
    if annotation is type(None):
        return "null"
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return f"[{_title(annotation)}](#{_anchor(annotation)})"
    return getattr(annotation, "__name__", str(annotation))


def _constraints(field: FieldInfo) -> str:
    """The bounds pydantic enforces (`>= 0`, `<= 1`, `1..32 items`), from the field's metadata."""
    words = []
    lo = hi = None
    for meta in field.metadata:
        for attr, sign in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(meta, attr, None)
            if value is not None:
                words.append(f"{sign} {value}")
        lo = getattr(meta, "min_length", None) if getattr(meta, "min_length", None) is not None else lo
        hi = getattr(meta, "max_length", None) if getattr(meta, "max_length", None) is not None else hi
    if lo is not None or hi is not None:
        words.append(f"{lo or 0}..{hi if hi is not None else '∞'} items")
    return ", ".join(words)


def _default(field: FieldInfo) -> str:
    if field.is_required():
        return "**required**"
    value = (
        field.get_default(call_default_factory=True) if field.default is PydanticUndefined else field.default
    )
    if isinstance(value, BaseModel):
        return "(its keys' defaults)"
    return f"`{json.dumps(value, default=str)}`"


def _title(model: type[BaseModel]) -> str:
    return model.__name__.lstrip("_")


def _anchor(model: type[BaseModel]) -> str:
    return f"{model.__module__.rsplit('.', 1)[-1]}-{_title(model)}".lower().replace("_", "-")


def _nested(annotation: Any) -> Iterator[type[BaseModel]]:
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        yield annotation
    for arg in typing.get_args(annotation):
        yield from _nested(arg)


def _model_table(
    model: type[BaseModel],
    doc: str,
    comments: dict[tuple[str, ...], str] | None = None,
    at: tuple[str, ...] = (),
) -> list[str]:
    comments = comments or {}
    out = [f"### {_title(model)} {{ #{_anchor(model)} }}", "", f"`{model.__module__}.{model.__name__}`", ""]
    if doc:
        out += [doc, ""]
    own = inspect.cleandoc(model.__dict__.get("__doc__") or "")  # its own docstring, not its base's
    if own:
        out += [own.split("\n\n")[0], ""]
    out += ["| key | type | bounds | default | description |", "|---|---|---|---|---|"]
    for name, field in model.model_fields.items():
        key = field.alias or name
        text = (field.description or comments.get((*at, key), "")).replace("|", "\\|").replace("\n", " ")
        kind = _type_name(field.annotation).replace("|", "\\|")
        out.append(f"| `{key}` | {kind} | {_constraints(field)} | {_default(field)} | {text} |")
    return out + [""]


def _config_models() -> list[type[BaseModel]]:
    """Every pydantic model defined in a module of scone_bt.config, in module and source order."""
    import scone_bt.config as package

    found: list[type[BaseModel]] = []
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda i: i.name):
        module = importlib.import_module(f"scone_bt.config.{info.name}")
        for value in vars(module).values():
            if (
                inspect.isclass(value)
                and issubclass(value, BaseModel)
                and value.__module__ == module.__name__
                and value not in found
            ):
                found.append(value)
    return found


def config_page() -> str:
    """Every key of every configuration file, from the pydantic models that validate them."""
    out = [
        "# Configuration keys",
        "",
        "Generated at build time from the pydantic models that validate each file (`scone_bt/config/`). A key",
        'outside these tables, a wrong type (no `"3"` for 3, no `true` for 1), a value out of bounds or a NaN is',
        "one line naming the file, the key and what is allowed. Units are SI (metres, radians, seconds, kilograms,",
        "newtons) unless the key says otherwise (`_deg`, `_hz`).",
        "",
        "The kitchen file (`perception/kitchen.yaml`) and the scenario files have their own pages:",
        "[scenarios](../scenarios.md) and the [scenario schema](scenario-schema.md).",
        "",
        "## The files you edit",
        "",
    ]
    shown: list[type[BaseModel]] = []
    Entry = tuple[type[BaseModel], str, dict[tuple[str, ...], str], tuple[str, ...]]
    queue: list[Entry] = []
    for title, module, name, doc, shipped, section in FILE_MODELS:
        model = getattr(importlib.import_module(module), name, None)
        if model is None:
            raise SystemExit(f"docs_reference: {module}.{name} is gone; update FILE_MODELS")
        comments = yaml_comments(ROOT / shipped) if shipped else {}
        queue.append((model, f"**{title}.** {doc}", comments, section))
    while queue:
        model, doc, comments, at = queue.pop(0)
        if model in shown:
            continue
        shown.append(model)
        out += _model_table(model, doc, comments, at)
        inner_entries: list[Entry] = []
        for key, field in model.model_fields.items():
            for inner in _nested(field.annotation):
                if inner not in shown:
                    where = " · ".join((*at, field.alias or key))
                    inner_entries.append(
                        (inner, f"The `{where}` section of {_title(model)}.", comments, (*at, key))
                    )
        queue[:0] = inner_entries
    rest = [m for m in _config_models() if m not in shown and m.model_fields]
    if rest:
        out += ["## Other validated sections", ""]
        for model in rest:
            out += _model_table(model, "")
    return "\n".join(out)


def scenario_schema_page() -> str:
    """The scenario file's JSON Schema: each object's keys as a table, then the whole schema."""
    from scone_bt.scenario.model import json_schema

    schema = json_schema()
    out = [
        "# Scenario schema",
        "",
        "Generated at build time from the scenario model (`scone_bt.scenario.model`); the same schema that",
        "`scone-scenario schema` prints and `scenarios/scenario.schema.json` holds for editors. What each key means,",
        "with examples: [Scenario tests](../scenarios.md).",
        "",
    ]
    objects = {"ScenarioFile": schema, **schema.get("$defs", {})}
    for name, part in objects.items():
        props = part.get("properties")
        if not props:
            continue
        required = set(part.get("required", ()))
        out += [f"## {name}", ""]
        if part.get("description"):
            out += [part["description"].split("\n\n")[0], ""]
        out += ["| key | type | default |", "|---|---|---|"]
        for key, spec in props.items():
            default = "**required**" if key in required else f"`{json.dumps(spec.get('default'))}`"
            out.append(f"| `{key}` | {_schema_type(spec)} | {default} |")
        out.append("")
    out += ["## The whole schema", "", "```json", json.dumps(schema, indent=2), "```", ""]
    return "\n".join(out)


def _schema_type(spec: dict[str, Any]) -> str:
    if "$ref" in spec:
        name = spec["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{name.lower()})"
    for key in ("anyOf", "oneOf"):
        if key in spec:
            return " \\| ".join(_schema_type(s) for s in spec[key])
    if "const" in spec:
        return f"`{json.dumps(spec['const'])}`"
    if "enum" in spec:
        return " \\| ".join(f"`{json.dumps(v)}`" for v in spec["enum"])
    kind = spec.get("type", "any")
    if kind == "array":
        return f"list of {_schema_type(spec.get('items', {}))}"
    if kind == "object" and isinstance(spec.get("additionalProperties"), dict):
        return f"map of {_schema_type(spec['additionalProperties'])}"
    return str(kind)


def changelog_page() -> str:
    """CHANGELOG.md of the checkout, which lives beside README.md, outside docs/."""
    return (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")


PAGES: dict[str, Callable[[], str]] = {
    "changelog.md": changelog_page,
    "reference/cli.md": cli_page,
    "reference/config.md": config_page,
    "reference/scenario-schema.md": scenario_schema_page,
}


def _write_with_gen_files() -> None:
    import mkdocs_gen_files

    for path, make in PAGES.items():
        with mkdocs_gen_files.open(path, "w") as f:
            f.write(make())


if __name__ == "__main__":
    for path, make in PAGES.items():
        print(f"<!-- {path} -->\n{make()}")
elif __name__ == "<run_path>":  # run by mkdocs-gen-files (runpy.run_path) during `mkdocs build`
    _write_with_gen_files()
