"""The suite's own habits: the slow list in conftest names tests that exist (a renamed test
would silently drop out of it), and no test module imports another (shared code lives in
tests/helpers/)."""

import ast
from pathlib import Path

import conftest

HERE = Path(__file__).resolve().parent
MODULES = sorted(HERE.glob("test_*.py"))


def _functions(path):
    return {
        node.name
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.FunctionDef)
    }


def test_every_slow_entry_names_a_test():
    for entry in conftest.SLOW:
        module, _, test = entry.partition("::")
        assert (HERE / module).is_file(), f"conftest.SLOW: no tests/{module}"
        assert not test or test in _functions(HERE / module), f"conftest.SLOW: no {entry}"


def test_no_test_module_imports_another():
    names = {p.stem for p in MODULES}
    for path in MODULES:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imported = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                imported = [node.module.split(".")[0]]
            else:
                continue
            assert not set(imported) & names, (
                f"{path.name} imports {imported}: move what it shares to tests/helpers/"
            )
