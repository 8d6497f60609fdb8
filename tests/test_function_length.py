"""No function in scone_bt over 80 lines, outside the compiled kernels and the list in
docs/explanation/code-structure.md (which says why each is still long); the list only shrinks."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import scone_bt

PACKAGE = Path(scone_bt.__file__).resolve().parent
ROOT = PACKAGE.parent
PAGE = ROOT / "docs" / "explanation" / "code-structure.md"
LIMIT = 80
"""Lines a function may have, from its `def` (decorators not counted) to its last line."""
EXEMPT = {"scone_bt/motion/compiled.py"}  # numba kernels: one body compiles best
_ROW = re.compile(r"^\| `(?P<name>[^`]+)` \| `(?P<file>[^`]+)` \| (?P<why>.+) \|\s*$")


def _functions(node: ast.AST, prefix: str = "") -> list[tuple[str, int]]:
    """(qualified name, lines) of every function under ``node``, methods as ``Class.method``."""
    out = []
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            name = f"{prefix}{child.name}"
            if not isinstance(child, ast.ClassDef):
                out.append((name, (child.end_lineno or child.lineno) - child.lineno + 1))
            out.extend(_functions(child, name + "."))
        else:
            out.extend(_functions(child, prefix))
    return out


def long_functions() -> dict[tuple[str, str], int]:
    """(file, qualified name) → lines, for every function over LIMIT lines outside EXEMPT."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        file = path.relative_to(ROOT).as_posix()
        if file in EXEMPT or "_data" in path.parts:
            continue
        for name, lines in _functions(ast.parse(path.read_text(encoding="utf-8"), file)):
            if lines > LIMIT:
                found[(file, name)] = lines
    return found


def allowed() -> dict[tuple[str, str], str]:
    """(file, qualified name) → why, from the page's table."""
    rows = (_ROW.match(line) for line in PAGE.read_text(encoding="utf-8").splitlines())
    return {(m["file"], m["name"]): m["why"] for m in rows if m}


def test_the_page_lists_functions_with_a_reason():
    assert PAGE.exists(), f"{PAGE}: the page that lists long functions is gone"
    assert all(why.strip() for why in allowed().values())


def test_the_length_check_sees_a_long_function():
    # the check itself: a function of LIMIT + 1 lines is found, one of LIMIT is not
    body = "\n".join(f"    x{i} = {i}" for i in range(LIMIT - 1))
    short = ast.parse(f"def f():\n{body}\n")
    long = ast.parse(f"def f():\n{body}\n    y = 0\n")
    assert _functions(short) == [("f", LIMIT)]
    assert _functions(long) == [("f", LIMIT + 1)]


def test_no_new_function_over_80_lines():
    new = sorted(set(long_functions()) - set(allowed()))
    assert not new, (
        f"functions over {LIMIT} lines: split them into named steps, or list them with why in "
        f"{PAGE.relative_to(ROOT)}:\n"
        + "\n".join(f"  {f}: {n} ({long_functions()[(f, n)]} lines)" for f, n in new)
    )


def test_the_list_only_shrinks():
    gone = sorted(set(allowed()) - set(long_functions()))
    assert not gone, (
        f"listed in {PAGE.relative_to(ROOT)} but gone or now at most {LIMIT} lines; take them off the list:\n"
        + "\n".join(f"  {f}: {n}" for f, n in gone)
    )
