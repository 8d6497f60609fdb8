"""`Fields`: typed reads from one mapping of a config file, checked by pydantic, one line naming the key path."""

from __future__ import annotations

import math

import pytest

from scone_bt.config.yaml_io import Fields
from scone_bt.errors import ConfigError

F = Fields(
    {"n": 3, "x": 2, "name": "a", "flag": True, "v": [1, 2.5, 3], "sub": {"k": 1}, 5: "odd"}, "k.yaml:scene"
)


def test_values_of_the_right_type_come_back_an_int_counting_as_a_float():
    assert F.get("n", int) == 3 and F.get("name", str) == "a" and F.get("flag", bool) is True
    x = F.get("x", float)
    assert x == 2.0 and isinstance(x, float)
    assert F.get("x", (int, str)) == 2
    assert F.vector("v", 3) == (1.0, 2.5, 3.0)
    assert F.get("absent", float, 0.5) == 0.5 and F.vector("absent", 3, (0.0, 0.0, 1.0)) == (0.0, 0.0, 1.0)
    assert F.sub("sub").get("k", int) == 1 and F.sub("sub").where == "k.yaml:scene.sub"


@pytest.mark.parametrize(
    ("read", "message"),
    [
        (lambda: F.get("name", float), "k.yaml:scene.name: expected float, got 'a'"),
        (lambda: F.get("flag", int), "k.yaml:scene.flag: expected int, got True"),  # a bool is not a count
        (lambda: F.get("x", str), "k.yaml:scene.x: expected str, got 2"),
        (lambda: F.get("n", (str, list)), "k.yaml:scene.n: expected str/list, got 3"),
        (lambda: F.vector("name"), "k.yaml:scene.name: expected list, got 'a'"),
        (lambda: F.vector("v", 2), "k.yaml:scene.v: expected 2 numbers, got 3"),
        (lambda: F.sub("n"), "k.yaml:scene.n: expected dict, got 3"),
        (
            lambda: F.get("gone", int),
            "k.yaml:scene: missing key 'gone'; present: n, x, name, flag, v, sub, 5",
        ),
    ],
)
def test_a_wrong_value_is_one_line_naming_the_key_path(read, message):
    with pytest.raises(ConfigError) as err:
        read()
    assert str(err.value) == message


@pytest.mark.parametrize("bad", [["1", 2], [True, 2], [math.nan, 1], [1, None]])
def test_a_vector_holds_finite_numbers_only(bad):
    with pytest.raises(ConfigError, match=r"^k\.yaml:scene\.v: expected a list of numbers, got "):
        Fields({"v": bad}, "k.yaml:scene").vector("v")
