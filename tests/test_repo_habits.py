"""The repository's habits, kept by a test: one version, a license that matches what the
package declares, a README within its budget whose images and links exist, and every
equation number in the user documentation tied to the thesis it comes from.

Checks on files of the source tree skip where there is none (the sanitizer build runs the
suite from a copy of tests/)."""

import importlib.metadata
import re
from pathlib import Path

import pytest

import granular

ROOT = Path(__file__).resolve().parent.parent

# "A few hundred lines at most"; today's README is about 250 lines, 14 KB. Engine
# design belongs in docs/engine.md, measurements in docs/performance.md.
README_MAX_LINES = 300
README_MAX_BYTES = 16_000

# The thesis, defined once per document as [G20] with its full reference.
THESIS_TITLE = "Simulation methods for granular gas dynamics in periodic three-dimensional systems"
# A reference to a numbered part of the thesis: eq. 2.68, eqs. 4.1-4.2, Table 2.2, ch. 4,
# section 4.2.2, Fig. 4.8 ... Each must be written "[G20] eq. 2.68".
NUMBERED = re.compile(
    r"\b(?:eqs?\.|equations?|Tables?|Figs?\.|Figures?|ch\.|chapters?|"
    r"sec\.|sections?|App\.)\s*\(?\d+(?:\.\d+)*",
    re.IGNORECASE,
)
# A bare "(2.68)" or "thesis 2.22", the way the old README cited equations without a reference
BARE = re.compile(r"\([1-9A-F]\.\d{1,3}\)|\bthesis'?\s+\d\.\d{1,3}\b")


def _source_file(name):
    path = ROOT / name
    if not (ROOT / "pyproject.toml").is_file():
        pytest.skip("not a source tree (the tests run from a copy)")
    assert path.is_file(), f"{name} is missing from the repository"
    return path


def _pyproject():
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
    with open(_source_file("pyproject.toml"), "rb") as f:
        return tomllib.load(f)


def _user_docs():
    """README.md and docs/*.md: the documentation a user reads."""
    readme = _source_file("README.md")
    return [readme, *sorted((ROOT / "docs").glob("*.md"))]


# -- one version ----------------------------------------------------------------------------


def test_installed_version_is_granular_version():
    # the metadata is written at install time from granular.__version__; a mismatch means the
    # version was changed without reinstalling, or written somewhere else as well
    assert importlib.metadata.version("granular") == granular.__version__


def test_version_is_written_once():
    project = _pyproject()
    assert "version" not in project["project"], "pyproject writes the version itself"
    assert "version" in project["project"].get("dynamic", [])
    attr = project["tool"]["setuptools"]["dynamic"]["version"]
    assert attr == {"attr": "granular.__version__"}


def test_citation_and_changelog_name_this_version():
    cff = _source_file("CITATION.cff").read_text()
    assert re.search(rf"^version:\s*{re.escape(granular.__version__)}\s*$", cff, re.M), (
        f"CITATION.cff does not say version {granular.__version__}"
    )
    changelog = _source_file("CHANGELOG.md").read_text()
    assert "## [Unreleased]" in changelog
    assert f"## [{granular.__version__}]" in changelog, (
        f"CHANGELOG.md has no section for {granular.__version__}"
    )


# -- license --------------------------------------------------------------------------------


def test_license_file_matches_pyproject():
    declared = _pyproject()["project"]["license"]
    assert declared == "MIT"
    text = _source_file("LICENSE").read_text()
    assert text.startswith("MIT License\n")
    assert "Copyright (c) 2026 the granular developers" in text
    assert 'THE SOFTWARE IS PROVIDED "AS IS"' in text


def test_installed_metadata_carries_the_license():
    meta = importlib.metadata.metadata("granular")
    assert meta.get("License-Expression") == "MIT"
    assert "LICENSE" in (meta.get_all("License-File") or [])


# -- README ---------------------------------------------------------------------------------


def test_readme_within_its_budget():
    readme = _source_file("README.md")
    lines = readme.read_text().count("\n")
    size = readme.stat().st_size
    assert lines <= README_MAX_LINES and size <= README_MAX_BYTES, (
        f"README.md is {lines} lines, {size} bytes (budget {README_MAX_LINES} lines, "
        f"{README_MAX_BYTES} bytes): move internals to docs/engine.md or docs/performance.md"
    )


def test_readme_keeps_the_install_and_test_commands():
    text = _source_file("README.md").read_text()
    assert "make test" in text and "make demo" in text
    extras = _pyproject()["project"]["optional-dependencies"]
    unnamed = [extra for extra in extras if f"`{extra}`" not in text]
    assert not unnamed, f"extras the README's Install section does not name: {unnamed}"


@pytest.mark.parametrize("doc", ["README.md", "docs/engine.md", "docs/performance.md"])
def test_local_links_and_images_exist(doc):
    path = _source_file(doc)
    targets = re.findall(r"\]\(([^)\s#]+)(?:#[^)\s]*)?\)", path.read_text())
    local = [t for t in targets if "://" not in t]
    if doc == "README.md":
        assert any(t.startswith("docs/") and t.endswith(".png") for t in local), (
            "the README shows no image from docs/: this test checks nothing"
        )
    missing = [t for t in local if not (path.parent / t).exists()]
    assert not missing, f"{doc} links to files that do not exist: {missing}"


def test_every_equation_number_cites_the_thesis():
    for path in _user_docs():
        text = path.read_text()
        name = path.relative_to(ROOT)
        refs = list(NUMBERED.finditer(text))
        uncited = [
            m.group(0)
            for m in refs
            if not re.search(r"\[G20\]\s*$", text[max(0, m.start() - 8) : m.start()])
        ]
        assert not uncited, f"{name}: numbers not written as '[G20] eq. ...': {uncited}"
        bare = BARE.findall(text)
        assert not bare, f"{name}: equation numbers without [G20]: {bare}"
        if refs:
            flat = " ".join(text.split())
            definition = re.search(
                r"\[G20\][^\n]{0,40}?A\. Gjersvoll, \*([^*]+)\*, master's "
                r"thesis[^.]*NTNU[^.]*2020",
                flat,
            )
            assert definition, f"{name} cites [G20] but never gives its full reference"
            assert definition.group(1) == THESIS_TITLE


# -- comments say why, not when or which ticket ---------------------------------------------

# "issue 16", "#16", or a date: the history belongs in git and CHANGELOG.md, measurements in
# docs/performance.md with their dates
TICKET_OR_DATE = re.compile(r"\bissues?\s+\d+|(?<![\w&])#\d{1,4}\b|\b20\d\d-\d\d-\d\d\b", re.I)


def test_code_carries_no_issue_numbers_or_dates():
    _source_file("pyproject.toml")
    files = [
        *sorted((ROOT / "granular").rglob("*.py")),
        *sorted((ROOT / "csrc").glob("*.[ch]")),
        *sorted((ROOT / "tests").rglob("*.py")),
    ]
    found = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in files
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if TICKET_OR_DATE.search(line) and path.name != "test_repo_habits.py"
    ]
    assert not found, "\n".join(found)
