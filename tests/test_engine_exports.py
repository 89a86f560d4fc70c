"""The engine's rules are owned by the C core and read from it by the Python side:
the big-particle rule and its default, the bytes per particle, and the
checks of a configuration without building an engine."""

import math

import numpy as np
import pytest

import granular
from granular import _core
from granular.errors import GranularError
from granular.scene import BIG_RATIO


def test_big_rule_and_default_come_from_c():
    assert BIG_RATIO == _core.BIG_RATIO == 3.0
    assert _core.BIG_MAX == 16
    r = np.full(101, 0.01)
    r[7] = 0.05
    # the cut is BIG_RATIO times the upper median radius
    assert _core.big_cut(r, BIG_RATIO) == pytest.approx(0.03)
    big = _core.big_particles(r, np.array([1.0, 1.0, 1.0]), BIG_RATIO, 1.0)
    assert big.dtype == bool and np.flatnonzero(big).tolist() == [7]
    # more than BIG_MAX wide ones: none kept out; none at all with an infinite ratio
    r[:20] = 0.05
    assert not _core.big_particles(r, np.array([1.0, 1.0, 1.0]), BIG_RATIO, 1.0).any()
    assert not _core.big_particles(r, np.array([1.0, 1.0, 1.0]), math.inf, 1.0).any()


def test_bytes_per_particle():
    cells = _core.edmd_bytes_per_particle(3, False)
    lists = _core.edmd_bytes_per_particle(3, True)
    assert 200 < cells < lists < 1000
    assert _core.edmd_bytes_per_particle(2, False) < cells


def test_check_agrees_with_the_engine():
    s = granular.Scene.random(200, 0.02, seed=3)
    assert _core.edmd_check(**s._engine_keywords()) is None
    pos = s.positions.copy()
    pos[5] = pos[9] + [0.01, 0.0, 0.0]  # overlapping 9
    pos[5] %= 1.0
    bad = {**s._engine_keywords(), "positions": pos}
    knobs = dict(cell_factor=1.0, big_ratio=BIG_RATIO, shell=0.0)
    for build in (_core.edmd_check, _core.EDMD):
        with pytest.raises(GranularError, match="overlap"):
            build(**bad, **knobs)
    pos = s.positions.copy()
    pos[3, 1] = 1.5  # outside the box
    bad["positions"] = pos
    for build in (_core.edmd_check, _core.EDMD):
        with pytest.raises((GranularError, ValueError)):
            build(**bad, **knobs)


def test_the_engine_takes_keywords_only():
    """EDMD, edmd_check and advance take every argument by name: a positional call, a
    misspelt or a missing name is a TypeError naming it, so two numbers cannot swap
    places unseen; advance's energy criterion and its samples' buffer have two names."""
    s = granular.Scene.random(20, 0.02, seed=3)
    kw = s._engine_keywords()
    for build in (_core.edmd_check, _core.EDMD):
        with pytest.raises(TypeError, match="positional"):
            build(*kw.values())
        with pytest.raises(TypeError, match="restitutoin"):
            build(**kw, restitutoin=0.5)
        with pytest.raises(TypeError, match="missing required keyword argument 'contact_duration'"):
            build(**{k: v for k, v in kw.items() if k != "contact_duration"})
    engine = _core.EDMD(**kw)
    stop = dict(
        t_stop=math.inf,
        collisions_per_particle=1.0,
        stop_kinetic_energy=-1.0,
        max_events=10**6,
        sample_times=np.array([0.0, 0.001]),
        next=0,
    )
    with pytest.raises(TypeError, match="positional"):
        engine.advance(*stop.values())
    with pytest.raises(TypeError, match="missing required keyword argument 'max_events'"):
        engine.advance(**{k: v for k, v in stop.items() if k != "max_events"})
    kinetic = np.full(2, -1.0)
    code, nxt = engine.advance(**stop, kinetic_energy=kinetic)
    assert code == _core.STOP_COLLISIONS and nxt == 2
    assert kinetic == pytest.approx(np.full(2, s.kinetic_energy), rel=1e-12)


def test_scene_and_simulation_do_not_import_each_other():
    """simulation imports scene; scene (and _edmd, which both use) import neither when they
    run (an import under ``if TYPE_CHECKING:`` is for the type checker only)."""
    import ast
    import pathlib

    src = pathlib.Path(granular.__file__).parent
    for name, banned in (("scene", {"simulation"}), ("_edmd", {"scene", "simulation"})):
        tree = ast.parse((src / f"{name}.py").read_text())
        typing_only = {
            id(inner)
            for node in ast.walk(tree)
            if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING"
            for inner in ast.walk(node)
        }
        froms = [
            node
            for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and id(node) not in typing_only
        ]
        imported = {alias.name for node in froms for alias in node.names}
        imported |= {node.module for node in froms}
        assert not imported & banned, name
