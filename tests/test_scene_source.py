"""Scenes by name, file or module (ngfracture.run.scene_source), and --set NAME=VALUE parsing."""
import inspect
import re
import textwrap

import pytest

from ngfracture import scenes
from ngfracture.run.scene_source import (convert_value, load_scene_function, parse_assignments,
                                     scene_parameters)


@pytest.mark.parametrize("name", ["plate", "disk", "disintegration"])
def test_builtin_names(name):
    assert load_scene_function(name) is scenes.SCENES[name]


def test_module_function_spec():
    assert load_scene_function("ngfracture.scenes:plate") is scenes.plate


def test_file_spec(tmp_path):
    path = tmp_path / "my.py"
    path.write_text(textwrap.dedent("""
        from dataclasses import dataclass   # a dataclass needs its module in sys.modules

        @dataclass
        class Box:
            a: float = 1.0

        def scene(a=1.0, n=3):
            return Box(a * n)
    """))
    func = load_scene_function(str(path))
    assert func(a=2.0, n=2).a == 4.0
    assert scene_parameters(func) == {"a": 1.0, "n": 3}


@pytest.mark.parametrize("spec,message", [
    ("plat", "unknown scene 'plat': the built-in scenes are bar3d, beam, blocks3d, disintegration, disk, holed_beam, plate, plate3d, shaft3d"),
    ("missing/file.py", "scene file 'missing/file.py' does not exist"),
    ("ngfracture.scenes:nothing", "module 'ngfracture.scenes' has no attribute 'nothing'"),
    ("ngfracture.nomodule:f", "module 'ngfracture.nomodule' failed to import"),
    ("ngfracture.scenes:GLASS", "'GLASS' is not callable"),
    (":f", "expected package.module:function"),
    ("", "a scene is a built-in name"),
])
def test_bad_specs_are_named(spec, message):
    with pytest.raises(ValueError) as exc:
        load_scene_function(spec)
    assert message in str(exc.value)


def test_file_without_scene_or_failing_import(tmp_path):
    nofunc = tmp_path / "nofunc.py"
    nofunc.write_text("x = 1\n")
    with pytest.raises(ValueError, match=r"nofunc.py' defines no function scene\(\*\*params\)"):
        load_scene_function(str(nofunc))
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('boom')\n")
    with pytest.raises(ValueError, match=r"broken.py' failed to import: RuntimeError: boom"):
        load_scene_function(str(broken))


def test_scene_parameters_of_the_plate():
    params = scene_parameters(scenes.plate)
    defaults = {k: v.default for k, v in inspect.signature(scenes.plate).parameters.items()}
    assert params == defaults
    assert params["maxh"] == 0.034


def test_parse_assignments_converts_by_the_default_type():
    def f(x=1.0, n=2, flag=False, label="a", opt=None, free=None):
        pass
    got = parse_assignments(["x=2", "n=1e3", "flag=yes", "label=7", "opt=0.25", "free=hello",
                             "x=3.5"], f)
    assert got == {"x": 3.5, "n": 1000, "flag": True, "label": "7", "opt": 0.25, "free": "hello"}
    assert type(got["x"]) is float and type(got["n"]) is int
    assert parse_assignments(["opt=None"], f) == {"opt": None}


@pytest.mark.parametrize("pair,message", [
    ("E=1", "unknown scene parameter 'E'; the known ones are: x, n, flag"),
    ("x", "'x': expected NAME=VALUE"),
    ("=1", "expected NAME=VALUE"),
    ("x=abc", "x=abc: expected a number"),
    ("n=1.5", "n=1.5: expected an integer"),
    ("flag=maybe", "flag=maybe: expected true or false"),
])
def test_bad_assignments_are_named(pair, message):
    def f(x=1.0, n=2, flag=False):
        pass
    with pytest.raises(ValueError) as exc:
        parse_assignments([pair], f)
    assert message in str(exc.value)


def test_every_builtin_parameter_is_reachable():
    for name, func in scenes.SCENES.items():
        for pname, default in scene_parameters(func).items():
            text = "None" if default is None else str(default)
            assert parse_assignments([f"{pname}={text}"], func) == {pname: default}, (name, pname)


def test_convert_value_of_a_tuple_default():
    assert convert_value("size", "(1, 2)", (0, 0)) == (1, 2)
    with pytest.raises(ValueError, match="expected a Python literal"):
        convert_value("size", "x y", (0, 0))


def test_none_switches_a_scene_to_the_papers_criterion():
    """A float parameter takes ``none`` for None: ``--set radius=none`` is the one-ring criterion."""
    assert convert_value("radius", "none", 0.04) is None
    assert convert_value("radius", " None ", 0.04) is None
    assert parse_assignments(["radius=none"], scenes.plate) == {"radius": None}
    assert scenes.plate(maxh=0.2, radius=None).radius is None
    assert scenes.plate(maxh=0.2).radius == scenes.PLATE_RADIUS


@pytest.mark.parametrize("body, message", [
    ("    raise RuntimeError('the mesher is out of paper')",
     r"its function scene\(width=2.0\) raised RuntimeError: the mesher is out of paper"),
    ("    from netgen.geom2d import unit_square\n    import ngsolve\n    return ngsolve.Mesh(unit_square.GenerateMesh(maxh=0.5))",
     r"its function scene\(width=2.0\) returned ngsolve.comp.Mesh .*not an ngfracture Scene"),
])
def test_a_scene_function_that_fails_or_returns_no_scene_is_bad_input(tmp_path, capsys, body, message):
    """Exit status 2 (the user's input), the function and what it did named, no file touched."""
    from ngfracture.cli import main
    path = tmp_path / "faulty.py"
    path.write_text(f"def scene(width=1.0):\n{body}\n")
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main(["run", str(path), "--set", "width=2.0", "--out", str(out), "--progress", "none"])
    assert exc.value.code == 2
    assert re.search(message, capsys.readouterr().err)
    assert not out.exists()
