"""The calling convention of granular.theory and granular.plot: the independent variable (in
plot: the data drawn, x then y) positional, every other parameter keyword-only; one name per
quantity (granular._params.QUANTITIES, the table of docs/conventions.md), each checked by
name; the old positional calls still work for one release, with a FutureWarning, and give
the same numbers."""

import inspect
import math
import re
from pathlib import Path

import numpy as np
import pytest

from granular import Scene, _deprecation, _params, theory
from granular.errors import shown

pytestmark = pytest.mark.filterwarnings("error::FutureWarning")

# what may come before the keyword-only parameters
THEORY_INDEPENDENT = {
    "t", "lag", "speed", "eta", "box", "temperature", "height", "stiffness", "collisions",
    "peak_velocity", "z", "shear_rate",
}  # fmt: skip
PLOT_X = {"times", "velocities", "positions", "traj"}

# names the package used, or a user might reach for, for a quantity that has another name
SYNONYMS = {
    "xi": "restitution",
    "starts": "start",
    "T": "temperature",
    "T0": "temperature0",
    "number_density": "density",
    "rho": "density",
    "n_particles": "n",
    "N": "n",
    "r": "radius",
    "m": "mass",
    "d": "dim",
    "D": "D0",
    "gamma": "gamma0",
}


def _public(module, defined_in):
    out = []
    for name in getattr(module, "__all__", dir(module)):
        f = getattr(module, name)
        if inspect.isfunction(f) and not name.startswith("_") and f.__module__ in defined_in:
            out.append((name, f))
    return out


def _theory():
    return _public(theory, {"granular.theory"})


def _plot():
    from granular import plot

    return _public(plot, {"granular.plot", "granular._animate"})


def _positional(f):
    return [
        p.name
        for p in inspect.signature(f).parameters.values()
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
    ]


def test_the_functions_are_found():
    names = {n for n, _ in _theory()}
    assert {"haff_tau0", "msd_granular", "udsbm_ergodicity_breaking", "tracer_friction"} <= names
    assert len(names) >= 44, sorted(names)
    assert {"haff", "msd", "animate", "snapshot"} <= {n for n, _ in _plot()}


@pytest.mark.parametrize("name, f", _theory(), ids=lambda x: x if isinstance(x, str) else "")
def test_theory_takes_only_its_independent_variable_by_position(name, f):
    positional = _positional(f)
    assert len(positional) <= 1 and set(positional) <= THEORY_INDEPENDENT, (
        f"theory.{name}{inspect.signature(f)}: only the independent variable "
        f"({sorted(THEORY_INDEPENDENT)}) may come before '*'"
    )
    assert not any(
        p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        for p in inspect.signature(f).parameters.values()
    )


@pytest.mark.parametrize("name, f", _plot(), ids=lambda x: x if isinstance(x, str) else "")
def test_plot_takes_only_the_data_drawn_by_position(name, f):
    positional = _positional(f)
    assert 1 <= len(positional) <= 2 and positional[0] in PLOT_X, (
        f"plot.{name}{inspect.signature(f)}: only x (and the y drawn against it) before '*'"
    )


@pytest.mark.parametrize(
    "name, f", _theory() + _plot(), ids=lambda x: x if isinstance(x, str) else ""
)
def test_one_name_per_quantity(name, f):
    if f.__module__ == "granular._animate":
        pytest.skip("animate's drawing options are its own (its quantities: traj)")
    params = list(inspect.signature(f).parameters)
    unknown = [p for p in params if p not in _params.QUANTITIES]
    assert not unknown, (
        f"{name}: parameters {unknown} are not in granular/_params.py's QUANTITIES; use the "
        "name the package has for the quantity, or register a new one (and its row in "
        "docs/conventions.md)"
    )
    used = [p for p in params if p in SYNONYMS]
    assert not used, f"{name}: {used} are spelt {[SYNONYMS[p] for p in used]} in granular"


def test_the_registry_has_one_name_per_meaning_and_matches_scene():
    meanings = [q.meaning for q in _params.QUANTITIES.values()]
    assert len(meanings) == len(set(meanings))
    assert not set(_params.QUANTITIES) & set(SYNONYMS)
    # the theory's names for the gas are Scene's
    random = inspect.signature(Scene.random).parameters
    for name in ("n", "radius", "dim", "restitution"):
        assert name in random and name in _params.QUANTITIES, name


def test_docs_conventions_lists_every_name():
    page = Path(__file__).resolve().parent.parent / "docs" / "conventions.md"
    if not page.is_file():
        pytest.skip("not a source tree (the tests run from a copy)")
    rows = set(re.findall(r"^\| `([A-Za-z_0-9]+)` \|", page.read_text(), re.M))
    assert rows == set(_params.QUANTITIES), (
        f"docs/conventions.md's table and QUANTITIES differ: {rows ^ set(_params.QUANTITIES)}"
    )


@pytest.mark.parametrize(
    "name, f", _theory() + _plot(), ids=lambda x: x if isinstance(x, str) else ""
)
def test_every_docstring_has_parameters_with_units(name, f):
    doc = inspect.getdoc(f)
    assert re.search(r"^Parameters\n-{5,}", doc, re.M), f"{name}: no Parameters section"
    if "density" in inspect.signature(f).parameters:
        assert "number density" in doc.lower() and "L^-d" in doc, name


# -- validation by name --------------------------------------------------------------------

VALID = {
    "t": 1.0,
    "lag": 0.5,
    "start": 0.25,
    "speed": 1.0,
    "eta": 0.1,
    "box": 1.0,
    "n": 1000,
    "density": 1000.0,
    "radius": 0.025,
    "volume": 1.0,
    "mass": 1.0,
    "dim": 3,
    "restitution": 0.8,
    "temperature": 0.5,
    "temperature0": 0.66,
    "critical": 1.2,
    "a_kappa": 0.05,
    "tracer_radius": 0.1,
    "tracer_mass": 25.0,
    "chi": 1.2,
    "diffusion": 0.01,
    "viscosity": 0.3,
    "shear_rate": 1.5,
    "D0": 0.07,
    "gamma0": 9.26,
    "tau0": 10.0,
    "exponent": 5 / 6,
    "v0_sq": 0.5,
    "order": 1,
    "points": 50,
    "stiffness": 4.0,
    "gravity": 2.0,
    "height": 0.5,
    "strength": 0.5,
    "approximation": "linear",
    "kick": 0.05,
    "collisions": 3.0,
    "tangential_restitution": 0.5,
    "inertia_factor": 0.4,
    "rotational_temperature0": 0.1,
    "peak_velocity": 0.5,
    "wall_restitution": 0.9,
    "waveform": "sine",
    "wall_distance": 0.9,
    "z": 0.5,
    "area": 1.0,
    "bottom": 0.0,
    "top": 1.0,
}
BAD = {
    "positive": [-1.0, 0.0, math.nan, math.inf],
    "positive_or_inf": [-1.0, 0.0, math.nan],
    "nonnegative": [-1.0, math.nan],
    "restitution": [1.5, -0.1, math.nan],
    "packing": [1.0, -0.1],
    "dim": [1, 4],
    "beta": [1.5, -1.5, math.nan],
    "inertia": [0.0, 1.5, math.nan],
}


def _cases():
    for name, f in _theory():
        for p in inspect.signature(f).parameters.values():
            rule = _params.QUANTITIES[p.name].check
            for bad in BAD.get(rule, []):
                yield pytest.param(f, p.name, bad, id=f"{name}-{p.name}={bad}")


def _call(f, **override):
    args, kwargs = [], {}
    for p in inspect.signature(f).parameters.values():
        value = override.get(p.name, VALID[p.name])
        if p.name == "temperature" and "temperature0" in inspect.signature(f).parameters:
            value = override.get(p.name, 0.5)  # a cooled temperature below T0
        if p.name == "approximation" and f.__name__ in (
            "hydrostatic_density",
            "excess_chemical_potential",
        ):
            value = override.get(p.name, "carnahan-starling")  # there an equation of state
        if p.name == "eta" and f.__name__ == "pieprzyk_diffusion":
            value = override.get(p.name, math.pi * 0.5 / 6)  # a table: a tabulated density
        if p.kind == p.POSITIONAL_OR_KEYWORD:
            args.append(value)
        else:
            kwargs[p.name] = value
    return f(*args, **kwargs)


@pytest.mark.parametrize("name, f", _theory(), ids=lambda x: x if isinstance(x, str) else "")
def test_the_valid_values_are_valid(name, f):
    # the cases below fail for the bad value alone
    out = _call(f)
    assert out is not None


@pytest.mark.parametrize("f, name, bad", list(_cases()))
def test_an_impossible_value_is_refused_by_name(f, name, bad):
    with pytest.raises(ValueError, match=rf"^{name} must .*, got {re.escape(shown(bad))}"):
        _call(f, **{name: bad})


def test_a_bad_element_of_an_array_is_named():
    t = np.array([0.0, 1.0, -2.0])
    with pytest.raises(ValueError, match=r"^t must be >= 0 and finite, got -2 in the array"):
        theory.msd_granular(t, D0=0.07, gamma0=9.26, tau0=10.0)


def test_the_issue_examples():
    # a negative D0 gave a negative MSD; a negative radius blamed the packing fraction
    with pytest.raises(ValueError, match=r"^D0 must be positive and finite, got -1 \(D0: "):
        theory.msd_granular(1.0, D0=-1.0, gamma0=9.26, tau0=10.0)
    with pytest.raises(ValueError, match=r"^radius must be positive and finite, got -0.025"):
        theory.langevin_coefficients(
            n=1000, radius=-0.025, volume=1.0, restitution=0.8, temperature0=0.66
        )
    with pytest.raises(TypeError, match="density must be a number"):
        theory.collision_frequency(density="dense", radius=0.025, temperature=0.5)


# -- the deprecation path -------------------------------------------------------------------

T = np.array([0.0, 0.1, 1.0, 10.0])
DEPRECATED = [
    # (function, old positional args, old keywords, the new call's keywords)
    (
        theory.haff_tau0,
        (1000, 0.025, 0.8, 0.66),
        {},
        dict(density=1000, radius=0.025, restitution=0.8, temperature0=0.66),
    ),
    (
        theory.collision_frequency,
        (100, 0.025, 0.5),
        {"dim": 2},
        dict(density=100, radius=0.025, temperature=0.5, dim=2),
    ),
    (
        theory.cooling_rate,
        (1000, 0.025),
        {"xi": 0.7, "temperature": 0.5},
        dict(density=1000, radius=0.025, restitution=0.7, temperature=0.5),
    ),
    (
        theory.msd_logarithmic,
        (T, 0.07, 10.0, 2, 9.26),
        {},
        dict(D0=0.07, tau0=10.0, dim=2, gamma0=9.26),
    ),
    (theory.msd_langevin, (T, 0.07, 9.26, 2), {}, dict(D0=0.07, gamma0=9.26, dim=2)),
    (theory.haff_temperature, (T, 0.66, 10.0), {}, dict(temperature0=0.66, tau0=10.0)),
    (
        theory.langevin_coefficients,
        (1000, 0.025, 1.0, 0.8, 2 / 3),
        {},
        dict(n=1000, radius=0.025, volume=1.0, restitution=0.8, temperature0=2 / 3),
    ),
    (
        theory.udsbm_increment_msd,
        (0.5, 2.0, 0.07, 9.26, 10.0),
        {},
        dict(start=2.0, D0=0.07, gamma0=9.26, tau0=10.0),
    ),
    (
        theory.udsbm_ergodicity_breaking,
        (0.5,),
        {"starts": [0.0, 0.5, 1.0], "D0": 0.07, "gamma0": 9.26, "tau0": 10.0},
        dict(start=[0.0, 0.5, 1.0], D0=0.07, gamma0=9.26, tau0=10.0),
    ),
]


@pytest.mark.parametrize(
    "f, args, old_keywords, new", DEPRECATED, ids=lambda x: getattr(x, "__name__", "")
)
def test_the_old_call_warns_and_gives_the_same_number(f, args, old_keywords, new):
    independent = args[: len(_positional(f))]
    expected = f(*independent, **new)  # the new form: no warning (FutureWarning is an error)
    with pytest.warns(FutureWarning) as record:
        got = f(*args, **old_keywords)
    np.testing.assert_array_equal(np.asarray(got), np.asarray(expected))
    assert len(record) == 1
    message = str(record[0].message)
    assert f"granular.theory.{f.__name__}" in message
    assert f"is deprecated and removed in granular {_deprecation.REMOVAL_VERSION}" in message
    # the new call spelt out, with the keywords the new form takes
    for key in new:
        assert f"{key}=" in message.split("; call ")[1], (key, message)
    assert record[0].filename == __file__  # the warning points at the caller's line


def test_the_issue_swap_is_no_longer_silent():
    # haff_tau0(1000, .025, 0.66, 0.8) swapped xi and T0 and gave 0.566 for 0.977; the new
    # call names both
    right = theory.haff_tau0(density=1000, radius=0.025, restitution=0.8, temperature0=0.66)
    assert right == pytest.approx(0.977, abs=1e-3)
    with pytest.warns(FutureWarning, match=r"restitution=0.66, temperature0=0.8"):
        theory.haff_tau0(1000, 0.025, 0.66, 0.8)


def test_old_and_new_names_together_are_refused():
    with pytest.raises(TypeError, match="both xi= and restitution="):
        theory.haff_tau0(density=1000, radius=0.025, xi=0.8, restitution=0.8, temperature0=0.66)
    with pytest.raises(TypeError, match="multiple values for radius"):
        theory.haff_tau0(1000, 0.025, radius=0.025, restitution=0.8, temperature0=0.66)


def test_too_many_positional_arguments_say_how_many_are_taken():
    # the deprecated positional form takes up to the old signature's count, not the new one's
    n_old = len(theory.haff_tau0.old_positional)
    with pytest.raises(
        TypeError,
        match=rf"^haff_tau0\(\) takes at most {n_old} positional arguments \(deprecated: pass "
        r"them by keyword\) but 8 were given",
    ):
        theory.haff_tau0(1000, 0.025, 0.8, 0.66, 2, 1.0, 3, 4)


def test_a_missing_argument_names_the_function():
    with pytest.raises(TypeError, match=r"^udsbm_increment_msd\(\) missing a required argument"):
        theory.udsbm_increment_msd(0.5, D0=0.07, gamma0=9.26, tau0=10.0)


def test_the_old_plot_call_warns_and_draws_the_same():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from granular import plot

    times = np.array([0.0, 1.0, 2.0, 4.0])
    temperature = np.array([0.66, 0.5, 0.4, 0.3])
    new = plot.haff(times, temperature, tau0=3.0, temperature0=0.7)
    with pytest.warns(FutureWarning, match=r"tau0, temperature0 by position"):
        old = plot.haff(times, temperature, 3.0, 0.7)
    for a, b in zip(new.get_lines(), old.get_lines(), strict=True):
        np.testing.assert_array_equal(a.get_ydata(), b.get_ydata())
    plt.close("all")
