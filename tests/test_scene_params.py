"""Each Scene parameter is declared once (granular/_scene_params.py) and that declaration
drives the Scene, the engine's arguments, the checkpoints and GSD files: a parameter that exists in
one of them but not in the others fails here."""

import inspect
import math

import numpy as np
import pytest

import granular
from granular import Scene, Simulation, TabulatedRestitution, Viscoelastic, _core, _scene_params
from granular._scene_params import BY_NAME, NAMES, PARAMETERS, REQUIRED

_ENGINE_KNOBS = {"cell_factor", "big_ratio", "shell", "stress"}  # Simulation's, not the scene's


_INNER = (np.array([-1.0, 0.5]), np.array([1.5, 2.0]))
_RADII = np.array([0.03, 0.05] * 6)


def _examples():
    """A value for every declared parameter, none its default: a walled 2D box off the
    origin, unequal radii and masses, laws for the restitutions, the TC model on, a random
    driving force."""
    base = Scene.random(12, _RADII, dim=2, box=_INNER, boundary="walls", seed=4)
    return {
        "positions": base.positions,
        "velocities": base.velocities,
        "radii": base.radii,
        "masses": np.linspace(0.5, 2.0, 12),
        "box": (_INNER[0] - 0.5, _INNER[1] + 0.5),
        "boundary": "walls",
        "wall_restitution": Viscoelastic.from_restitution(0.9, 1.0),
        "restitution": TabulatedRestitution([0.0, 1.0, 3.0], [1.0, 0.9, 0.7]),
        "contact_duration": 1e-3,
        "driving": granular.WhiteNoise(0.5, 20.0, seed=3),
        "angular_velocities": np.linspace(-1.0, 1.0, 12),
        "tangential_restitution": 0.5,
        "inertia_factor": 0.3,
        "friction": 0.2,
        "free_fall": True,
    }


# parameters that need a periodic box, with their examples (the walled examples keep
# their defaults); _examples_for gives them a periodic scene
_PERIODIC_ONLY = {"shear_rate": 0.3, "shear_offset": 0.25}


# parameters whose examples run with smooth particles (a vibrating wall, gravity; rough
# particles combine with both too: tests/test_rough_combined.py), with
# their examples; _examples_for gives them the walled examples with smooth particles
_SMOOTH_ONLY = {
    "vibrating_wall": granular.VibratingWall(1, "lower", 0.2, 3.0, phase=-np.pi / 2),
    "gravity": np.array([0.1, -0.5]),
}
_SMOOTH = {
    "angular_velocities": None,
    "tangential_restitution": -1.0,
    "inertia_factor": None,
    "friction": math.inf,
}


def _examples_for(name):
    """_examples, with ``name``'s example if it needs a periodic box (in one) or smooth
    particles (with them)."""
    if name in _SMOOTH_ONLY:
        return {**_examples(), **_SMOOTH, name: _SMOOTH_ONLY[name]}
    if name not in _PERIODIC_ONLY:
        return _examples()
    # an offset needs a shear rate (the sheared example with smooth particles; rough ones
    # are sheared in tests/test_rough_combined.py)
    rate = {"shear_rate": _PERIODIC_ONLY["shear_rate"], "tangential_restitution": -1.0}
    return {**_examples(), "boundary": "periodic", **rate, name: _PERIODIC_ONLY[name]}


def _alternative(name):
    """Another valid value of parameter ``name`` beside the other examples: its default,
    or for the particles and the box one that _examples' values fit."""
    other = Scene.random(12, _RADII, dim=2, box=_INNER, boundary="walls", seed=5)
    special = {
        "positions": other.positions,
        "velocities": np.zeros((12, 2)),
        "radii": 0.8 * _RADII,
        "box": _INNER,
    }
    return special[name] if name in special else _scene_params.BY_NAME[name].default


def _same(a, b):
    if a is None or b is None:  # an unset array parameter (gravity)
        return a is b
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_every_parameter_has_an_example_unlike_its_default():
    examples = {**_examples(), **_PERIODIC_ONLY, **_SMOOTH_ONLY}
    assert set(examples) == set(NAMES), "give the new parameter an example value here"
    for p in PARAMETERS:
        assert p.default is REQUIRED or not _same(p.check(p.default, 12, 2), examples[p.name])


def test_the_scene_is_its_declaration():
    """Scene's constructor, its attributes and replace's fields are the declared ones."""
    params = list(inspect.signature(Scene).parameters)
    assert params == list(NAMES)
    assert set(Scene.__annotations__) == set(_scene_params.FIELDS), (
        "a Scene attribute that is not a declared parameter (or the reverse)"
    )
    for p in PARAMETERS:
        assert f"{p.name} : " in Scene.__doc__


def test_every_parameter_reaches_the_engine_by_name():
    """The keywords the declaration gives the engine are exactly the scene's part of the
    binding's keyword list (_core.EDMD_KEYWORDS: csrc/_core.c's edmd_names, whose numbers
    come from csrc/scene_params.h), each parameter giving some; and the engine takes them
    (edmd_check of a scene with every parameter set)."""
    names = _core.EDMD_KEYWORDS
    scene = Scene(**_examples())
    given = {}
    for p in PARAMETERS:
        keywords = p.engine(p.get(scene))
        assert keywords, f"{p.name} gives the engine nothing"
        assert not set(keywords) & set(given), f"{p.name} gives a keyword twice"
        given.update(keywords)
    assert set(given) == set(names) - _ENGINE_KNOBS
    assert list(given) == list(scene._engine_keywords())
    assert _core.edmd_check(**given) is None
    _core.EDMD(**given)


@pytest.mark.parametrize("name", NAMES)
def test_every_parameter_goes_through_replace(name):
    examples = _examples_for(name)
    base = Scene(**{**examples, name: _alternative(name)})
    p = _scene_params.BY_NAME[name]
    assert not _same(p.get(base), p.check(examples[name], 12, 2))
    changed = base.replace(**{name: examples[name]})
    assert _same(p.get(changed), p.check(examples[name], 12, 2))


def test_every_parameter_survives_a_checkpoint(tmp_path):
    """A scene with every parameter set is saved and loaded with each one unchanged (the
    initial scene and the state now), and the run goes on bit for bit."""
    scene = Scene(**_examples())
    sim = Simulation(scene)
    sim.run(stop_when={"collisions_per_particle": 2}, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    for p in PARAMETERS:
        assert _same(p.get(loaded._initial), p.get(scene)), p.name
        if p.name not in _scene_params.SAMPLED:
            assert _same(p.get(loaded.scene), p.get(scene)), p.name
    a = sim.run(stop_when={"collisions_per_particle": 4}, store=("positions",))
    b = loaded.run(stop_when={"collisions_per_particle": 4}, store=("positions",))
    assert np.array_equal(a.positions, b.positions)


def _gsd_round_trip(tmp_path, writer=None, name=None):
    """A run of a scene with every parameter set, written to a GSD file (by ``writer``,
    else ``Trajectory.write``): the parameters whose value ``Scene.from_gsd`` (of the last
    frame) or ``granular.read`` gives back differs from the run's, and those read keeps
    (with ``name``'s example in a periodic box if it needs one)."""
    scene = Scene(**(_examples_for(name) if name else _examples()))
    sim = Simulation(scene)
    store = ("positions", "velocities", "angular_velocities")
    traj = sim.run(t_stop=0.05, sample_times=[0.0, 0.05], store=store)
    (writer or type(traj).write)(traj, tmp_path / "run.gsd")
    back = Scene.from_gsd(tmp_path / "run.gsd")
    read = granular.read(tmp_path / "run.gsd").scene_parameters
    now = scene.replace(
        positions=traj.positions[-1],
        velocities=traj.velocities[-1],
        angular_velocities=traj.angular_velocities[-1],
    )
    differ = [p.name for p in PARAMETERS if not _same(p.get(back), p.get(now))]
    differ += [f"read {n}" for n in read if not _same(read[n], BY_NAME[n].get(scene))]
    return differ, set(read)


def test_every_parameter_survives_a_gsd_file(tmp_path):
    """Scene.from_gsd of a file a run wrote is the run's scene at that frame, every
    parameter (restitution laws, the TC model, ...) included, and granular.read's
    Trajectory keeps them all."""
    differ, kept = _gsd_round_trip(tmp_path)
    assert not differ
    assert kept == set(NAMES) - set(_scene_params.SAMPLED)


@pytest.mark.parametrize("name", [p.name for p in _scene_params.RUN_PARAMETERS])
def test_a_parameter_the_gsd_writer_skips_is_caught(tmp_path, monkeypatch, name):
    """The round trip above fails if the writer leaves a parameter out: the file is
    refused (a required one, or the box its particles no longer fit) or read with the
    parameter's default, unlike the run's."""
    from granular import gsd_io

    skipped = tuple(p for p in gsd_io.RUN_PARAMETERS if p.name != name)

    def write(traj, path):
        with monkeypatch.context() as m:
            m.setattr(gsd_io, "RUN_PARAMETERS", skipped)
            traj.write(path)

    try:
        differ, _ = _gsd_round_trip(tmp_path, write, name)
    except granular.errors.GSDFileError:
        return
    assert name in differ


def test_no_parameter_takes_a_name_the_gsd_log_uses_for_its_own():
    # a GSD file logs each parameter's attributes by name beside its own fields
    from granular import gsd_io

    fields = {a for p in _scene_params.RUN_PARAMETERS for a in p.fields}
    assert not fields & set(gsd_io.LOG_NAMES)
