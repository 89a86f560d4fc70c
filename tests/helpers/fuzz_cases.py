"""Random bad and edge inputs for tests/test_fuzz.py, and the worker process that runs them.

A case is one call -- ``Scene(...)``, ``Scene.random(...)``, ``Simulation(scene).run(...)``,
``langevin.run(...)`` (its ``threads=`` too), a scene with a ``TabulatedRestitution`` table, or
``Simulation.load`` of a checkpoint -- drawn by a seeded generator: a valid baseline with none,
one or two of its arguments replaced by something wrong or extreme (wrong shapes and types,
NaN/inf, zero and negative values, scales at the ends of float64, overlapping particles,
far-away boxes, odd sample times and stop criteria, tables out of order or range, checkpoints
truncated, bit-flipped or crafted: tests/helpers/checkpoint_fuzz.py). ``make_cases(seed,
count)`` gives the same list in every process, so the worker and the test only exchange case
numbers.

A case passes when the call raises GranularError, ValueError or TypeError with a message
(MemoryError too where the input asks for more memory than a machine has; a checkpoint only
CheckpointError), or returns a result that passes the invariants: every number finite, no two
particles overlapping at any sample, the kinetic energy conserved when pair collisions and
walls are elastic and never gained without heated walls, every requested sample returned when
the run reaches its t_stop, Scene.random's radii where they were asked for, a Langevin run's
results the same to the bit for any number of threads, an unaltered checkpoint continuing bit
for bit. An unmutated baseline must not raise at all (but for an inelastic collapse, which is
physics).
"""

from __future__ import annotations

import json
import math
import os
import sys
import traceback
import warnings

import numpy as np

NAN, INF = math.nan, math.inf
# Floats at the edges of float64: subnormal, near the square root of the extremes, near the max
EXTREME = [
    NAN,
    INF,
    -INF,
    0.0,
    -0.0,
    -1.0,
    5e-324,
    1e-310,
    1e-300,
    1e-154,
    1e154,
    1e300,
    1.7976931348623157e308,
]
# An elastic run may drift by rounding only: ~1e-16 relative per collision (<= 2e-15 over
# 1e7 collisions measured); these runs have < 1e5 events, so 1e-10 is far above rounding
# and far below any real loss (a lost or doubled impulse changes E by O(1/N)).
ENERGY_RTOL = 1e-10
EVENTS = 20_000  # the event budget that keeps a case's run short


class Opaque:
    """A value of a type no parameter accepts, with a stable repr for the report."""

    def __repr__(self):
        return "Opaque()"


WRONG_TYPES = ["abc", None, {"a": 1}, 1 + 1j, Opaque(), b"x"]


# -- valid baselines ------------------------------------------------------------------------


def _grid(rng, n, dim, length):
    """n centres on a cubic grid in [0, length]^dim and the grid spacing."""
    k = math.ceil(n ** (1 / dim) - 1e-9)
    idx = np.array(np.unravel_index(rng.permutation(k**dim)[:n], (k,) * dim)).T
    spacing = length / k
    return (idx + 0.5) * spacing, spacing


def _scene_params(rng):
    n = int(rng.integers(1, 21))
    dim = int(rng.choice([2, 3]))
    length = float(rng.choice([1.0, 2.5, 0.5]))
    pos, spacing = _grid(rng, n, dim, length)
    boundary = str(rng.choice(["periodic", "walls"]))
    radius = spacing * rng.uniform(0.1, 0.4)
    if boundary == "periodic":
        radius = min(radius, length / 4.5)  # the box must be > 2 diameters wide
    p = dict(
        positions=pos,
        velocities=rng.normal(size=(n, dim)),
        radii=np.full(n, radius),
        masses=rng.uniform(0.5, 2.0, n),
        box=length,
        boundary=boundary,
        wall_restitution=float(rng.choice([1.0, 1.0, 0.9])),
        restitution=float(rng.choice([1.0, 1.0, 0.9, 0.5])),
        contact_duration=float(rng.choice([0.0, 0.0, 1e-3])),
        driving=_driving(rng, n),
    )
    if boundary == "periodic" and rng.random() < 0.3:  # Lees-Edwards shear (offset 0: the
        # grid start may overlap through displaced images; the mutations try offsets)
        p["shear_rate"] = float(rng.choice([0.5, -2.0, 5.0]))
    return p


def _driving(rng, n):
    """A random driving force now and then (pairs: n >= 2), kicking a few times per unit
    time so that a short run sees kicks and collisions alike."""
    from granular import PairThermostat, WhiteNoise

    u = rng.random()
    if n < 2 or u < 0.7:
        return None
    seed = int(rng.integers(0, 2**53))
    if u < 0.85:
        return WhiteNoise(float(rng.uniform(0.1, 2.0)), float(rng.uniform(1.0, 50.0)), seed)
    return PairThermostat(float(rng.uniform(0.1, 2.0)), float(rng.uniform(1.0, 50.0)), seed)


def _random_params(rng, max_n=50):
    n = int(rng.integers(1, max_n + 1))
    dim = int(rng.choice([2, 3]))
    length = float(rng.choice([1.0, 2.0]))
    # the lattice start, melted by EDMD; in 2D only: a 3D box holds few fcc cells at n <= 50,
    # and Scene.random refuses packings from 0.3 that such a small lattice cannot reach
    dense = dim == 2 and n >= 20 and rng.random() < 0.2
    packing = rng.uniform(0.3, 0.45) if dense else rng.uniform(0.01, 0.15)
    if not dense and rng.random() < 0.4:  # a mixture of 2-3 species, size ratios up to 3
        sizes = rng.uniform(1.0, 3.0, int(rng.integers(2, 4)))
        rel = sizes[rng.integers(0, len(sizes), n)]
    else:
        rel = np.ones(n)
    unit = math.pi if dim == 2 else 4 * math.pi / 3  # volume of a unit disk / sphere
    scale = (packing * length**dim / (unit * np.sum(rel**dim))) ** (1 / dim)
    radius = rel * scale if len(set(rel)) > 1 else float(scale)
    boundary = str(rng.choice(["periodic", "walls"]))
    if boundary == "periodic" and np.max(radius) > length / 4.5:
        boundary = "walls"
    p = dict(
        n=n,
        radius=radius,
        dim=dim,
        box=length,
        boundary=boundary,
        restitution=float(rng.choice([1.0, 0.9])),
        seed=int(rng.integers(0, 2**31)),
    )
    if rng.random() < 0.3:
        p["temperature"] = float(rng.uniform(0.1, 3))
    if boundary == "walls" and rng.random() < 0.3:
        p["wall_restitution"] = float(rng.choice([0.9, 1.0]))
    return p


def _run_params(rng):
    scene = _random_params(rng, max_n=30)
    t_stop = float(rng.choice([0.5, 1.0, 2.0]))
    run = dict(
        t_stop=t_stop,
        sample_times=np.linspace(0.0, t_stop, int(rng.integers(2, 8))),
        stop_when={"events": EVENTS},
    )
    return dict(scene=scene, run=run)


def _langevin_params(rng):
    p = dict(
        n=int(rng.integers(1, 51)),
        gamma0=float(rng.uniform(0.1, 10)),
        D0=float(rng.uniform(0.1, 2)),
        dt=0.01,
        t_stop=float(rng.choice([0.5, 1.0, 2.0])),
        scheme=str(rng.choice(["em", "exact"])),
        dim=int(rng.integers(1, 4)),
        initial=str(rng.choice(["thermal", "fixed"])),
        seed=int(rng.integers(0, 2**31)),
    )
    if rng.random() < 0.4:
        p["tau0"] = float(rng.uniform(1, 100))
        p["initial"] = str(rng.choice(["thermal", "udsbm", "fixed"]))
    if rng.random() < 0.3:
        p["tamsd_lags"] = [0.1, 0.2]
    if rng.random() < 0.3:
        p["store_positions"] = True
    return p


# -- mutations: (label, function(rng, params)); labels starting "big:" may raise MemoryError --


def _set(key, values):
    def mutate(rng, p):
        v = values[int(rng.integers(len(values)))]
        p[key] = v
        return f"{key}={v!r}"

    return mutate


def _entry(key, values):
    """One entry of an array parameter set to a special value."""

    def mutate(rng, p):
        a = np.array(p[key], dtype=float)
        v = values[int(rng.integers(len(values)))]
        a.flat[int(rng.integers(a.size))] = v
        p[key] = a
        return f"{key}[one entry]={v!r}"

    return mutate


def _shape(key):
    def mutate(rng, p):
        a = np.asarray(p[key])
        choice = int(rng.integers(6))
        p[key] = [
            a.reshape(-1),
            a[:-1],
            np.concatenate([a, a[:1]]),
            a[None],
            a.reshape(len(a), -1)[:, :1],
            np.zeros((0, *a.shape[1:])),
        ][choice]
        return f"{key} reshaped to {np.shape(p[key])}"

    return mutate


def _scale(factor):
    """Every length (positions, radii, box) times factor: the same scene at another scale."""

    def mutate(rng, p):
        with np.errstate(over="ignore", under="ignore"):  # to inf or 0 on purpose
            p["positions"] = p["positions"] * factor
            p["radii"] = p["radii"] * factor
            p["box"] = p["box"] * factor
        return f"all lengths x {factor:g}"

    return mutate


def _far_box(offset):
    def mutate(rng, p):
        p["positions"] = p["positions"] + offset
        p["box"] = (offset, offset + p["box"])
        return f"box shifted to {offset:g}"

    return mutate


def _overlap(kind):
    def mutate(rng, p):
        pos = np.array(p["positions"], dtype=float)
        if len(pos) < 2:
            pos = np.vstack([pos, pos])
            p["velocities"] = np.vstack([p["velocities"], p["velocities"]])
            p["radii"] = np.concatenate([p["radii"], p["radii"]])
            p["masses"] = np.concatenate([p["masses"], p["masses"]])
        gap = {"same place": 0.0, "overlap 1e-9": 1 - 1e-9, "touching": 1.0}[kind]
        pos[1] = pos[0]
        pos[1, 0] += gap * (p["radii"][0] + p["radii"][1])
        p["positions"] = pos
        return f"particles 0 and 1: {kind}"

    return mutate


def _outside(rng, p):
    pos = np.array(p["positions"], dtype=float)
    pos[0, 0] = float(rng.choice([-0.5, 1.5])) * p["box"]
    p["positions"] = pos
    return "particle 0 outside the box"


def _velocity_scale(rng, p):
    f = float(rng.choice([1e154, 1e200, 1e-300, 0.0]))
    p["velocities"] = np.asarray(p["velocities"]) * f
    return f"velocities x {f:g}"


def _mass_spread(rng, p):
    m = np.ones(len(p["masses"]))
    m[::2] = 1e-300
    m[1::2] = 1e300
    p["masses"] = m
    return "masses alternating 1e-300 and 1e300"


def _bad_driving():
    """Drivings the classes accept and the engine or the run must refuse or survive: huge
    kicks, a total rate too small to time (rate N / 2 below 1e-140), heating that blows the
    gas up, kicks far more frequent than the event budget."""
    from granular import PairThermostat, WhiteNoise

    return [
        WhiteNoise(1e130, 1e130),
        WhiteNoise(1e120, 1e-10),
        PairThermostat(1e-130, 1e-130),
        PairThermostat(1e130, 1.0),
        WhiteNoise(1.0, 1e8),
        WhiteNoise(1.0, 1e-139, seed=2**53 - 1),
    ]


_BAD_DRIVING = _bad_driving()


def _gravity(rng, p):
    """Gravity along the last axis of any strength from the representable to the absurd
    (or NaN), with or without the free-fall frame (which a periodic box needs)."""
    dim = np.asarray(p["positions"]).shape[1]
    g = np.zeros(dim)
    g[-1] = -float(rng.choice([1.0, 50.0, 1e-300, 1e-150, 1e140, 1e279, 1e300, NAN, -INF]))
    g[0] = float(rng.choice([0.0, 0.0, 0.5]))
    p["gravity"] = g
    p["free_fall"] = bool(rng.random() < 0.5)
    return f"gravity={g.tolist()} free_fall={p['free_fall']}"


SCENE_MUTATIONS = [
    _entry("positions", [NAN, INF, -INF]),
    _shape("positions"),
    _set("positions", [*WRONG_TYPES, [[0.1, 0.1], [0.5]], np.array([["a", "b"]])]),
    _entry("velocities", [NAN, INF, 1e154, 1e300]),
    _shape("velocities"),
    _set("velocities", WRONG_TYPES),
    _velocity_scale,
    _entry("radii", EXTREME),
    _shape("radii"),
    _set("radii", EXTREME + WRONG_TYPES),
    _entry("masses", EXTREME),
    _shape("masses"),
    _set("masses", EXTREME + WRONG_TYPES),
    _mass_spread,
    _set("box", EXTREME + WRONG_TYPES + [(1.0, 0.0), ([0, 0], [1, 1, 1]), (0.0, NAN)]),
    _far_box(1e8),
    _far_box(1e13),
    _far_box(1e15),
    _scale(1e-300),
    _scale(1e300),
    _scale(1e-150),
    _scale(1e150),
    _set("boundary", ["wall", "", None, 3, "PERIODIC"]),
    _set("wall_restitution", [*EXTREME, 2.0, 1e3, *WRONG_TYPES]),
    _set("restitution", [*EXTREME, -0.1, 1.1, 1 - 1e-16, "0.5", 1j, None]),
    _set("contact_duration", [*EXTREME, "x", None]),
    _set("shear_rate", [*EXTREME, 1e200, 1e-200, "x", None, 1j]),
    _set("shear_offset", [*EXTREME, 0.99, 1e200, "x", None]),
    _set("driving", ["x", 0.5, {"strength": 1.0}, *_BAD_DRIVING]),
    _gravity,
    _gravity,
    _set("gravity", [*WRONG_TYPES[:1], 1j, [0.0, 0.0, 0.0, -1.0], [[0.0, -1.0]], 1.0]),
    _set("free_fall", ["yes", None, 2, NAN]),
    _overlap("same place"),
    _overlap("overlap 1e-9"),
    _overlap("touching"),
    _outside,
]

RANDOM_MUTATIONS = [
    _set("n", [0, -1, 1.5, "3", True, NAN, INF, None, 2**62, 10**30, np.int64(3), 1.0]),
    _set("radius", EXTREME + WRONG_TYPES + [0.6, [0.01, 0.02], np.array([[0.01]])]),
    _set("dim", [0, 1, 4, "3", 2.5, True, None, NAN]),
    _set(
        "box",
        EXTREME
        + WRONG_TYPES
        + [(1e15, 1e15 + 1), (1e13, 1e13 + 1), (1.0, 0.0), ([0, 0], [1, 1]), 1e-300],
    ),
    _set("boundary", ["wall", None, 0]),
    _set("restitution", [*EXTREME, -0.1, 1.1, "1"]),
    _set("speed", EXTREME + WRONG_TYPES + [1e200]),
    _set("temperature", EXTREME + WRONG_TYPES),
    _set("mass", EXTREME + WRONG_TYPES + [1e308, 5e-324, [1.0, 2.0]]),
    _set("wall_restitution", [*EXTREME, 2.0, 1e3]),
    _set("contact_duration", [*EXTREME, "x"]),
    _set("seed", [-1, "abc", 1.5, NAN, [1, 2], 2**200]),
    _set("remove_drift", ["no", None, 2]),
]


def _scene_key(key, values):
    def mutate(rng, p):
        v = values[int(rng.integers(len(values)))]
        p["scene"][key] = v
        return f"scene {key}={v!r}"

    return mutate


def _run_key(key, values, unbounded=False):
    """A run argument; ``unbounded`` drops the event budget and t_stop (criteria that must end
    on their own or be refused)."""

    def mutate(rng, p):
        v = values[int(rng.integers(len(values)))]
        p["run"][key] = v
        if unbounded:
            p["run"].pop("t_stop", None)
            p["run"].pop("sample_times", None)
        return f"run {key}={v!r}" + (" (no t_stop, no event budget)" if unbounded else "")

    return mutate


def _unbounded_t_stop(rng, p):
    """t_stop infinite, absent or astronomic, with the event budget kept: the run must end."""
    v = [INF, None, 1e300][int(rng.integers(3))]
    p["run"]["t_stop"] = v
    p["run"]["stop_when"] = {"events": EVENTS}
    return f"run t_stop={v!r} (event budget kept)"


def _huge_event_budget(rng, p):
    """An event budget past int64, with a short t_stop that ends the run."""
    p["run"]["t_stop"] = 0.5
    p["run"]["sample_times"] = None
    p["run"]["stop_when"] = {"events": 2**70}
    return "run stop_when={'events': 2**70} with t_stop=0.5"


def _run_twice(rng, p):
    p["again"] = dict(t_stop=float(rng.choice([0.1, NAN, 1e300])))
    return f"a second run to t_stop={p['again']['t_stop']!r}"


def _round_sample(rng, p):
    t = p["run"]["t_stop"]
    p["run"]["sample_times"] = [t + 5e-13 * t, t + 9e-13 * t]
    return "sample_times within rounding past t_stop"


def _big_n(rng, p):
    p["n"] = int(rng.choice([2**62, 2**40]))
    return f"big: n={p['n']}"


def _stress_params(rng):
    """A run baseline with the stress tensor kept (Simulation(stress=True))."""
    return dict(_run_params(rng), knobs={"stress": True})


def _stress_knob(rng, p):
    """Simulation(stress=...): the tensor kept (True, NumPy's True) or a refused value."""
    v = [True, np.bool_(True), "yes", 1, None][int(rng.integers(5))]
    p["knobs"] = {"stress": v}
    return f"Simulation(stress={v!r})"


RUN_MUTATIONS = [
    _scene_key("restitution", [0.0, 0.5, 0.99]),
    _scene_key("wall_restitution", [0.5, 1.2, 2.0, 1e3]),
    _scene_key("contact_duration", [1e-4, 1e-2, 1e3]),
    _scene_key("speed", [1e154, 1e-154, 0.0]),
    _scene_key("mass", [1e-300, 1e300, 1e-310, 1e308]),
    _run_key("t_stop", [0.0, -1.0, NAN, "1", 5e-324, [1.0]]),
    _unbounded_t_stop,
    _huge_event_budget,
    _run_key(
        "sample_times",
        [
            [],
            [NAN],
            [0.5, 0.2],
            [[0.0, 1.0]],
            [0.0, 3.0],
            [-1.0, 0.0],
            ["a"],
            [0.0, 0.0],
            np.linspace(0, 0.5, 10**4),
            5.0,
            None,
            [0.0, 5e-324, 1e-323],
        ],
    ),
    _round_sample,
    _run_key(
        "stop_when",
        [
            {"kinetic_energy": 0.1},
            {"kinetic_energy": 0.0},
            {"kinetic_energy": 1e-300},
            {"collisions_per_particle": 5},
        ],
        unbounded=True,
    ),
    _run_key(
        "stop_when",
        [
            {"kinetic_energy": NAN},
            {"kinetic_energy": INF},
            {"collisions_per_particle": 0},
            {"collisions_per_particle": -1},
            {"collisions_per_particle": NAN},
            {"events": -1},
            {"events": 1.5},
            {"events": True},
            {"events": 0},
            {"bogus": 1},
            "kinetic_energy",
            5,
            {"events": "10"},
        ],
    ),
    _run_key("store", [(), ("positions",), ("foo",), "positions", None, 3]),
    _run_twice,
]

LANGEVIN_MUTATIONS = [
    _set("n", [0, -1, 1.5, "5", True, NAN, None]),
    _big_n,
    _set("gamma0", EXTREME + WRONG_TYPES + [250.0]),
    _set("D0", EXTREME + WRONG_TYPES),
    _set("dt", EXTREME + WRONG_TYPES + [10.0]),
    _set("t_stop", EXTREME + WRONG_TYPES),
    _set("tau0", EXTREME + WRONG_TYPES),
    _set("model", ["langevin", "udsbm", "foo", None, 3]),
    _set("scheme", ["rk4", None, "EM", 1]),
    _set("dim", [0, 4, "2", 2.5, None]),
    _set(
        "sample_times",
        [[], [NAN], [0.5, 0.2], [[0.0, 1.0]], [0.0, 1e300], [-1.0], ["a"], 5.0, [0.0, 1e-300]],
    ),
    _set("tamsd_lags", [[], [0.0], [-0.1], [NAN], [1e300], [0.2, 0.1], [[0.1]], ["a"], [1e-300]]),
    _set("initial", ["foo", None, 3]),
    _set("speed", EXTREME + WRONG_TYPES),
    _set("seed", [-1, "abc", 1.5, NAN]),
    _set("store_positions", ["yes", None]),
    # external forces (Langevin model only): lengths that fit one dim but not another, NaN,
    # huge, negative, and stiffnesses past Euler-Maruyama's limit at dt = 0.01
    _set("gravity", [[0.0, 0.0, -9.8], [0.0, -9.8], [-9.8], [NAN], "down", [1e300], [1e300] * 3]),
    _set("trap_stiffness", [1.0, 0.0, -1.0, NAN, 1e300, [1.0, 2.0], [5.0] * 3, 2000.0, None]),
    _set("trap_centre", [[0.5], [0.0, 1.0], [NAN] * 3, [1e300] * 2]),
]


def _power(rng, lo, hi):
    """10^u, u uniform in [lo, hi]: a scale of a random order of magnitude."""
    return float(10.0 ** rng.uniform(lo, hi))


def _either_end(rng, lo, hi):
    """A scale near float64's top or bottom: 10^+-u, u uniform in [lo, hi]."""
    return _power(rng, lo, hi) ** (1 if rng.random() < 0.5 else -1)


def _shown(p, *keys):
    """The label of a mutation that set these keys."""
    return ", ".join(f"{k}={p[k]!r}" for k in keys)


def _huge_speed(rng, p):
    p["initial"], p["speed"] = "fixed", _power(rng, 130, 160)
    return _shown(p, "initial", "speed")


def _ballistic_reach(rng, p):  # speed * t_stop around the limit 1e140, speed itself inside
    p["t_stop"] = _power(rng, 20, 60)
    p["dt"] = p["t_stop"] / int(rng.integers(10, 200))
    p["gamma0"] = float(rng.uniform(0.1, 10)) / p["t_stop"]
    p["initial"], p["speed"] = "fixed", _power(rng, 80, 120)
    return _shown(p, "initial", "speed", "gamma0", "dt", "t_stop")


def _extreme_gamma0(rng, p):
    p["gamma0"], p["scheme"] = _either_end(rng, 130, 150), "exact"
    return _shown(p, "gamma0", "scheme")


def _extreme_D0(rng, p):
    p["D0"] = _either_end(rng, 270, 290)
    return _shown(p, "D0")


def _extreme_times(rng, p):  # the times and the rate scaled together
    p["t_stop"] = _either_end(rng, 130, 150)
    p["dt"] = p["t_stop"] / int(rng.integers(10, 200))
    p["gamma0"] = float(rng.uniform(0.1, 10)) / p["t_stop"]
    return _shown(p, "dt", "t_stop", "gamma0")


def _extreme_tau0(rng, p):
    p["model"], p["tau0"], p["initial"] = "udsbm", _either_end(rng, 130, 150), "thermal"
    return _shown(p, "model", "tau0", "initial")


def _extreme_mass(rng, p):
    p["mass"] = _either_end(rng, 270, 290)
    return _shown(p, "mass")


def _heavy_and_fast(rng, p):  # the temperature, mass v^2, around 1e280
    p["mass"], p["initial"], p["speed"] = _power(rng, 250, 280), "fixed", _power(rng, 0, 20)
    return _shown(p, "mass", "initial", "speed")


def _steep_decay(rng, p):  # UDSBM's friction at t_stop, gamma0 (1 + t/tau0)^-a, down to ~1e-600
    p["model"], p["initial"] = "udsbm", "thermal"
    p["tau0"], p["exponent"] = _power(rng, -2, 0), _power(rng, 0, 2.5)
    return _shown(p, "model", "tau0", "exponent", "initial")


# Scales around the limits of float64 (granular._scales): each accepted run must give finite
# results, every refused one a clear error.
LANGEVIN_SCALE_MUTATIONS = [
    _huge_speed,
    _ballistic_reach,
    _extreme_gamma0,
    _extreme_D0,
    _extreme_times,
    _extreme_tau0,
    _extreme_mass,
    _heavy_and_fast,
    _steep_decay,
]


def _in_scene(mutate):
    """A scene mutation applied to the scene of a case that holds one (p["scene"])."""

    def wrapped(rng, p):
        return "scene: " + mutate(rng, p["scene"])

    return wrapped


def _table_params(rng):
    """A scene whose pair or wall restitution is a table of 1-6 points, decreasing in speed."""
    k = int(rng.integers(1, 7))
    speeds = np.sort(rng.uniform(0.0, 4.0, k))
    if rng.random() < 0.5:
        speeds[0] = 0.0
    scene = _scene_params(rng)
    side = str(rng.choice(["restitution", "wall_restitution"]))
    return dict(scene=scene, side=side, speeds=speeds, values=np.sort(rng.uniform(0.3, 1, k))[::-1])


def _table_order(rng, p):
    speeds = np.array(p["speeds"], dtype=float)
    if len(speeds) < 2:
        speeds = np.append(speeds, speeds[-1] + 1.0)
        p["values"] = np.append(p["values"], 0.5)
    how = int(rng.integers(3))
    speeds = [speeds[::-1], np.concatenate([speeds[:1], speeds[:-1]]), -speeds][how]
    p["speeds"] = speeds
    return ["speeds decreasing", "a speed repeated", "speeds negated"][how]


def _table_long(rng, p):
    from granular.restitution import TABLE_MAX

    k = int(rng.choice([TABLE_MAX + 1, 10**5]))
    p["speeds"] = np.linspace(0.0, 10.0, k)
    p["values"] = np.linspace(1.0, 0.5, k)
    return f"a table of {k} points"


TABLE_MUTATIONS = [
    _entry("speeds", [NAN, INF, -INF, -1.0, -0.0, 1e308, 5e-324]),
    _entry("values", [NAN, INF, -1e-300, 1.0 + 1e-15, 2.0, 0.0, 1.0]),
    _shape("speeds"),
    _shape("values"),
    _set("speeds", [*WRONG_TYPES, [], [[0.0, 1.0], [2.0, 3.0]], 1.0]),
    _set("values", [*WRONG_TYPES, [], 0.5]),
    _table_order,
    _table_long,
    _in_scene(_scale(1e-150)),
    _in_scene(_scale(1e150)),
    _in_scene(_set("wall_restitution", [1.5])),  # heated walls with a table between particles
]


def _checkpoint_params(rng):
    """A small gas (a valid scene of _scene_params) run for up to 400 events, to be saved and
    loaded."""
    return dict(scene=_scene_params(rng), events=int(rng.integers(0, 400)), edits=[])


def _edit(make):
    """A mutation appending an edit of the checkpoint's bytes (checkpoint_fuzz.apply_edits)."""

    def mutate(rng, p):
        edit = make(rng)
        p["edits"].append(edit)
        return f"{edit[0]} {edit[1:]}"

    return mutate


def _pick(rng, values):
    return values[int(rng.integers(len(values)))]


_META_PATHS = [
    ("format",),
    ("format_version",),
    ("granular_version",),
    ("layout",),
    ("knobs",),
    ("knobs", "cell_factor"),
    ("knobs", "shell"),
    ("knobs", "bogus"),
    ("scene",),
    ("scene", "boundary"),
    ("scene", "restitution"),
    ("scene", "wall_restitution"),
    ("scene", "contact_duration"),
    ("scene", "driving"),
    ("engine_state_sha256",),
]
_META_VALUES = [
    None,
    -1,
    0,
    0.5,
    1e308,
    10**400,
    "x",
    "auto",
    True,
    [],
    {},
    [[[[[]]]]],
    {"law": "TabulatedRestitution", "speeds": [1.0, 0.0], "values": [2.0]},
    {"law": "Viscoelastic", "damping": -1.0, "kappa": 1.0},
    {"law": "os.system", "command": "true"},
    {"driving": "WhiteNoise", "strength": -1.0, "rate": 1.0, "seed": 0},
    {"driving": "PairThermostat", "temperature": 1.0, "rate": 1.0, "seed": 1.5},
    {"driving": "os.system", "command": "true"},
]
_RECORD_VALUES = [NAN, INF, -INF, 1e140, -1e140, 1e300, 2.0, -1.0, 0.5, 0.0, 5e-324]
_IMAGE_VALUES = [-(2**63), 2**63 - 1, 2**62, -1, 1, 10**12]


def _state_int(rng):
    from helpers.checkpoint_fuzz import STATE_HEADER

    if rng.random() < 0.5:  # a header field
        _, at, width = _pick(rng, STATE_HEADER)
        value = _pick(rng, [-1, 0, 1, 2, 3, 4, 64, 2**31 - 1, -(2**31)])
        return ("state_int", at, width, value)
    width = int(rng.choice([4, 8]))
    values = [-1, 0, 1, 2**31 - 1, -(2**31)] + ([2**62, -(2**63)] if width == 8 else [])
    return ("state_int", float(rng.random()), width, _pick(rng, values))


CHECKPOINT_MUTATIONS = [
    _edit(lambda r: ("rezip",)),  # the same members in a new archive: loads
    _edit(lambda r: ("truncate", float(r.random()))),
    _edit(lambda r: ("flip", float(r.random()), int(r.integers(1, 256)))),
    _edit(
        lambda r: (
            "zip_field",
            _pick(r, ["flags", "method", "size", "offset"]),
            _pick(r, [0, 1, 8, 12, 99, 0xFFFF, 2**31, 0xFFFFFFFF]),
        )
    ),
    _edit(lambda r: ("compress",)),
    _edit(
        lambda r: (
            "extra_member",
            _pick(r, ["extra.npy", "meta.npy", "../x"]),
            _pick(r, [1, 1 << 20, 16 << 20]),
        )
    ),
    _edit(lambda r: ("drop_member", int(r.integers(8)))),
    _edit(
        lambda r: (
            "npy_header",
            int(r.integers(8)),
            *_pick(
                r,
                [
                    ("shape", (2**40,)),
                    ("shape", (2**20, 2**20)),
                    ("shape", (0,)),
                    ("shape", ()),
                    ("shape", (1,)),
                    ("descr", "<f4"),
                    ("descr", "|O"),
                    ("descr", ">f8"),
                    ("descr", "<U3"),
                    ("descr", "|u1"),
                    ("fortran_order", True),
                ],
            ),
        )
    ),
    _edit(lambda r: ("meta", _pick(r, _META_PATHS), _pick(r, _META_VALUES))),
    _edit(
        lambda r: (
            "meta_raw",
            *_pick(
                r,
                [("[", 100_000), ("{}", 1), ("", 1), ("null", 1), ("1e999999", 1), ("[1, 2", 1)],
            ),
        )
    ),
    _edit(_state_int),
    _edit(lambda r: ("state_double", float(r.random()), _pick(r, _RECORD_VALUES))),
    _edit(lambda r: ("record", int(r.integers(20)), int(r.integers(8)), _pick(r, _RECORD_VALUES))),
    _edit(lambda r: ("image", int(r.integers(20)), int(r.integers(3)), _pick(r, _IMAGE_VALUES))),
]

THREADS_MUTATIONS = [
    _set("threads", [0, -1, 1.5, True, "2", NAN, None, 1, 2, 3, 7, 1024, 10**6, np.int64(2)]),
]

KINDS = {
    "scene": (_scene_params, SCENE_MUTATIONS),
    "random": (_random_params, RANDOM_MUTATIONS),
    "run": (_run_params, RUN_MUTATIONS),
    "langevin": (_langevin_params, LANGEVIN_MUTATIONS),
}
# Kinds added later draw from a stream of their own, so that adding one leaves the cases of
# the others as they were: restitution tables, checkpoints, langevin.run's threads= (a
# Langevin baseline whose threads are always set, so that its result is compared with one
# thread's).
LATER_KINDS = {
    "table": (_table_params, TABLE_MUTATIONS),
    "checkpoint": (_checkpoint_params, CHECKPOINT_MUTATIONS),
    "threads": (_langevin_params, THREADS_MUTATIONS),
}
LATER_SHARE = 0.2  # of the cases


def _rough_params(rng):
    """A scene of rough particles: spins, a tangential restitution, maybe Walton's rule;
    sometimes in a sheared box (_scene_params' shear), sometimes under gravity between
    walls."""
    p = _scene_params(rng)
    n, dim = p["velocities"].shape
    p["angular_velocities"] = rng.normal(size=(n,) if dim == 2 else (n, 3)) * 5.0
    p["tangential_restitution"] = float(rng.choice([-1.0, 0.0, 0.5, 1.0]))
    p["inertia_factor"] = [None, 0.4, 1.0][int(rng.integers(3))]
    p["friction"] = float(rng.choice([INF, INF, 0.2]))
    if p["boundary"] == "walls" and rng.random() < 0.4:
        g = np.zeros(dim)
        g[-1] = -float(rng.choice([1.0, 10.0]))
        p["gravity"] = g
    return p


def _rough_vib_params(rng):
    """_vib_params' wall and particles, rough (spins, beta, maybe Walton's rule), and half
    the time gravity towards the vibrating wall (a vibrated bed)."""
    p = _vib_params(rng)
    sc, w = p["scene"], p["wall"]
    n, dim = sc["velocities"].shape
    sc["angular_velocities"] = rng.normal(size=(n,) if dim == 2 else (n, 3)) * 5.0
    sc["tangential_restitution"] = float(rng.choice([0.0, 0.5, 1.0]))
    sc["friction"] = float(rng.choice([INF, 0.2]))
    if rng.random() < 0.5:
        g = np.zeros(dim)
        g[w["axis"]] = float(rng.choice([1.0, 10.0])) * (-1.0 if w["side"] == "lower" else 1.0)
        sc["gravity"] = g
        # a heated wall that gravity brings them back to heats without end (HeatedWallsError)
        sc["wall_restitution"] = min(sc["wall_restitution"], 1.0)
    return p


ROUGH_MUTATIONS = [
    _set("tangential_restitution", [*EXTREME, -1.1, 1.1, 1 + 1e-16, "0.5", None, 1j]),
    _set("inertia_factor", [*EXTREME, 1.5, 1 + 1e-16, "x", 1j]),
    _set("friction", [*EXTREME, "x", None]),
    _entry("angular_velocities", EXTREME),
    _shape("angular_velocities"),
    _set("angular_velocities", [*EXTREME, *WRONG_TYPES]),
    _set("restitution", [0.0, 0.5]),
    _scale(1e-150),
    _scale(1e150),
    _overlap("touching"),
]
# Rough particles, from a stream of their own (the others' cases stay as they were).
ROUGH_KINDS = {"rough": (_rough_params, ROUGH_MUTATIONS)}
ROUGH_SHARE = 0.06


# A walled scene with a vibrating wall (granular.VibratingWall), from a stream of its own
# (the first stream's cases stay as they were, fewer by this share).


def _vib_params(rng):
    """A walled box with its particles on a grid beside the vibrating wall's sweep, the wall
    on a random axis and side, sine or triangle, amplitude up to a tenth of the box."""
    n = int(rng.integers(1, 16))
    dim = int(rng.choice([2, 3]))
    length = float(rng.choice([1.0, 2.5]))
    axis, side = int(rng.integers(dim)), str(rng.choice(["lower", "upper"]))
    amplitude = length * float(rng.uniform(1e-3, 0.1))
    free = length - 2 * amplitude  # the room beside the sweep
    pos, spacing = _grid(rng, n, dim, length)
    pos[:, axis] = pos[:, axis] * free / length + (2 * amplitude if side == "lower" else 0.0)
    return dict(
        scene=dict(
            positions=pos,
            velocities=rng.normal(size=(n, dim)),
            radii=np.full(n, spacing * free / length * rng.uniform(0.1, 0.4)),
            masses=rng.uniform(0.5, 2.0, n),
            box=length,
            boundary="walls",
            wall_restitution=float(rng.choice([1.0, 1.0, 0.9, 1.1])),
            restitution=float(rng.choice([1.0, 0.9])),
            contact_duration=float(rng.choice([0.0, 1e-3])),
        ),
        wall=dict(
            axis=axis,
            side=side,
            amplitude=amplitude,
            angular_frequency=_power(rng, -1.0, 3.0),  # 0.1 .. 1000
            phase=float(rng.uniform(-10, 10)),
            waveform=str(rng.choice(["sine", "triangle"])),
        ),
        t_stop=float(rng.choice([0.5, 2.0])),
    )


def _wall_key(key, values):
    def mutate(rng, p):
        v = values[int(rng.integers(len(values)))]
        p["wall"][key] = v
        return f"wall {key}={v!r}"

    return mutate


def _into_the_sweep(rng, p):
    """A particle moved to the middle of the wall's sweep (behind the wall at some phase)."""
    w, x = p["wall"], p["scene"]["positions"]
    length = p["scene"]["box"]
    x[0, w["axis"]] = w["amplitude"] if w["side"] == "lower" else length - w["amplitude"]
    return "particle 0 in the sweep"


def _long_run(rng, p):
    p["t_stop"] = 1e12
    return "t_stop=1e12 (past float64's timing of the wall)"


VIB_MUTATIONS = [
    _wall_key("amplitude", [*EXTREME, 0.6, 10.0]),
    _wall_key("angular_frequency", [*EXTREME, 1e12, 1e100]),
    _wall_key("phase", [NAN, INF, -INF, 1e300, 1e16]),
    _wall_key("axis", [-1, 3, 1.5, "0", None, True]),
    _wall_key("side", ["left", None, 0]),
    _wall_key("waveform", ["square", None, 1]),
    _into_the_sweep,
    _long_run,
    _scene_key("wall_restitution", [0.5, 2.0]),
]
VIB_KINDS = {"vibrating": (_vib_params, VIB_MUTATIONS)}
VIB_SHARE = 0.05
# rough particles beside a vibrating wall (and on a vibrated bed), in the rough stream
ROUGH_KINDS["rough vibrating"] = (
    _rough_vib_params,
    [
        *VIB_MUTATIONS,
        _scene_key("tangential_restitution", [-1.5, NAN, "x"]),
        _scene_key("friction", [-0.1, NAN]),
    ],
)

# Langevin runs whose scales are near the ends of float64, from a third stream of their own
# (the first stream's cases stay as they were, fewer by this share).
SCALE_KINDS = {"langevin": (_langevin_params, LANGEVIN_SCALE_MUTATIONS)}
SCALE_SHARE = 0.06
# Runs keeping the stress tensor (and bad values of the knob), from a fourth stream (the
# first stream's cases stay as they were, fewer by this share).
STRESS_KINDS = {"stress": (_stress_params, [*RUN_MUTATIONS, _stress_knob])}
STRESS_SHARE = 0.04


# Runs under gravity keeping the stress tensor (its flight integral under gravity,
# csrc/stress.h), between walls or in the freely falling periodic box, from a stream of
# their own (the first stream's cases stay as they were, fewer by this share).
def _falling_params(rng):
    p = _stress_params(rng)
    g = np.zeros(p["scene"]["dim"])
    g[-1] = -float(rng.choice([0.5, 3.0, 50.0]))
    g[0] = float(rng.choice([0.0, 0.5]))
    p["fall"] = dict(gravity=g, free_fall=p["scene"]["boundary"] == "periodic")
    return p


def _fall_strength(rng, p):
    """Gravity from the representable to the absurd (or NaN) on the falling baseline."""
    v = float(rng.choice([1e-300, 1e-150, 1e140, 1e279, 1e300, NAN, INF]))
    g = np.zeros(len(p["fall"]["gravity"]))
    g[-1] = v  # (eye * v would make 0 * inf = NaN in the other components)
    p["fall"]["gravity"] = g
    return f"gravity[-1]={v!r}"


def _fall_frame(rng, p):
    """The free-fall frame flipped (a periodic box without it is refused)."""
    p["fall"]["free_fall"] = not p["fall"]["free_fall"]
    return f"free_fall={p['fall']['free_fall']}"


FALLING_KINDS = {
    "falling": (_falling_params, [*RUN_MUTATIONS, _stress_knob, _fall_strength, _fall_frame])
}
FALLING_SHARE = 0.03


def _draw(rng, kinds, count, at_least_one=()):
    cases = []
    for i in range(count):
        kind = list(kinds)[i % len(kinds)]
        baseline, mutations = kinds[kind]
        params = baseline(rng)
        n_mut = int(rng.choice([0, 1, 1, 1, 1, 1, 2, 2, 2, 2]))
        if kind in at_least_one:
            n_mut = max(n_mut, 1)
        labels = []
        for _ in range(n_mut):
            mutate = mutations[int(rng.integers(len(mutations)))]
            try:
                labels.append(mutate(rng, params))
            except Exception:  # noqa: BLE001 -- does not apply after an earlier mutation
                pass
        cases.append(dict(kind=kind, params=params, labels=labels))
    return cases


def make_cases(seed, count):
    """``count`` cases as dicts {kind, params, labels}, the same for the same seed."""
    later, scales = int(LATER_SHARE * count), int(SCALE_SHARE * count)
    stress = int(STRESS_SHARE * count)
    rough = int(ROUGH_SHARE * count)
    vib = int(VIB_SHARE * count)
    falling = int(FALLING_SHARE * count)
    first = _draw(
        np.random.default_rng(seed), KINDS, count - later - scales - stress - rough - vib - falling
    )
    return (
        first
        + _draw(np.random.default_rng([seed, 1]), LATER_KINDS, later, ("threads",))
        + _draw(np.random.default_rng([seed, 2]), SCALE_KINDS, scales, ("langevin",))
        + _draw(np.random.default_rng([seed, 3]), STRESS_KINDS, stress)
        + _draw(np.random.default_rng([seed, 4]), ROUGH_KINDS, rough)
        + _draw(np.random.default_rng([seed, 5]), VIB_KINDS, vib)
        + _draw(np.random.default_rng([seed, 6]), FALLING_KINDS, falling)
    )


def describe(case):
    """A short, reproducible description: kind, what was changed, the main arguments."""

    def short(v):
        if isinstance(v, np.ndarray):
            return f"array{v.shape}" if v.size > 4 else repr(v.tolist())
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k}: {short(x)}" for k, x in v.items()) + "}"
        return repr(v)

    params = ", ".join(f"{k}={short(v)}" for k, v in case["params"].items())
    return f"{case['kind']}[{'; '.join(case['labels']) or 'baseline'}]({params})"


# -- running one case -----------------------------------------------------------------------


class InvariantError(AssertionError):
    pass


def _check(ok, what):
    if not ok:
        raise InvariantError(what)


def _verified(check):
    """``check`` with any exception it raises turned into a failed invariant: once a call has
    returned, its result must be usable (a final state that raises OverlapError is a bug)."""

    def wrapped(*args):
        try:
            check(*args)
        except InvariantError:
            raise
        except Exception as exc:  # noqa: BLE001
            raise InvariantError(
                f"checking the result raised {type(exc).__name__}: {exc}"
            ) from None

    return wrapped


@_verified
def _check_trajectory(scene, traj, sim, sample_times=None):
    from granular import Scene
    from granular.restitution import heats

    if sample_times is not None and traj.stop_reason == "time":  # every sample or an error
        want = len(np.asarray(sample_times, dtype=float))
        _check(len(traj.times) == want, f"{want} sample times asked, {len(traj.times)} returned")

    for name in ("times", "positions", "velocities", "kinetic_energy", "momentum"):
        a = getattr(traj, name)
        _check(a is None or np.all(np.isfinite(a)), f"non-finite {name} in the trajectory")
    for name in ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor"):  # stress=True
        a = getattr(traj, name)
        _check(a is None or np.all(np.isfinite(a)), f"non-finite {name} in the trajectory")
        if a is not None:
            _check(np.all(np.isfinite(sim.stats[name])), f"non-finite stats {name}")
    if scene.gravity is not None and traj.kinetic_tensor is not None:
        _check_falling_tensor(scene, traj, sim)
    stats = {
        k: v
        for k, v in sim.stats.items()  # pressure, temperature_ratio: NaN is a documented answer
        if k not in ("pressure", "temperature_ratio") and isinstance(v, (int, float, np.number))
    }
    _check(all(math.isfinite(v) for v in stats.values()), f"non-finite stats: {stats}")
    if scene.shear_rate != 0.0:
        _check_sheared(scene, traj, sim)
        return
    if traj.positions is not None and traj.velocities is not None:
        length = scene.upper - scene.lower
        every = max(1, len(traj.times) // 20)  # at most ~20 samples checked for overlaps
        for x, v in zip(traj.positions[::every], traj.velocities[::every], strict=True):
            if scene.boundary == "periodic":
                x = scene.lower + np.mod(x - scene.lower, length)
                x = np.where(x >= scene.upper, scene.lower, x)  # mod can round up to L
            # the scene's own checks (inside the box, no overlap) raise on a bad sample
            Scene(
                x,
                v,
                scene.radii,
                scene.masses,
                box=(scene.lower, scene.upper),
                boundary=scene.boundary,
            )
    _ = sim.scene  # the final state, checked the same way (the property builds a Scene)
    from granular._rough import rough_keeps_energy

    elastic = (
        scene.driving is None
        and scene.restitution == 1
        and (scene.boundary == "periodic" or scene.wall_restitution == 1)
        and rough_keeps_energy(scene)
    )
    e = np.asarray(traj.kinetic_energy, dtype=float)
    if traj.rotational_energy is not None:  # rough particles trade the two
        _check(np.all(np.isfinite(traj.rotational_energy)), "non-finite rotational energy")
        e = e + np.asarray(traj.rotational_energy, dtype=float)
    g = scene.gravity
    if g is not None:
        # gravity: the energy kept is kinetic + potential between walls (measured from the
        # corner g points to, >= 0); in the freely falling periodic box, the kinetic
        # energy of the motion relative to the fall (v - g t); none without the samples
        if traj.positions is None or traj.velocities is None:
            e = e[:0]
        elif scene.boundary == "periodic":
            v = traj.velocities - np.asarray(traj.times)[:, None, None] * g
            e = 0.5 * np.einsum("n,tnd,tnd->t", scene.masses, v, v)
        else:
            corner = np.where(g > 0, scene.upper, scene.lower)
            e = e + np.einsum("n,tnd,d->t", scene.masses, corner - traj.positions, g)
    if elastic and len(e):
        drift = np.max(np.abs(e - e[0])) / e[0] if e[0] > 0 else np.max(np.abs(e))
        _check(drift <= ENERGY_RTOL, f"elastic run: kinetic energy drifted by {drift:.3g}")
    heated = scene.driving is not None or (
        scene.boundary == "walls" and heats(scene.wall_restitution)
    )
    if len(e) and not heated:
        rise = (np.max(e) - e[0]) / e[0] if e[0] > 0 else np.max(e)
        _check(rise <= ENERGY_RTOL, f"no heated walls, yet the kinetic energy rose by {rise:.3g}")


@_verified
def _check_falling_tensor(scene, traj, sim):
    """Under gravity with stress=True: trace(pressure_tensor) / d is the scalar pressure (two
    integrals of the kinetic energy through the parabolic flights, summed apart), and the
    kinetic tensor kept by differences (stats) is the velocities' own now, both to 1e-9
    (the kept tensor to 1e-9 of the largest energy the run held: it carries the rounding of
    the energies it held since it was last summed anew)."""
    st = sim.stats
    d = scene.dim
    if st["time"] > 0 and math.isfinite(st["pressure"]):
        trace = float(np.trace(np.array(st["pressure_tensor"]))) / d
        gap = abs(trace - st["pressure"])
        _check(gap <= 1e-9 * abs(st["pressure"]) + 1e-300, f"trace / d - pressure = {gap:.3g}")
    v = sim.scene.velocities
    own = np.einsum("i,ia,ib->ab", scene.masses, v, v)
    held = max(2 * float(np.max(traj.kinetic_energy, initial=0.0)), float(np.trace(own)))
    gap = float(np.max(np.abs(np.array(st["kinetic_tensor"]) - own)))
    _check(gap <= 1e-9 * held + 1e-300, f"the kept kinetic tensor is off by {gap:.3g}")


@_verified
def _check_sheared(scene, traj, sim):
    """_check_trajectory for a sheared box: samples brought into the box through the
    sliding images at their time make valid scenes with the offset then (no overlap
    through any image), and an elastic run's energy rose by the boundary's work."""
    from granular import _shear

    if traj.positions is not None and traj.velocities is not None:
        length = scene.upper - scene.lower
        every = max(1, len(traj.times) // 20)
        for k in range(0, len(traj.times), every):
            t = float(traj.times[k])
            rate, d0 = scene.shear_rate, scene.shear_offset
            x, _ = _shear.wrap(traj.positions[k], scene.lower, scene.upper, rate, d0, t)
            offset = _shear.offset(rate, d0, float(length[0]), float(length[1]), t)
            scene.replace(positions=x, velocities=traj.velocities[k], shear_offset=offset)
    _ = sim.scene
    st = sim.stats
    from granular._rough import rough_keeps_energy

    elastic = scene.restitution == 1 and rough_keeps_energy(scene)
    if elastic and len(traj.kinetic_energy):
        # (rough particles: translation + rotation)
        e0 = scene.kinetic_energy + scene.rotational_energy
        e = st["kinetic_energy"] + st["rotational_energy"]
        work = st["shear_work"] + st["drive_energy"]  # a driving's kicks add theirs
        gap = abs(e - e0 - work)
        scale = max(e0, e, abs(st["shear_work"]), abs(st["drive_energy"]))
        _check(gap <= ENERGY_RTOL * scale, f"sheared elastic run: energy - work off by {gap:.3g}")
    k, kt, w = traj.kinetic_tensor, traj.kinetic_time_tensor, traj.stress_collisional
    if elastic and k is not None and len(traj.times) >= 2:
        # stress=True: the peculiar energy rose by the viscous heating -rate V int P_yx dt
        # (rough particles: with the rotational energy, and the collisional stress with the
        # tangential impulse)
        assert kt is not None and w is not None
        gained = 0.5 * (np.trace(k[-1]) - np.trace(k[0]))
        if traj.rotational_energy is not None:
            gained += traj.rotational_energy[-1] - traj.rotational_energy[0]
        heated = -scene.shear_rate * (kt[-1, 0, 1] - kt[0, 0, 1] + w[-1, 1, 0] - w[0, 1, 0])
        scale = max(np.trace(k[-1]), np.trace(k[0]), abs(heated))
        _check(
            abs(gained - heated) <= ENERGY_RTOL * scale,
            f"sheared elastic run: peculiar energy - viscous heating off by {gained - heated:.3g}",
        )


def _check_langevin(r):
    for name in (
        "times",
        "msd_total",
        "msd_per_dimension",
        "v2",
        "temperature",
        "tamsd_mean",
        "tamsd_per_particle",
        "positions",
        "final_positions",
        "final_velocities",
        "initial_positions",
    ):
        a = getattr(r, name, None)
        _check(a is None or np.all(np.isfinite(a)), f"non-finite {name}")
    _check(np.all(r.msd() >= 0), "negative MSD")
    _check(np.all(np.diff(r.times) > 0), "sample times not increasing")


def _run_scene(scene):
    """A short run of a scene that was accepted: it must keep the invariants."""
    from granular import Simulation

    speed = math.sqrt(2 * scene.kinetic_energy / np.sum(scene.masses)) if scene.n else 0.0
    length = float(np.min(scene.upper - scene.lower))
    t_stop = length / speed if speed > 0 and math.isfinite(length / speed) else 1.0
    # half the sheared scenes with neighbour lists (where the box is wide enough for them)
    lists = scene.shear_rate != 0.0 and scene.n % 2 == 0
    sim = Simulation(scene, shell=0.25) if lists else Simulation(scene)
    traj = sim.run(t_stop, sample_times=np.linspace(0, t_stop, 5), stop_when={"events": EVENTS})
    _check_trajectory(scene, traj, sim)
    if lists and sim.stats["shell"] > 0:
        # the engine's own check of a state (csrc/checkpoint.c): every centre filed where
        # the flow carries it, every pair within reach over a list's life listed
        sim._engine.restore_state(sim._engine.save_state())


def _run_vibrating(p):
    """A run with a vibrating wall: finite, no overlaps, nobody behind the wall at any
    sample (the Scene of each sample, the wall at its phase then, checks it), and the
    kinetic energy changed by wall_work - collision_loss (to rounding: 1e-12 of the
    energies in play, far below a lost or doubled hit)."""
    from granular import Scene, Simulation, VibratingWall

    wall = VibratingWall(**p["wall"])
    scene = Scene(**p["scene"], vibrating_wall=wall)
    sim = Simulation(scene)
    times = np.linspace(0.0, p["t_stop"], 5)
    traj = sim.run(p["t_stop"], sample_times=times, stop_when={"events": EVENTS})
    _check_vibrating(scene, traj, sim)


@_verified
def _check_vibrating(scene, traj, sim):
    from granular import Scene

    for name in ("times", "positions", "velocities", "kinetic_energy"):
        _check(np.all(np.isfinite(getattr(traj, name))), f"non-finite {name} in the trajectory")
    st = sim.stats
    for key in ("wall_work", "collision_loss", "kinetic_energy"):
        _check(math.isfinite(st[key]), f"non-finite {key}: {st[key]}")
    for t, x, v in zip(traj.times, traj.positions, traj.velocities, strict=True):
        Scene(x, v, scene.radii, scene.masses, box=(scene.lower, scene.upper),
              boundary="walls", vibrating_wall=scene.vibrating_wall.at_time(t))  # fmt: skip
    _ = sim.scene
    from granular.checkpoint import potential_energy

    def energy(x):  # (rough particles: + rotation; under gravity: + the potential energy)
        return x.kinetic_energy + x.rotational_energy + potential_energy(x)

    change = energy(sim.scene) - energy(scene)
    scale = max(energy(scene), abs(st["wall_work"]), abs(st["collision_loss"]))
    miss = abs(change - (st["wall_work"] - st["collision_loss"]))
    bound = 1e-12 * scale
    if scene.gravity is not None:
        # each event's flight and collision round the mover's kinetic + potential energy by
        # a few ulp (the position's ulp times m g as well): 8 ulp of the energies in play an
        # event bounds it (a particle chattering on the floor makes ~1e4 hits), still far
        # below a lost or doubled hit
        bound = max(bound, 8 * 2.0**-53 * st["events"] * scale)
    _check(miss <= bound, f"energy: change {change:.6g} vs work - loss, off by {miss:.3g}")
    # the books per sample: cumulative, the stats' at a last sample taken now, and (smooth,
    # no gravity: the Trajectory's energy is the kinetic one) each window's energy change
    work, loss = traj.wall_work, traj.collision_loss
    _check(work is not None and loss is not None, "a vibrating wall's run without its books")
    if len(traj.times) and traj.times[-1] == sim.time:
        _check(work[-1] == st["wall_work"] and loss[-1] == st["collision_loss"],
               "the last sample's books are not the stats'")  # fmt: skip
    if scene.gravity is None and scene.tangential_restitution == -1.0:
        gap = np.abs(np.diff(traj.kinetic_energy) - (np.diff(work) - np.diff(loss)))
        scale = max(scale, float(np.max(traj.kinetic_energy, initial=0.0)))
        _check(np.all(gap <= 1e-12 * scale), "a window's energy change is not its work - loss")


def _same_stats(a, b):
    """Two stats dicts equal, a NaN (a documented answer: a sheared pressure without the
    stress tensor, a ratio of zeros) equal to a NaN."""

    def same(x, y):
        return x == y or (isinstance(x, float) and isinstance(y, float) and x != x and y != y)

    return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)


def _run_checkpoint(p, mutated):
    """Save a short run, damage the file (p["edits"]), load it: CheckpointError, or a
    Simulation that runs on within the invariants and bit for bit as the original (when the
    file is unaltered, or only its packaging changed).  A state crafted past its checksum
    that passes every check must be a valid scene, and need only end cleanly after (its
    predictions cannot be checked)."""
    from granular import CheckpointError, GranularError, Scene, Simulation
    from granular import checkpoint as ck

    from helpers.checkpoint_fuzz import apply_edits

    scene = Scene(**p["scene"])
    sim = Simulation(scene)
    if p["events"]:
        sim.run(stop_when={"events": p["events"]})
    data = ck.dumps(sim)
    bad = apply_edits(data, p["edits"], sim._engine.state()[1])
    try:
        loaded = Simulation._loads(bad)
    except CheckpointError as exc:
        if bad == data:
            return "FAIL", f"an unaltered checkpoint was refused: {exc}"
        return "error", f"CheckpointError: {exc}"[:300]
    except Exception as exc:  # noqa: BLE001 -- anything else is the failure
        tb = traceback.extract_tb(exc.__traceback__)[-1]
        where = f"{os.path.basename(tb.filename)}:{tb.lineno}"
        return "FAIL", f"{type(exc).__name__} (not CheckpointError): {exc} (at {where})"
    more = dict(stop_when={"events": 1000}, t_stop=loaded.time + 1.0)
    crafted = any(e[0].startswith(("state", "record", "image")) for e in p["edits"])
    if crafted and bad != data:
        try:
            _ = loaded.scene  # what a load accepts is a valid scene (no overlaps, inside, scales)
        except Exception as exc:  # noqa: BLE001
            return "FAIL", f"a loaded state is not a valid scene: {type(exc).__name__}: {exc}"
        try:
            traj = loaded.run(**more)
        except GranularError as exc:
            return "error", f"{type(exc).__name__} in the run: {exc}"[:300]
        _check(np.all(np.isfinite(traj.kinetic_energy)), "non-finite energy after a load")
        return "ok", ""
    t0 = loaded.time
    times = np.linspace(t0, t0 + 1.0, 4)
    traj = loaded.run(**more, sample_times=times)
    _check_trajectory(scene, traj, loaded)
    # what the checks accept of a file whose state was not crafted is the saved state
    again = sim.run(**more, sample_times=times)
    same = np.array_equal(traj.positions, again.positions) and _same_stats(loaded.stats, sim.stats)
    _check(same, "an accepted checkpoint did not continue bit for bit")
    return "ok", ""


def run_case(case):
    """Run one case: ("ok" | "error" | "FAIL", detail)."""
    import granular
    from granular import Scene, Simulation, langevin

    kind, p = case["kind"], case["params"]
    mutated = bool(case["labels"])
    big = any("big:" in label for label in case["labels"])
    try:
        if kind == "scene":
            _run_scene(Scene(**p))
        elif kind == "random":
            s = Scene.random(**p)
            want = np.asarray(p["radius"], dtype=float)
            _check(s.n == p["n"] and s.dim == p["dim"], f"got n={s.n}, dim={s.dim}")
            _check(
                want.shape in ((), (s.n,)) and np.array_equal(s.radii, want * np.ones(s.n)),
                "the radii are not the requested ones, particle by particle",
            )
            _run_scene(s)
        elif kind in ("run", "stress", "falling"):
            scene = Scene.random(**p["scene"])
            if "fall" in p:  # (Scene.random takes no gravity)
                scene = scene.replace(**p["fall"])
            sim = Simulation(scene, **p.get("knobs", {}))
            traj = sim.run(**p["run"])
            _check_trajectory(scene, traj, sim, p["run"].get("sample_times"))
            if "again" in p:
                traj = sim.run(**p["again"], stop_when={"events": EVENTS})
                _check_trajectory(scene, traj, sim)
        elif kind == "rough":
            _run_scene(Scene(**p))
        elif kind == "table":
            law = granular.TabulatedRestitution(p["speeds"], p["values"])
            _run_scene(Scene(**dict(p["scene"], **{p["side"]: law})))
        elif kind == "checkpoint":
            return _run_checkpoint(p, mutated)
        elif kind in ("vibrating", "rough vibrating"):
            _run_vibrating(p)
        else:  # langevin, threads
            r = langevin.run(**p)
            _check_langevin(r)
            if "threads" in p and p["threads"] != 1:  # the same bits on one thread
                one = langevin.run(**dict(p, threads=1))
                for name in ("msd_total", "v2", "tamsd_mean", "final_positions"):
                    a, b = getattr(r, name), getattr(one, name)
                    _check(np.array_equal(a, b), f"threads={p['threads']!r}: {name} differs")
        return "ok", ""
    except InvariantError as exc:
        return "FAIL", f"invariant: {exc}"
    except Exception as exc:  # noqa: BLE001 -- classifying every exception is the point
        name = type(exc).__name__
        msg = str(exc).strip()
        allowed = (granular.GranularError, ValueError, TypeError) + ((MemoryError,) if big else ())
        if not mutated and not isinstance(exc, granular.InelasticCollapseError):
            return "FAIL", f"a valid baseline raised {name}: {msg}"
        if not isinstance(exc, allowed):
            tb = traceback.extract_tb(exc.__traceback__)[-1]
            return "FAIL", f"{name}: {msg} (at {os.path.basename(tb.filename)}:{tb.lineno})"
        if not msg:
            return "FAIL", f"{name} without a message"
        return "error", f"{name}: {msg}"


def worker(seed, count):
    """Read case numbers from stdin, write one JSON line [status, detail] per case."""
    out = os.fdopen(os.dup(1), "w")
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # what the library prints must not mix with the answers
    warnings.simplefilter("ignore")
    np.seterr(all="ignore")
    cases = make_cases(seed, count)
    import granular  # noqa: F401 -- imported before the first case's timer starts

    out.write("ready\n")
    out.flush()
    for line in sys.stdin:
        status, detail = run_case(cases[int(line)])
        out.write(json.dumps([status, detail[:500]]) + "\n")
        out.flush()
