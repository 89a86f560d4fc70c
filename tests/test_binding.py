"""The binding itself, in bottleneck's style: every public entry point that hands arrays to
C (``Scene``, ``langevin.run`` and the raw ``_core.sde_run``) and the analysis functions,
given the same numbers laid out every awkward way -- a list, a non-contiguous view, a
view with negative strides, read-only, Fortran order, big-endian, an integer dtype --
gives the same results as the plain C-contiguous float64 array, and never modifies its
inputs.  A layout the raw binding cannot take must be refused with an error, never read
wrongly."""

import math

import numpy as np
import pytest

import granular
from granular import _core, analysis, langevin

from helpers import sde_reference


def _strided(a):
    """A non-contiguous view of a's values (every other row of a larger array)."""
    big = np.zeros((2 * a.shape[0], *a.shape[1:]), dtype=a.dtype) if a.ndim else a
    if a.ndim:
        big[::2] = a
        return big[::2]
    return a


def _read_only(a):
    a = a.copy()
    a.setflags(write=False)
    return a


def _reversed(a):
    """A view with negative strides."""
    return a[::-1].copy()[::-1] if a.ndim else a


def variants(a, integer=False):
    """(name, value) pairs holding a's numbers in every layout; ``integer``: a's values
    are whole numbers, so integer dtypes hold them too."""
    a = np.asarray(a, dtype=np.float64)
    out = [
        ("list", a.tolist()),
        ("strided", _strided(a)),
        ("negative strides", _reversed(a)),
        ("read-only", _read_only(a)),
        ("fortran", np.asfortranarray(a)),
        ("big-endian", a.astype(">f8")),
        ("fortran big-endian read-only", _read_only(np.asfortranarray(a.astype(">f8")))),
    ]
    if integer:
        out += [
            ("int64", a.astype(np.int64)),
            ("int64 big-endian", a.astype(">i8")),
            ("int32 big-endian", a.astype(">i4")),
            ("uint8", a.astype(np.uint8)) if np.all(a >= 0) else ("int16", a.astype(np.int16)),
            ("int64 list", a.astype(np.int64).tolist()),
        ]
    return out


def _snapshot(value):
    """What an input holds: its numbers, and for an array its dtype, strides and flags."""
    if isinstance(value, list):
        return repr(value)
    return value.copy(), value.dtype, value.strides, value.flags.writeable


def _unchanged(value, before):
    """The input still holds its numbers, in its own dtype and layout."""
    if isinstance(value, list):
        assert repr(value) == before
    else:
        values, dtype, strides, writeable = before
        assert (value.dtype, value.strides, value.flags.writeable) == (dtype, strides, writeable)
        np.testing.assert_array_equal(value, values)


# -- Scene -----------------------------------------------------------------------------------

# four disks on an integer grid in a 12 x 12 box: every input can be an integer
POS = np.array([[1.0, 1.0], [4.0, 1.0], [1.0, 7.0], [7.0, 4.0]])
VEL = np.array([[1.0, 0.0], [-1.0, 2.0], [0.0, -1.0], [3.0, 1.0]])
RADII = np.array([1.0, 1.0, 1.0, 1.0])
MASSES = np.array([1.0, 2.0, 1.0, 3.0])


def _scene(**arrays):
    kw = dict(positions=POS, velocities=VEL, radii=RADII, masses=MASSES)
    kw.update(arrays)
    return granular.Scene(
        kw["positions"], kw["velocities"], kw["radii"], kw["masses"], box=12.0, restitution=0.9
    )


@pytest.fixture(scope="module")
def plain_scene_run():
    s = _scene()
    tr = granular.Simulation(s).run(
        t_stop=3.0, sample_times=[0.0, 1.5, 3.0], store=("positions", "velocities")
    )
    return s, tr


@pytest.mark.parametrize("name", ["positions", "velocities", "radii", "masses"])
def test_scene_takes_every_layout(name, plain_scene_run):
    plain, plain_tr = plain_scene_run
    base = {"positions": POS, "velocities": VEL, "radii": RADII, "masses": MASSES}[name]
    for label, value in variants(base, integer=True):
        before = _snapshot(value)
        s = _scene(**{name: value})
        _unchanged(value, before)
        for attr in ("positions", "velocities", "radii", "masses"):
            got = getattr(s, attr)
            assert got.dtype == np.float64 and got.flags.c_contiguous, (label, attr)
            np.testing.assert_array_equal(got, getattr(plain, attr), err_msg=label)
        tr = granular.Simulation(s).run(
            t_stop=3.0, sample_times=[0.0, 1.5, 3.0], store=("positions", "velocities")
        )
        np.testing.assert_array_equal(tr.positions, plain_tr.positions, err_msg=label)
        np.testing.assert_array_equal(tr.velocities, plain_tr.velocities, err_msg=label)
        _unchanged(value, before)


def test_a_scene_does_not_share_memory_with_its_inputs():
    pos = POS.copy()
    s = _scene(positions=pos)
    pos[0, 0] = 99.0
    assert s.positions[0, 0] == 1.0


# -- langevin.run and the raw sde_run --------------------------------------------------------

RUN = dict(
    gamma0=9.26,
    D0=0.072,
    dt=0.01,
    t_stop=1.0,
    tau0=0.972,
    scheme="exact",
    store_positions=True,
    seed=3,
)
SAMPLES = np.array([0.0, 0.1, 0.25, 0.5, 1.0])
LAGS = np.array([0.01, 0.2, 0.5])


@pytest.fixture(scope="module")
def plain_langevin():
    return langevin.run(6, sample_times=SAMPLES, tamsd_lags=LAGS, **RUN)


def _same_langevin(r, plain, label):
    for name in (
        "times",
        "msd_total",
        "msd_per_dimension",
        "v2",
        "tamsd_lags",
        "tamsd_per_particle",
        "positions",
        "final_velocities",
    ):
        np.testing.assert_array_equal(
            getattr(r, name), getattr(plain, name), err_msg=f"{label}: {name}"
        )


@pytest.mark.parametrize("which", ["sample_times", "tamsd_lags"])
def test_langevin_run_takes_every_layout(which, plain_langevin):
    base = {"sample_times": SAMPLES, "tamsd_lags": LAGS}
    for label, value in variants(base[which]):
        before = _snapshot(value)
        r = langevin.run(6, **{**base, which: value}, **RUN)
        _unchanged(value, before)
        _same_langevin(r, plain_langevin, label)


def test_langevin_run_takes_integer_times():
    """Whole-number times in integer dtypes: the same run as in float64."""
    kw = dict(RUN, dt=0.5, t_stop=8.0)
    plain = langevin.run(4, sample_times=[0.0, 1.0, 2.0, 8.0], tamsd_lags=[1.0, 4.0], **kw)
    for label, value in variants([0.0, 1.0, 2.0, 8.0], integer=True):
        lags = np.array([1, 4], dtype=np.int32)
        r = langevin.run(4, sample_times=value, tamsd_lags=lags, **kw)
        _same_langevin(r, plain, label)


SDE = dict(model="udsbm", scheme="exact", gamma0=9.26, D0=0.072, tau0=0.972, dt=0.05, n_steps=40)


def _raw(x=None, v=None, steps=None, lags=None, v0=None):
    """One whole run through _core.sde_run of 3 particles in 2D with the given buffers
    (None: fresh plain ones); returns the buffers after the call."""
    v0 = np.array([[0.5, -0.2], [0.1, 0.3], [-0.4, 0.0]]) if v0 is None else v0
    x = np.zeros((3, 2)) if x is None else x
    v = v0.copy() if v is None else v
    steps = np.array([0, 5, 20, 40], dtype=np.int64) if steps is None else steps
    lags = np.array([1, 17, 40], dtype=np.int64) if lags is None else lags
    x2, v2 = np.zeros((4, 2)), np.zeros((4, 2))
    pos, tamsd = np.zeros((4, 3, 2)), np.zeros((3, 3))
    ring = np.zeros(_core.sde_ring_size(2, np.array([1, 17, 40], dtype=np.int64)))
    _core.sde_run(
        dim=2,
        model=1,
        scheme=1,
        gamma0=SDE["gamma0"],
        D0=SDE["D0"],
        tau0=SDE["tau0"],
        dt=SDE["dt"],
        key=77,
        n=3,
        first=0,
        step_from=0,
        step_to=40,
        n_steps=40,
        x=x,
        v=v,
        sample_steps=steps,
        x2=x2,
        v2=v2,
        positions=pos,
        lags=lags,
        tamsd=tamsd,
        ring=ring,
    )
    return x, v, x2, pos, tamsd


def test_the_raw_sde_run_is_the_reference():
    v0 = np.array([[0.5, -0.2], [0.1, 0.3], [-0.4, 0.0]])
    _, v, _, pos, _ = _raw()
    xs, vs = sde_reference.run(v0, 77, **SDE)
    np.testing.assert_allclose(pos, xs[[0, 5, 20, 40]], rtol=0, atol=1e-13)
    np.testing.assert_allclose(v, vs[-1], rtol=0, atol=1e-13)


# The raw binding must check byte order as well as the type number: ">i8" and ">f8" are
# NPY_INT64 / NPY_FLOAT64 too, and C would read their bytes as native numbers.


def _labels(integer):
    return [label for label, _ in variants(np.zeros(2), integer=integer)]


@pytest.mark.parametrize("label", _labels(integer=True))
@pytest.mark.parametrize("which", ["steps", "lags"])
def test_the_raw_sde_run_reads_its_inputs_right_or_refuses_them(which, label):
    """sample_steps and lags are read in place: any layout other than a C-contiguous
    native int64 array must give the same run or be refused by name, never misread (a
    refusal for another reason, e.g. misread steps that do not increase, is a misread)."""
    plain = _raw()
    base = {"steps": np.array([0, 5, 20, 40]), "lags": np.array([1, 17, 40])}[which]
    value = dict(variants(base, integer=True))[label]
    before = _snapshot(value)
    try:
        got = _raw(**{which: value})
    except ValueError as exc:
        assert "C-contiguous native-order int64" in str(exc), exc
    else:
        for a, b in zip(got, plain, strict=True):
            np.testing.assert_array_equal(a, b)
    _unchanged(value, before)


@pytest.mark.parametrize("label", _labels(integer=False))
@pytest.mark.parametrize("which", ["x", "v"])
def test_the_raw_sde_run_writes_its_state_in_place_or_refuses(which, label):
    """x and v are the state, written back: a buffer C cannot write in place as native
    float64 (a list, read-only, non-contiguous, Fortran, big-endian) must be refused,
    since a converted copy would silently drop the result."""
    base = {"x": np.zeros((3, 2)), "v": np.array([[0.5, -0.2], [0.1, 0.3], [-0.4, 0.0]])}
    value = dict(variants(base[which]))[label]
    with pytest.raises(ValueError, match=f"{which} must be"):
        _raw(**{which: value})


# -- analysis --------------------------------------------------------------------------------


def _positions():
    """(T, N, d) whole-number positions: every dtype holds them."""
    return np.cumsum(np.random.default_rng(5).integers(-3, 4, size=(9, 4, 3)), axis=0)


CASES = {
    "msd": (lambda a: analysis.msd(a), _positions),
    "msd per dimension, particles": (
        lambda a: analysis.msd(a, per_dimension=True, particles=[0, 2]),
        _positions,
    ),
    "tamsd fft": (lambda a: analysis.tamsd(a, lag_samples=[1, 3, 8]), _positions),
    "tamsd direct": (
        lambda a: analysis.tamsd(
            a, [1.0, 3.0], times=np.arange(9.0), method="direct", per_particle=True
        ),
        _positions,
    ),
    "temperature": (lambda a: analysis.temperature(a, masses=2.0), _positions),
    "speed_histogram": (lambda a: analysis.speed_histogram(a, bins=5), _positions),
    "speed_statistics": (lambda a: analysis.speed_statistics(a[-1]), _positions),
    "ensemble_mean": (lambda a: analysis.ensemble_mean(a), _positions),
    "diffusivity": (
        lambda a: analysis.diffusivity(np.arange(1.0, 10.0), a[:, 0, 0] ** 2),
        _positions,
    ),
    "fit_slope": (lambda a: analysis.fit_slope(np.arange(1.0, 10.0), a[:, 1, 2]), _positions),
}


def _same(got, want, label):
    if isinstance(want, dict):
        assert got.keys() == want.keys()
        for k in want:
            _same(got[k], want[k], label)
    elif isinstance(want, tuple):
        for g, w in zip(got, want, strict=True):
            _same(g, w, label)
    else:
        np.testing.assert_array_equal(got, want, err_msg=label)


@pytest.mark.parametrize("case", sorted(CASES))
def test_analysis_takes_every_layout(case):
    """The analysis functions convert what they are given; the layout changes no bit."""
    fn, make = CASES[case]
    base = make().astype(np.float64)
    want = fn(base)

    def through(value):
        return fn(np.asarray(value)) if isinstance(value, list) else fn(value)

    for label, value in variants(base, integer=True):
        before = _snapshot(value)
        _same(through(value), want, f"{case}, {label}")
        _unchanged(value, before)


def test_analysis_takes_times_and_series_in_every_layout():
    t = np.arange(1.0, 10.0)
    y = 2.0 * t + np.array([0.0, 1, -1, 0, 2, -2, 0, 1, -1])
    temps = 100.0 / (1.0 + t / 4.0) ** 2
    want = (analysis.fit_slope(t, y), analysis.diffusivity(t, y), analysis.fit_haff_tau0(t, temps))
    for label, value in variants(t, integer=True):
        before = _snapshot(value)
        got = (
            analysis.fit_slope(value, y),
            analysis.diffusivity(value, y),
            analysis.fit_haff_tau0(value, temps),
        )
        _same(got, want, label)
        _unchanged(value, before)
    for label, value in variants(y, integer=True):
        _same(analysis.fit_slope(t, value), want[0], label)
    assert math.isfinite(want[2][0])
