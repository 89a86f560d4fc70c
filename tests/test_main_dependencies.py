"""The command line checks its optional dependencies before any work:
after ``pip install .`` without extras, ``python -m granular demo`` used to compute for a
minute and then die on ``import matplotlib``, losing the results.

matplotlib is hidden the way Python itself reports a missing module: ``sys.modules`` maps
it to None, so ``import matplotlib`` raises ImportError and ``find_spec`` returns None."""

import subprocess
import sys

import pytest

from granular import __main__ as cli

ADVICE = "needs matplotlib, which is not installed: pip install 'granular[plot]'"


@pytest.fixture
def commands_recorded(monkeypatch):
    """Replace every command's work by a recorder of the call."""
    from granular.cli import bench, demo, reproduce, speed_accuracy

    calls = []
    for module in (demo, reproduce, speed_accuracy, bench):
        monkeypatch.setattr(
            module, "main", lambda *a, _name=module.__name__, **k: calls.append(_name)
        )
    return calls


@pytest.mark.parametrize(
    "argv", [["demo"], ["reproduce", "--quick"], ["bench", "--speed-accuracy"]]
)
def test_commands_that_draw_refuse_to_start_without_matplotlib(
    argv, monkeypatch, capsys, commands_recorded
):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert cli.main(argv) == 2
    assert commands_recorded == []
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"python -m granular {' '.join(argv[:1])}" in err
    assert ADVICE in err


def test_commands_run_when_what_they_need_is_there(monkeypatch, commands_recorded):
    """The plain benchmark draws nothing: it runs without matplotlib; the others run when
    matplotlib is installed."""
    with monkeypatch.context() as hidden:
        hidden.setitem(sys.modules, "matplotlib", None)
        assert cli.main(["bench", "--quick"]) == 0
    assert cli.main(["demo", "--quick"]) == 0
    assert commands_recorded == ["granular.cli.bench", "granular.cli.demo"]


def test_demo_without_matplotlib_stops_before_any_work(tmp_path):
    """A real run in a fresh interpreter where matplotlib cannot be imported: exit code 2,
    one line naming the extra, and no output folder (nothing was computed)."""
    code = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "from granular.__main__ import main\n"
        "sys.exit(main(['demo', '--quick', '--out', 'out']))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == f"python -m granular demo {ADVICE}\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", ["demo", "reproduce", "speed_accuracy", "bench", "bench_langevin"])
def test_old_application_names_still_work_with_a_warning(name):
    """granular.<app> moved to granular.cli.<app>; the old name is the same module
    for one more release, and says where it went."""
    import importlib

    import granular

    with pytest.warns(FutureWarning, match=f"granular.cli.{name}"):
        old = getattr(granular, name)
    assert old is importlib.import_module(f"granular.cli.{name}")


def test_the_library_never_imports_the_applications():
    """granular.cli is built on the library, never the other way round: importing the whole
    library (lazy modules too) loads nothing from granular.cli."""
    code = (
        "import sys, granular, granular.plot, granular.interop\n"
        "print(*(m for m in sys.modules if m.startswith('granular.cli')))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert done.stdout.strip() == ""
