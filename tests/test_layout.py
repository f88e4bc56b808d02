"""The shape of the package: small functions and modules, no private names across modules,
one C++ module name, and a module map in docs/design.md that lists exactly the modules.

The limits (80 lines per function, 600 per module, docstrings included) are the
project's readability rules, not measurements.
"""
import ast
import re
from pathlib import Path

import ngfracture

PACKAGE = Path(ngfracture.__file__).parent
DESIGN = Path(__file__).resolve().parent.parent / "docs" / "design.md"   # the repository, not the installed package
MAX_FUNCTION_LINES, MAX_MODULE_LINES = 80, 600


def modules():
    return sorted(PACKAGE.rglob("*.py"))


def test_functions_and_modules_are_short():
    long_functions, long_modules = [], []
    for path in modules():
        text = path.read_text()
        if len(text.splitlines()) > MAX_MODULE_LINES:
            long_modules.append((path.name, len(text.splitlines())))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long_functions.append((f"{path.relative_to(PACKAGE)}:{node.name}", n))
    assert not long_functions and not long_modules, (long_functions, long_modules)


def _private_uses(tree):
    """Private names a module imports from, or reads of, another module of the package."""
    imported = set()
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            for alias in node.names:
                if alias.name.startswith("_") and not alias.name.startswith("__") and alias.name != "_ngfracture":
                    found.append(f"from {'.' * node.level}{node.module or ''} import {alias.name}")
                imported.add(alias.asname or alias.name)
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
                and isinstance(node.value, ast.Name) and node.value.id in imported and node.value.id != "_ext"):
            found.append(f"{node.value.id}.{node.attr}")
    return found


def test_no_private_name_crosses_modules():
    found = {str(p.relative_to(PACKAGE)): _private_uses(ast.parse(p.read_text())) for p in modules()}
    assert not {k: v for k, v in found.items() if v}


def test_the_compiled_module_has_one_name():
    for path in modules():
        for line in path.read_text().splitlines():
            if re.search(r"import _ngfracture\b", line) and "import _ngfracture as _ext" not in line:
                raise AssertionError(f"{path.relative_to(PACKAGE)}: {line.strip()}")


def test_the_module_map_lists_every_module():
    text = DESIGN.read_text()
    section = text[text.index("## Module map"):]
    section = section[:section.index("\n## ", 4)] if "\n## " in section[4:] else section
    listed = set(re.findall(r"`ngfracture/([\w/]+\.py)`", section))
    present = {str(p.relative_to(PACKAGE)) for p in modules() if p.name not in ("__init__.py", "__main__.py")}
    assert listed == present, (sorted(present - listed), sorted(listed - present))
