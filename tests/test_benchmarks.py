"""The scripts in benchmarks/ keep working: each runs at a tiny size (--tiny, seconds) in a
fresh interpreter, and uses only granular's public API, as a user's script would, so that a
change inside the library cannot silently break them."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = sorted((Path(__file__).resolve().parent.parent / "benchmarks").glob("*.py"))


def test_there_are_benchmarks():
    assert BENCHMARKS, "no benchmarks/*.py beside tests/"


@pytest.mark.parametrize("script", BENCHMARKS, ids=lambda p: p.name)
def test_runs_at_a_tiny_size(script, tmp_path):
    done = subprocess.run(
        [sys.executable, str(script), "--tiny"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()


@pytest.mark.parametrize("script", BENCHMARKS, ids=lambda p: p.name)
def test_uses_only_the_public_api(script):
    """No private module or name of granular (a leading underscore: _core, _LIST_SHELL...)."""
    private = []
    for node in ast.walk(ast.parse(script.read_text())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("granular"):
            names = [*node.module.split("."), *(a.name for a in node.names)]
        elif isinstance(node, ast.Import):
            names = [
                part
                for a in node.names
                if a.name.startswith("granular")
                for part in a.name.split(".")
            ]
        elif (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id == "granular"
        ):
            names = [node.attr]
        else:
            continue
        private += [n for n in names if n.startswith("_")]
    assert not private, f"{script.name} uses granular's private {private}"
