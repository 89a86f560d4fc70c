"""No two of granular's modules import each other, directly or round a longer circle: every
import is read from the source (ast), at module level, inside functions (an import deferred
to call time hides a circle from Python, not from the design) and under TYPE_CHECKING."""

import ast
from pathlib import Path

import pytest

import granular

SOURCE = Path(granular.__file__).resolve().parent


def _modules():
    """{dotted name: path} of every module of the package (a subpackage is its __init__)."""
    out = {}
    for path in SOURCE.rglob("*.py"):
        parts = path.relative_to(SOURCE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(name, path, modules):
    """The package's modules that module ``name`` imports anywhere in its source."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package
            for _ in range(node.level - 1):
                base = base.rpartition(".")[0]
            if node.level:
                base = f"{base}.{node.module}" if node.module else base
            else:
                base = node.module or ""
            # `from a import b`: the module a.b if there is one, else a
            targets = [
                f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                for alias in node.names
            ]
        else:
            continue
        for target in targets:
            while target and target not in modules:  # granular.theory.x.y -> a module
                target = target.rpartition(".")[0]
            if target:
                found.add(target)
    found.discard(name)
    return found


def _graph():
    modules = _modules()
    # the top package (granular/__init__.py) only hands the public names on; a module that
    # reads granular.__version__ does so at call time, after the package is imported
    graph = {name: _imports(name, path, modules) for name, path in modules.items()}
    graph.pop("granular")
    return {name: {t for t in targets if t != "granular"} for name, targets in graph.items()}


def _circles(graph):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_reader_sees_imports_of_every_kind():
    """The graph has the imports this test is about: module-level, in a function, under
    TYPE_CHECKING, relative from a subpackage."""
    graph = _graph()
    assert "granular._core" not in graph  # the extension: no source
    assert "granular.scene" in graph["granular.simulation"]  # module level
    assert "granular.restitution" in graph["granular.clustering"]  # TYPE_CHECKING / function
    assert "granular.restitution" in graph["granular.theory.viscoelastic"]  # from ..
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_module_imports_itself_round_a_circle():
    circles = _circles(_graph())
    if circles:
        graph = _graph()
        ties = [
            f"{a} -> {b}" for circle in circles for a in circle for b in graph[a] if b in circle
        ]
        pytest.fail(
            f"import circles {circles}: {'; '.join(ties)}.  Move what both need to a module "
            "that both can import"
        )
