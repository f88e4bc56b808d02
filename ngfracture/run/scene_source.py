"""Where a scene comes from: a built-in name, a Python file, or ``package.module:function``.

The command line (``ngfracture run SCENE --set NAME=VALUE``) and anything else that
starts runs by name use these three functions:

* :func:`load_scene_function` turns a spec into the function that builds the Scene;
* :func:`scene_parameters` lists that function's parameters with their defaults;
* :func:`parse_assignments` turns ``NAME=VALUE`` strings into keyword arguments, each
  value converted by the type of the parameter's default.

A scene file is a Python file that defines ``scene(**params)`` returning a
:class:`ngfracture.run.scene.Scene`; every parameter needs a default, so that the file
runs without any ``--set``.
"""
import ast
import hashlib
import importlib
import importlib.util
import inspect
import os
import sys

#: the function a scene file must define
SCENE_FUNCTION = "scene"


def builtin_scenes():
    """The built-in scenes by name.

    Returns
    -------
    dict of str -> callable
        ``plate``, ``disk``, ``disintegration`` (:mod:`ngfracture.scenes`).
    """
    from ..scenes import SCENES
    return dict(SCENES)


def load_scene_function(spec):
    """The function that builds the scene named by ``spec``.

    Parameters
    ----------
    spec : str
        A built-in scene name (see :func:`builtin_scenes`); a path to a Python file
        (ending in ``.py``) that defines ``scene(**params)``; or ``package.module:function``
        importable from ``sys.path``.

    Returns
    -------
    callable
        Called with keyword arguments, it returns a Scene.

    Raises
    ------
    ValueError
        Naming ``spec``: an unknown name, a missing file, a file or module that does not
        import, or that has no such function, or an attribute that is not callable.
    """
    if not isinstance(spec, str) or not spec:
        raise ValueError(f"a scene is a built-in name, a .py file or package.module:function, got {spec!r}")
    builtins = builtin_scenes()
    if spec in builtins:
        return builtins[spec]
    if spec.endswith(".py") or os.sep in spec or (os.altsep and os.altsep in spec):
        return _from_file(spec)
    if ":" in spec:
        return _from_module(spec)
    raise ValueError(f"unknown scene {spec!r}: the built-in scenes are {', '.join(sorted(builtins))}; "
                     f"or give a file path/to/scene.py defining {SCENE_FUNCTION}(**params), "
                     f"or package.module:function")


def _from_file(path):
    if not os.path.isfile(path):
        raise ValueError(f"scene file {path!r} does not exist")
    # a module name of its own per file (two scene files never share one), registered in
    # sys.modules so that dataclasses and pickling inside the file find their module
    digest = hashlib.sha1(os.path.abspath(path).encode()).hexdigest()[:12]
    name = f"_ngfracture_scene_{digest}"
    module_spec = importlib.util.spec_from_file_location(name, path)
    if module_spec is None:
        raise ValueError(f"scene file {path!r} is not a Python file")
    module = importlib.util.module_from_spec(module_spec)
    sys.modules[name] = module
    try:
        module_spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise ValueError(f"scene file {path!r} failed to import: {type(exc).__name__}: {exc}") from exc
    func = getattr(module, SCENE_FUNCTION, None)
    if not callable(func):
        raise ValueError(f"scene file {path!r} defines no function {SCENE_FUNCTION}(**params) "
                         f"that returns a Scene")
    return func


def _from_module(spec):
    module_name, _, attr = spec.partition(":")
    if not module_name or not attr:
        raise ValueError(f"scene {spec!r}: expected package.module:function")
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:
        raise ValueError(f"scene {spec!r}: module {module_name!r} failed to import: "
                         f"{type(exc).__name__}: {exc}") from exc
    func = module
    for part in attr.split("."):
        func = getattr(func, part, None)
        if func is None:
            raise ValueError(f"scene {spec!r}: module {module_name!r} has no attribute {attr!r}")
    if not callable(func):
        raise ValueError(f"scene {spec!r}: {attr!r} is not callable")
    return func


def scene_parameters(func):
    """The parameters of a scene function with their defaults.

    Parameters
    ----------
    func : callable

    Returns
    -------
    dict of str -> object
        Parameter name -> default value, in the signature's order; a parameter without a
        default maps to ``inspect.Parameter.empty``. ``*args``/``**kwargs`` are left out.
    """
    params = {}
    for p in inspect.signature(func).parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD, p.POSITIONAL_ONLY):
            continue
        params[p.name] = p.default
    return params


def convert_value(name, text, default):
    """``text`` converted to the type of ``default``.

    float and int defaults take a number (an int default also takes ``1e3``-style text
    if it is integral; a float default takes an integer, and ``none`` for None); bool takes
    true/false/yes/no/on/off/1/0; str takes the text itself. A default of None (or no
    default) takes a Python literal (``0.5``, ``None``, ``'text'``, ``(1, 2)``), or
    else the text as a string.

    Parameters
    ----------
    name : str
        The parameter, for the error message.
    text : str
    default : object

    Returns
    -------
    object

    Raises
    ------
    ValueError
        Naming the parameter, the text and the type expected.
    """
    if isinstance(default, bool):
        low = text.strip().lower()
        if low in ("true", "yes", "on", "1"):
            return True
        if low in ("false", "no", "off", "0"):
            return False
        raise ValueError(f"{name}={text}: expected true or false")
    if isinstance(default, int):
        try:
            return int(text)
        except ValueError:
            pass
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{name}={text}: expected an integer") from None
        if value.is_integer():
            return int(value)
        raise ValueError(f"{name}={text}: expected an integer")
    if isinstance(default, float):
        if text.strip().lower() == "none":     # e.g. radius=none: the paper's criterion
            return None
        try:
            return float(text)
        except ValueError:
            raise ValueError(f"{name}={text}: expected a number") from None
    if isinstance(default, str):
        return text
    # None, no default, or another type: a Python literal, else the plain text
    try:
        return ast.literal_eval(text.strip())
    except (ValueError, SyntaxError):
        if default is None or default is inspect.Parameter.empty:
            return text
        raise ValueError(f"{name}={text}: expected a Python literal like {default!r}") from None


def parse_assignments(pairs, func):
    """``NAME=VALUE`` strings as keyword arguments of ``func``.

    Parameters
    ----------
    pairs : iterable of str
        Each ``NAME=VALUE``; a name given twice keeps the last value.
    func : callable
        The scene function; its signature gives the known names and the types.

    Returns
    -------
    dict of str -> object

    Raises
    ------
    ValueError
        A pair without ``=``, an unknown name (the message lists the known ones), or a
        value that does not convert (:func:`convert_value`).
    """
    known = scene_parameters(func)
    takes_any = any(p.kind == p.VAR_KEYWORD for p in inspect.signature(func).parameters.values())
    result = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(f"{pair!r}: expected NAME=VALUE")
        if name not in known and not takes_any:
            listed = ", ".join(known) if known else "none"
            raise ValueError(f"unknown scene parameter {name!r}; the known ones are: {listed}")
        result[name] = convert_value(name, text, known.get(name, inspect.Parameter.empty))
    return result


def format_parameters(func):
    """``name=default`` for every parameter, comma-separated (for listings and --help).

    Parameters
    ----------
    func : callable

    Returns
    -------
    str
    """
    return ", ".join(name if default is inspect.Parameter.empty else f"{name}={default!r}"
                     for name, default in scene_parameters(func).items())


__all__ = ["load_scene_function", "scene_parameters", "parse_assignments", "convert_value",
           "builtin_scenes", "format_parameters"]


def build_scene(make_scene, spec, params):
    """Call a scene function; what goes wrong in it is the user's input, said as such.

    Parameters
    ----------
    make_scene : callable
        The scene function (:func:`load_scene_function`).
    spec : str
        How the user named it (for messages).
    params : dict
        Its keyword arguments.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        The function raised (its exception type and message, and the function named), or
        returned something other than a Scene (what it returned).
    """
    from .scene import Scene
    name = getattr(make_scene, "__qualname__", repr(make_scene))
    try:
        scene = make_scene(**params)
    except Exception as exc:       # noqa: BLE001 - any error of the user's function is bad input
        raise ValueError(f"scene {spec!r}: its function {name}({_call(params)}) raised "
                         f"{type(exc).__name__}: {exc}") from exc
    if not isinstance(scene, Scene):
        raise ValueError(f"scene {spec!r}: its function {name}({_call(params)}) returned "
                         f"{type(scene).__module__}.{type(scene).__qualname__} {_short(scene)}, not an ngfracture Scene")
    return scene


def _call(params):
    return ", ".join(f"{k}={v!r}" for k, v in params.items())


def _short(value):
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
