"""The documentation site: it builds without a warning, every Python example in its pages runs,
its API reference names every public module, and it shows every figure in docs/.

The build takes about 5 s on a 2-core machine (MathJax is copied, nothing is fetched), the
examples about 10 s together. Checks on the source tree skip where there is none (the
sanitizer build runs the suite from a copy of tests/). Sphinx comes with the test extra (the
docs extra), so CI never skips the build.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import granular

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"

# granular/*.py modules the API reference covers through their public names instead of a page
# of their own, or leaves out on purpose. A new module needs a line in docs/api.md (or here).
COVERED_BY_NAMES = {
    "scene": "granular.Scene",
    "simulation": "granular.Simulation",
    "trajectory": "granular.Trajectory",
    "ensemble": "granular.ensemble",
    "gsd_io": "granular.read",
}
NOT_PUBLIC = {
    "placement": "Scene.random's placement and velocity draws, not called by users",
    "checkpoint": "the file format behind Simulation.save / Simulation.load",
    "ensemble_store": "the directory behind ensemble(..., save_to=)",
    "_animate": "behind granular.plot.animate",
}


def _source_tree():
    if not (ROOT / "pyproject.toml").is_file() or not (DOCS / "conf.py").is_file():
        pytest.skip("not a source tree (the tests run from a copy)")


def _pages():
    return sorted(DOCS.glob("*.md"))


def _script(page):
    """The page's ```python blocks as one script, each line at its line number in the page, so
    a traceback points into the page."""
    out, inside = [], False
    for line in page.read_text().splitlines():
        fence = line.strip()
        if not inside and fence == "```python":
            inside = True
            out.append("")
        elif inside and fence == "```":
            inside = False
            out.append("")
        else:
            out.append(line if inside else "")
    assert not inside, f"{page.name}: a ```python block is never closed"
    return "\n".join(out) + "\n"


def _pages_with_examples():
    if not DOCS.is_dir():
        return []
    return [p.name for p in _pages() if "```python" in p.read_text()]


def test_sphinx_builds_the_site_without_warnings(tmp_path):
    _source_tree()
    pytest.importorskip("sphinx", reason="Sphinx is not installed: pip install '.[docs]'")
    out = tmp_path / "html"
    # the make docs command (-E: no cache; -W --keep-going: any warning fails, all reported)
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-E", "-W", "--keep-going", "-q"]
    cmd += ["-d", str(tmp_path / "doctrees"), str(DOCS), str(out)]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, f"the docs build failed:\n{result.stderr[-5000:]}"

    # one API page per public name and module of docs/api.md
    listed = re.findall(r"^\s+(granular\.\w+)\s*$", (DOCS / "api.md").read_text(), re.M)
    assert len(listed) >= 10, f"docs/api.md lists only {listed}"
    missing = [name for name in listed if not (out / "generated" / f"{name}.html").is_file()]
    assert not missing, f"no API page for {missing}"
    theory = (out / "generated" / "granular.theory.html").read_text()
    assert "msd_granular" in theory and "(2.79)" in theory, "theory's page lost its docstrings"

    # equations render offline: MathJax comes from the site itself, not from a CDN
    conventions = (out / "conventions.html").read_text()
    scripts = re.findall(r'<script[^>]*src="([^"]*mathjax[^"]*)"', conventions, re.I)
    assert scripts, "the conventions page loads no MathJax"
    assert all("://" not in s for s in scripts), f"MathJax from the network: {scripts}"
    assert all((out / s).is_file() for s in scripts), f"MathJax files missing: {scripts}"
    assert r"\frac{T_0}{(1 + t/\tau_0)^2}" in conventions, "Haff's law is not on the page"


@pytest.mark.parametrize("page", _pages_with_examples())
def test_every_python_example_in_a_page_runs(page, tmp_path):
    # each page's examples run in order, as one script in an empty directory (some write
    # files), with a non-interactive matplotlib; the time limit is far above the few seconds
    # each page takes, and only there to turn a hang into a failure
    _source_tree()
    script = tmp_path / f"{Path(page).stem}_md.py"
    script.write_text(_script(DOCS / page))
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    result = subprocess.run(
        [sys.executable, script.name],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=240,
        env=env,
    )
    assert result.returncode == 0, (
        f"an example in docs/{page} failed (line numbers are the page's):\n{result.stderr[-4000:]}"
    )
    assert result.stdout.strip(), f"docs/{page}'s examples print nothing: nothing shown to check"


def test_examples_are_found():
    _source_tree()
    pages = _pages_with_examples()
    for page in ("getting-started.md", "edmd.md", "langevin.md", "analysis.md", "ensembles.md"):
        assert page in pages, f"docs/{page} has no ```python example (or is missing)"


def test_api_reference_names_every_public_module():
    _source_tree()
    api = (DOCS / "api.md").read_text()
    modules = sorted(p.stem for p in (ROOT / "granular").glob("*.py") if not p.stem.startswith("_"))
    unlisted = [
        m
        for m in modules
        if m not in NOT_PUBLIC and f"granular.{m}" not in api and COVERED_BY_NAMES.get(m) not in api
    ]
    assert not unlisted, (
        f"modules missing from docs/api.md: {unlisted}; add 'granular.<name>' under its Modules "
        "list (or, if it is not public, to NOT_PUBLIC in this test with the reason)"
    )
    # every module granular exports, and the lazily imported ones, has its page
    exported = [n for n in granular.__all__ if isinstance(getattr(granular, n), type(granular))]
    exported += list(granular._LAZY)
    missing = [n for n in exported if f"granular.{n}\n" not in api]
    assert not missing, f"modules granular exports without an API page: {missing}"


def test_every_figure_in_docs_is_shown():
    _source_tree()
    shown = set()
    for page in _pages():
        shown |= set(re.findall(r"\]\(([^)\s]+\.png)\)", page.read_text()))
    figures = {p.name for p in DOCS.glob("*.png")}
    assert figures, "docs/ holds no figure: this test checks nothing"
    assert not figures - shown, f"figures no page shows: {sorted(figures - shown)}"
