"""The source distribution holds what its README shows and what its test suite needs.

The sdist is built the way pip would build it (``python -m build --sdist``, an isolated build
environment) from a copy of the files git tracks (or would: new files not ignored count too),
so the checkout is not touched (setuptools writes ``granular.egg-info`` beside the sources).
About 3 s with pip's cache warm.
"""

import re
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
# Every tracked file under these directories belongs in the sdist: granular/ (with its
# subpackage cli/) and csrc/ build the package, tests/ (with tests/helpers/, not only
# test_*.py), notebooks/ and benchmarks/ (tests/test_benchmarks.py runs them) are the suite,
# docs/ the README's images.
SHIPPED_DIRS = ("granular", "csrc", "docs", "notebooks", "tests", "benchmarks")


def _tracked_files():
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to know the tracked files (an unpacked sdist has none)")
    # tracked files and new ones not yet added (but not ignored): what the next commit's clone has
    out = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    )
    return [name for name in out.stdout.decode().split("\0") if name and (ROOT / name).is_file()]


@pytest.fixture(scope="module")
def sdist_names(tmp_path_factory):
    """The paths in the sdist built from the tracked files, relative to its top directory."""
    tracked = _tracked_files()
    src = tmp_path_factory.mktemp("src")
    for name in tracked:
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    dist = tmp_path_factory.mktemp("dist")
    done = subprocess.run(
        [sys.executable, "-m", "build", "--sdist", "--outdir", str(dist), str(src)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, f"python -m build --sdist failed:\n{done.stdout}\n{done.stderr}"
    (archive,) = dist.glob("*.tar.gz")
    with tarfile.open(archive) as tar:
        names = [m.name for m in tar.getmembers() if m.isfile()]
    top = names[0].split("/")[0]
    return tracked, {name[len(top) + 1 :] for name in names}


def test_sdist_holds_sources_tests_notebooks_and_images(sdist_names):
    tracked, shipped = sdist_names
    wanted = [name for name in tracked if name.split("/")[0] in SHIPPED_DIRS]
    assert {"tests/conftest.py", "csrc/edmd.c", "granular/cli/demo.py"} <= set(wanted)  # seen
    missing = sorted(set(wanted) - shipped)
    assert not missing, f"tracked files missing from the sdist (add them to MANIFEST.in): {missing}"
    assert not [name for name in shipped if name.endswith((".pyc", ".so", ".o"))], (
        "build products in the sdist"
    )


def test_sdist_holds_every_image_the_readme_shows(sdist_names):
    _, shipped = sdist_names
    readme = (ROOT / "README.md").read_text()
    images = set(re.findall(r"\]\(([^)\s]+\.png)\)", readme))
    assert images, "the README shows no image: this test checks nothing"
    assert not sorted(images - shipped), f"README images missing from the sdist: {images - shipped}"


def _extras():
    """{extra: set of requirement names} from pyproject.toml, self-references resolved."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
    with open(ROOT / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)["project"]
    raw = project["optional-dependencies"]

    def names(extra):
        out = set()
        for req in raw[extra]:
            name = re.match(r"[A-Za-z0-9_.-]+", req).group(0).lower()
            inner = re.search(r"\[(.*)\]", req)
            if name == project["name"]:
                out |= set().union(*(names(e.strip()) for e in inner.group(1).split(",")))
            else:
                out.add(name)
        return out

    return {extra: names(extra) for extra in raw}


def test_extras_cover_einstein_msd_and_the_notebooks():
    """MDAnalysis' EinsteinMSD computes by FFT by default, which imports tidynamics; the
    notebooks run in an IPython kernel (ipykernel), headless by nbconvert, and tqdm's bars
    need ipywidgets to be widgets rather than text lines in the saved output. The test extra
    installs what every part of the suite uses."""
    extras = _extras()
    assert {"mdanalysis", "tidynamics"} <= extras["interop"]
    assert {"matplotlib", "dask", "nbconvert", "ipykernel", "ipywidgets"} <= extras["notebooks"]
    missing = (
        extras["plot"]
        | extras["interop"]
        | extras["parallel"]
        | extras["notebooks"]
        | {"build", "nbclient", "nbformat", "pytest"}
    ) - extras["test"]
    assert not missing, f"the test extra lacks {sorted(missing)}"


def test_einstein_msd_with_its_default_fft_on_an_exported_trajectory():
    """What a user of the interop extra runs first: EinsteinMSD with its defaults (FFT).
    It must agree with the direct sum; both read the same float32 file, so only the FFT's
    rounding (~1e-6 of the MSD in MDAnalysis' float32-derived sums) separates them."""
    mda = pytest.importorskip("MDAnalysis")
    from MDAnalysis.analysis.msd import EinsteinMSD

    from granular import Scene, Simulation

    times = np.linspace(0.0, 1.0, 21)
    traj = Simulation(Scene.random(30, 0.03, seed=3)).run(t_stop=1.0, sample_times=times)
    u = traj.to_universe()
    fft = EinsteinMSD(u, select="all").run().results.timeseries  # needs tidynamics
    direct = EinsteinMSD(u, select="all", fft=False).run().results.timeseries
    np.testing.assert_allclose(fft, direct, rtol=1e-5, atol=1e-6 * direct.max())
    assert mda is not None


# the extras for the documentation and the test suite: tools, not something a user wants
TOOL_EXTRAS = ("docs", "test", "all")


def test_all_extra_covers_every_user_extra():
    """``pip install 'granular[all]'`` brings everything any user extra brings."""
    extras = _extras()
    assert "all" in extras, "no `all` extra in pyproject.toml"
    user = set().union(*(names for extra, names in extras.items() if extra not in TOOL_EXTRAS))
    assert {"matplotlib", "mdanalysis", "gsd", "dask", "ipykernel"} <= user  # seen
    missing = user - extras["all"]
    assert not missing, f"the all extra lacks {sorted(missing)}"


def _make_dry_run(target, tmp_path):
    """The commands ``make TARGET`` would run for a fresh venv (make -n: nothing is run)."""
    if shutil.which("make") is None:
        pytest.skip("needs make")
    done = subprocess.run(
        ["make", "-n", target, f"VENV={tmp_path / 'venv'}"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    return [line for line in done.stdout.splitlines() if "pip install" in line and " -e " in line]


def test_make_demo_installs_only_what_the_demo_needs(tmp_path):
    """``make demo`` on a fresh machine installs the plot extra (matplotlib), not the test
    extra's ~130 packages; ``make test`` installs the test extra."""
    (demo,) = _make_dry_run("demo", tmp_path)
    assert "'.[plot]'" in demo, demo
    (test,) = _make_dry_run("test", tmp_path)
    assert "'.[test]'" in test, test
