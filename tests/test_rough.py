"""Rough particles in the event-driven engine (csrc/rule.h): one collision at chosen
geometry against the collision formulas written out here (Huthmann & Zippelius 1997, PRE
56, R6275; Luding, Huthmann, McNamara & Zippelius 1998, PRE 58, 3416; Walton's Coulomb
rule), its energy loss and the angular momentum about the contact point, beta = -1 against
the smooth loop bit for bit, beta = 1 keeping the energy over many collisions, a gas against
the slow reference (tests/helpers/reference_edmd.py), checkpoints and bad input."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, TabulatedRestitution, _core

from helpers import reference_edmd

# -- the formulas, for unequal radii a and masses m (I = q m a^2) ------------------------
#
# n = (x_j - x_i) / |x_j - x_i| at contact; the contact point's relative velocity
#   g = v_j - v_i - (a_i w_i + a_j w_j) x n,   g_n = (g . n) n,   g_t = g - g_n;
# the impulse on j (Luding et al. 1998 eqs. 2-4, written for unequal particles):
#   P = -(1 + xi) m_eff g_n - (1 + beta) m_t g_t,
#   m_eff = m_i m_j / (m_i + m_j),   1/m_t = 1/m_eff + a_i^2/I_i + a_j^2/I_j;
# Walton's rule: beta = min(beta_0, -1 + mu (1 + xi) (m_eff/m_t) |g_n| / |g_t|);
# after: v_i - P/m_i, v_j + P/m_j, w_i - a_i n x P / I_i, w_j - a_j n x P / I_j;
# energy lost: (1 - xi^2) m_eff |g_n|^2 / 2 + (1 - beta^2) m_t |g_t|^2 / 2.


def _as3(u, dim):
    return np.append(u, 0.0) if dim == 2 else np.asarray(u, float)


def _spin3(w, dim):
    return np.array([0.0, 0.0, w]) if dim == 2 else np.asarray(w, float)


def formula(dr, vi, vj, wi, wj, ai, aj, mi, mj, q, xi, beta, mu, dim):
    """(vi, vj, wi, wj, beta applied, energy lost) by the closed-form formulas above."""
    n = _as3(dr, dim) / np.linalg.norm(dr)
    vi, vj, wi, wj = _as3(vi, dim), _as3(vj, dim), _spin3(wi, dim), _spin3(wj, dim)
    g = vj - vi - np.cross(ai * wi + aj * wj, n)
    gn = np.dot(g, n) * n
    gt = g - gn
    m_eff = mi * mj / (mi + mj)
    m_t = 1.0 / (1.0 / m_eff + 1.0 / (q * mi) + 1.0 / (q * mj))
    if np.isfinite(mu) and np.linalg.norm(gt) > 0:
        beta = min(
            beta, -1.0 + mu * (1.0 + xi) * (m_eff / m_t) * np.linalg.norm(gn) / np.linalg.norm(gt)
        )
    P = -(1.0 + xi) * m_eff * gn - (1.0 + beta) * m_t * gt
    vi2, vj2 = vi - P / mi, vj + P / mj
    wi2 = wi - ai * np.cross(n, P) / (q * mi * ai**2)
    wj2 = wj - aj * np.cross(n, P) / (q * mj * aj**2)
    lost = 0.5 * (1 - xi**2) * m_eff * np.dot(gn, gn) + 0.5 * (1 - beta**2) * m_t * np.dot(gt, gt)
    if dim == 2:
        return vi2[:2], vj2[:2], wi2[2], wj2[2], beta, lost
    return vi2, vj2, wi2, wj2, beta, lost


def energy(scene):
    return scene.kinetic_energy + scene.rotational_energy


# -- one collision -------------------------------------------------------------------------

# (dim, xi, beta, mu, what the impact does): constant beta, Coulomb sliding (a glancing
# impact with small mu), Coulomb sticking (a nearly head-on one with large mu)
_CASES = [
    (2, 0.8, 0.3, math.inf, "constant"),
    (3, 0.8, 0.3, math.inf, "constant"),
    (2, 0.9, 0.4, 0.1, "sliding"),
    (3, 0.9, 0.4, 0.1, "sliding"),
    (2, 0.9, 0.4, 2.0, "sticking"),
    (3, 0.9, 0.4, 2.0, "sticking"),
]


def _pair(dim, xi, beta, mu, q=None, glancing=True):
    """Two unequal particles about to collide (radii 0.1, 0.25; masses 1, 3), spinning,
    in a periodic box far wider than they are."""
    rng = np.random.default_rng(7 + dim)
    ai, aj = 0.1, 0.25
    sep = ai + aj
    offset = 0.25 if glancing else 0.05  # impact parameter along a transverse axis, / sep
    xi_pos = np.full(dim, 1.0)
    xj_pos = xi_pos.copy()
    xj_pos[0] += 1.02 * sep
    xj_pos[1] += offset * sep
    vi = np.zeros(dim)
    vi[0] = 1.0
    vj = np.zeros(dim)
    vj[0] = -0.5
    vj[1:] = 0.1 * rng.standard_normal(dim - 1)
    spin = 3.0 if glancing else 0.3  # glancing and spinning fast: sliding
    if dim == 2:
        w = np.array([10.0, -6.0]) * spin
    else:
        w = rng.standard_normal((2, 3)) * 3.0 * spin
    return Scene(
        np.array([xi_pos, xj_pos]),
        np.array([vi, vj]),
        np.array([ai, aj]),
        np.array([1.0, 3.0]),
        box=4.0,
        restitution=xi,
        tangential_restitution=beta,
        friction=mu,
        inertia_factor=q,
        angular_velocities=w,
    )


def _contact(scene):
    """The contact time of the pair and the separation x_j - x_i then."""
    dr = scene.positions[1] - scene.positions[0]
    dv = scene.velocities[1] - scene.velocities[0]
    sig = scene.radii.sum()
    b, a, c = dr @ dv, dv @ dv, dr @ dr - sig**2
    t = (-b - math.sqrt(b * b - a * c)) / a
    return t, dr + dv * t


def _collide(scene):
    sim = Simulation(scene)
    sim.run(stop_when={"collisions_per_particle": 1}, store=())
    assert sim.stats["pair_collisions"] == 1
    return sim.scene


@pytest.mark.parametrize(("dim", "xi", "beta", "mu", "kind"), _CASES)
def test_one_collision_against_the_formulas(dim, xi, beta, mu, kind):
    """Velocities and spins after one collision of unequal particles: the closed-form
    formulas above and the slow reference's rigid-body impulse (two routes) agree with the
    engine to rounding (1e-12 of the speeds); the regime is the one the case names."""
    s = _pair(dim, xi, beta, mu, glancing=kind != "sticking")
    _, dr = _contact(s)
    after = _collide(s)
    v, w, a, m = s.velocities, s.angular_velocities, s.radii, s.masses
    args = (dr, v[0], v[1], w[0], w[1], a[0], a[1], m[0], m[1], s.inertia_factor, xi)
    vi, vj, wi, wj, beta_applied, _ = formula(*args, beta, mu, dim)
    if kind == "sliding":
        assert beta_applied < beta
    else:
        assert beta_applied == beta
    tol = dict(rtol=0, atol=1e-12 * 10)  # speeds ~1, spins ~10
    np.testing.assert_allclose(after.velocities, [vi, vj], **tol)
    np.testing.assert_allclose(after.angular_velocities, [wi, wj], **tol)
    ref = reference_edmd.rough_collide(*args, beta, mu, dim)
    np.testing.assert_allclose(after.velocities, [ref[0], ref[1]], **tol)
    np.testing.assert_allclose(after.angular_velocities, [ref[2], ref[3]], **tol)


@pytest.mark.parametrize(("dim", "xi", "beta", "mu", "kind"), _CASES)
def test_energy_lost_in_a_collision(dim, xi, beta, mu, kind):
    """The translational plus rotational energy lost is (1 - xi^2) m_eff g_n^2 / 2 +
    (1 - beta^2) m_t g_t^2 / 2 with the beta applied (Walton's, when sliding), to rounding
    (1e-12 of the energy)."""
    s = _pair(dim, xi, beta, mu, glancing=kind != "sticking")
    _, dr = _contact(s)
    after = _collide(s)
    v, w, a, m = s.velocities, s.angular_velocities, s.radii, s.masses
    *_, lost = formula(
        dr, v[0], v[1], w[0], w[1], a[0], a[1], m[0], m[1], s.inertia_factor, xi, beta, mu, dim
    )
    assert lost > 0
    assert energy(s) - energy(after) == pytest.approx(lost, rel=0, abs=1e-12 * energy(s))


@pytest.mark.parametrize(("dim", "xi", "beta", "mu", "kind"), _CASES)
def test_angular_momentum_about_the_contact_point(dim, xi, beta, mu, kind):
    """The impulse acts at the contact point: the angular momentum about it, sum of m (x -
    c) x v + I w, is the same before and after (to 1e-12 of its terms); momentum too."""
    s = _pair(dim, xi, beta, mu, glancing=kind != "sticking")
    t, dr = _contact(s)
    after = _collide(s)
    x = s.positions + s.velocities * t  # at contact (the periodic box does not wrap here)
    c = x[0] + s.radii[0] * dr / np.linalg.norm(dr)
    inertia = s.moments_of_inertia

    def ang(scene):
        total = np.zeros(3)
        for k in range(2):
            total += scene.masses[k] * np.cross(_as3(x[k] - c, dim), _as3(scene.velocities[k], dim))
            total += inertia[k] * _spin3(scene.angular_velocities[k], dim)
        return total

    scale = float(np.max(np.abs(ang(s)))) + 1.0
    np.testing.assert_allclose(ang(after), ang(s), rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(
        s.masses @ after.velocities, s.masses @ s.velocities, rtol=0, atol=1e-13
    )


def test_inertia_factor_enters():
    """The same impact with q = 1 (I = m a^2) and q = 0.3 gives the formulas' different
    results: q is applied, not a default."""
    for q in (0.3, 1.0):
        s = _pair(3, 0.9, 0.2, math.inf, q=q)
        _, dr = _contact(s)
        after = _collide(s)
        v, w, a, m = s.velocities, s.angular_velocities, s.radii, s.masses
        vi, vj, wi, wj, *_ = formula(
            dr, v[0], v[1], w[0], w[1], a[0], a[1], m[0], m[1], q, 0.9, 0.2, math.inf, 3
        )
        np.testing.assert_allclose(after.velocities, [vi, vj], rtol=0, atol=1e-12)
        np.testing.assert_allclose(after.angular_velocities, [wi, wj], rtol=0, atol=1e-11)


def test_default_inertia_factors():
    s2 = Scene([[0.2, 0.2]], [[0.0, 0.0]], 0.1)
    s3 = Scene([[0.2, 0.2, 0.2]], [[0.0, 0.0, 0.0]], 0.1)
    assert (s2.inertia_factor, s3.inertia_factor) == (0.5, 0.4)
    assert s2.angular_velocities.shape == (1,) and s3.angular_velocities.shape == (1, 3)


# -- a gas ---------------------------------------------------------------------------------


def _gas(dim, n=200, seed=3, **rough):
    radius = 0.02 if dim == 2 else 0.04
    s = Scene.random(n, radius, dim=dim, seed=seed, temperature=1.0)
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((n,) if dim == 2 else (n, 3)) * 10.0
    return s.replace(angular_velocities=w, **rough)


# a restitution law of the normal impact speed (eps falls from 1 to 0.7)
_LAW = TabulatedRestitution([0.0, 1.0, 3.0], [1.0, 0.9, 0.7])


def _bits(engine):
    pos, vel, _ = engine.state()
    return pos.tobytes() + vel.tobytes(), engine.counters()["events"]


@pytest.mark.parametrize("dim", [2, 3])
def test_beta_minus_one_in_the_rough_loop_is_the_smooth_loop(dim):
    """The rough rule at beta = -1 (an engine given spins, run by the rough loop) makes the
    smooth loop's events bit for bit, with and without a restitution law, and leaves the
    spins as they were.  (A Scene with tangential_restitution -1 gives the engine no spins:
    it runs the smooth loop itself.)"""
    s = _gas(dim, restitution=0.9)
    kw = s._engine_keywords()
    assert kw["angular_velocities"] is None  # smooth: the smooth loop
    smooth = _core.EDMD(**kw)
    rough = _core.EDMD(**{**kw, "angular_velocities": np.array(s.angular_velocities)})
    for engine in (smooth, rough):
        code, _ = engine.advance(
            t_stop=math.inf,
            collisions_per_particle=30.0,
            stop_kinetic_energy=-1.0,
            max_events=10**7,
            sample_times=np.empty(0),
            next=0,
        )
        assert code == _core.STOP_COLLISIONS
    assert _bits(rough) == _bits(smooth)
    assert np.array_equal(rough.angular_velocities(), s.angular_velocities)
    assert smooth.angular_velocities() is None


def test_perfectly_rough_keeps_the_energy():
    """beta = 1, xi = 1: the total energy (translation + rotation) is kept over 1e6 pair
    collisions (about 2 s) to within the rounding bound: each collision rounds the pair's
    energy by a few ulp (<= 8 * 2^-53 of the total, the pair holding at most all of it), so
    K collisions drift by at most 8 K 2^-53 ~ 9e-10 at K = 1e6.  Started without spin, the
    gas shares its energy out equally (T_rot / T_tr = 1, one rotational degree of freedom
    per disk): the ratio's mean over 200 samples of the last half, each with a standard
    deviation of about sqrt(2/N + 2/(2N)) = 0.17 at N = 100, lies within 5 sigma / sqrt(200)
    = 0.06 of 1 (samples 50 collisions per particle apart: independent)."""
    s = _gas(2, n=100, tangential_restitution=1.0)
    s = s.replace(angular_velocities=np.zeros(100))
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 10500}, store=())
    t = sim.time
    times = t + np.linspace(0.0, t, 201)[1:]
    tr = sim.run(t_stop=times[-1], sample_times=times, store=())
    pairs = sim.stats["pair_collisions"]
    assert pairs >= 1e6
    bound = 8 * pairs * 2.0**-53
    assert abs(energy(sim.scene) - energy(s)) <= bound * energy(s)
    assert float(np.mean(tr.temperature_ratio)) == pytest.approx(1.0, abs=0.06)


@pytest.mark.parametrize(
    ("dim", "rough"),
    [
        (2, dict(tangential_restitution=0.4, restitution=0.9)),
        (3, dict(tangential_restitution=0.0, restitution=0.8)),
        (2, dict(tangential_restitution=0.6, friction=0.15, restitution=0.9)),
        (3, dict(tangential_restitution=0.5, friction=0.2, restitution=0.95, inertia_factor=0.6)),
        # with a restitution law: the rough loop evaluates it for the normal part
        (2, dict(tangential_restitution=0.3, restitution=_LAW)),
        (3, dict(tangential_restitution=0.3, friction=0.3, restitution=_LAW)),
    ],
)
def test_a_rough_gas_agrees_with_the_slow_reference(dim, rough):
    """A small rough gas (periodic, unequal radii and masses) against the O(N^2) NumPy
    EDMD with its rigid-body impulse: positions, velocities and spins at every sample agree
    to 1e-8 over 6 to 10 collisions per particle (chaos grows rounding by ~e a collision)."""
    n = 12
    small = 0.05 if dim == 2 else 0.1
    radii = np.where(np.arange(n) % 2, small, 1.6 * small)
    s = Scene.random(
        n, radii, dim=dim, box=1.0, seed=11, temperature=1.0, mass=(radii / small) ** dim
    )
    w = np.random.default_rng(1).standard_normal((n,) if dim == 2 else (n, 3)) * 5.0
    s = s.replace(angular_velocities=w, **rough)
    t_stop = 2.5
    times = np.linspace(0.0, t_stop, 7)
    sim = Simulation(s)
    store = ("positions", "velocities", "angular_velocities")
    tr = sim.run(t_stop=t_stop, sample_times=times, store=store)

    assert sim.stats["pair_collisions"] >= 3 * n
    rx, rv, rw = reference_edmd.run_scene(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.angular_velocities, rw, rtol=0, atol=1e-8)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_checkpoint_continues_bit_for_bit(tmp_path, dim):
    """Saved mid-run and loaded, a rough gas (Coulomb rule, renumbering and all) goes on
    with the same positions, velocities and spins, bit for bit."""
    s = _gas(dim, n=300, tangential_restitution=0.5, friction=0.3, restitution=0.9)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 5}, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    t = sim.time + 0.5
    times = np.linspace(sim.time, t, 4)
    store = ("positions", "velocities", "angular_velocities")
    a = sim.run(t_stop=t, sample_times=times, store=store)
    b = loaded.run(t_stop=t, sample_times=times, store=store)
    for name in store:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.rotational_energy, b.rotational_energy)


def test_samples_stats_and_scene_carry_the_spins():
    """The spins sampled, the rotational energy per sample, the stats' T_rot / T_tr and
    the scene now all say the same."""
    s = _gas(3, n=100, tangential_restitution=0.3, restitution=0.9)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.3, sample_times=[0.0, 0.3], store=("angular_velocities",))
    now = sim.scene
    assert np.array_equal(tr.angular_velocities[-1], now.angular_velocities)
    assert tr.rotational_energy[-1] == pytest.approx(now.rotational_energy, rel=1e-14)
    assert tr.rotational_temperature[0] == pytest.approx(s.rotational_temperature, rel=1e-14)
    st = sim.stats
    assert st["rotational_temperature"] == pytest.approx(now.rotational_temperature, rel=1e-14)
    assert st["temperature_ratio"] == pytest.approx(
        now.rotational_temperature / now.temperature, rel=1e-12
    )
    assert tr.positions is None and tr.velocities is None


# -- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (dict(tangential_restitution=1.5), "tangential_restitution must lie in [-1, 1]"),
        (dict(tangential_restitution=-1.01), "got -1.01"),
        (dict(tangential_restitution=float("nan")), "tangential_restitution"),
        (dict(inertia_factor=0.0), "inertia_factor q"),
        (dict(inertia_factor=1.2), "got 1.2"),
        (dict(inertia_factor=-0.1), "(0, 1]"),
        (dict(inertia_factor=float("nan")), "inertia_factor"),
        (dict(friction=-0.1), "friction must be >= 0"),
        (dict(friction=float("nan")), "friction"),
        (dict(angular_velocities=[float("nan"), 0.0, 0.0]), "NaN or infinity"),
        (dict(angular_velocities=[0.0, 0.0]), "shape (3,)"),
        (dict(angular_velocities=np.zeros((3, 3))), "(N,) in 2D"),
        (dict(angular_velocities=[1e200, 0.0, 0.0]), "angular_velocities must lie within"),
        (dict(angular_velocities=["a", "b", "c"]), "angular_velocities must be numbers"),
    ],
)
def test_bad_input_is_refused(change, words):
    s = Scene([[0.2, 0.2], [0.5, 0.5], [0.8, 0.2]], np.zeros((3, 2)), 0.05)
    with pytest.raises((ValueError, TypeError)) as info:
        s.replace(**change)
    assert words in str(info.value)


def test_the_engine_refuses_bad_rough_input_itself():
    """The C checks (csrc/validate.c) behind the Python ones."""
    s = _gas(2, n=20, tangential_restitution=0.5)
    kw = s._engine_keywords()
    for key, value, words in [
        ("tangential_restitution", 1.5, "tangential restitution"),
        ("inertia_factor", 0.0, "inertia factor"),
        ("friction", -1.0, "friction"),
    ]:
        with pytest.raises(ValueError, match=words):
            _core.edmd_check(**{**kw, key: value})
    bad = np.array(kw["angular_velocities"])
    bad[3] = np.nan
    with pytest.raises(Exception, match="angular velocities"):
        _core.EDMD(**{**kw, "angular_velocities": bad})
    with pytest.raises(ValueError, match="angular_velocities"):
        _core.EDMD(**{**kw, "angular_velocities": np.zeros((20, 3))})


# -- GSD -----------------------------------------------------------------------------------


@pytest.mark.parametrize("dim", [2, 3])
def test_gsd_carries_the_spins(tmp_path, dim):
    """A rough run written to GSD: HOOMD's particles/angmom is the quaternion (0, 2 I w)
    (orientations left at the identity, so P = 2 q x (0, S) with S = I w), moment_inertia
    (I, I, I) for spheres and (0, 0, I) for disks; granular.read gives back the spins and
    rotational energies exactly, Scene.from_gsd the last frame's spins."""
    gsd = pytest.importorskip("gsd.hoomd")
    import granular

    s = _gas(dim, n=40, tangential_restitution=0.3, friction=0.5, restitution=0.9)
    store = ("positions", "velocities", "angular_velocities")
    tr = Simulation(s).run(t_stop=0.2, sample_times=[0.0, 0.1, 0.2], store=store)
    tr.write(tmp_path / "r.gsd")
    back = granular.read(tmp_path / "r.gsd")
    assert np.array_equal(back.angular_velocities, tr.angular_velocities)
    assert np.array_equal(back.rotational_energy, tr.rotational_energy)
    assert back.scene_parameters["friction"] == 0.5
    scene = Scene.from_gsd(tmp_path / "r.gsd")
    assert np.array_equal(scene.angular_velocities, tr.angular_velocities[-1])
    inertia = s.moments_of_inertia
    w3 = np.zeros((s.n, 3))
    if dim == 2:
        w3[:, 2] = tr.angular_velocities[-1]
    else:
        w3[:] = tr.angular_velocities[-1]
    with gsd.open(tmp_path / "r.gsd") as f:
        frame = f[-1]
        np.testing.assert_allclose(frame.particles.angmom[:, 0], 0.0)
        np.testing.assert_allclose(
            frame.particles.angmom[:, 1:], 2 * inertia[:, None] * w3, rtol=1e-6, atol=1e-12
        )
        want = np.zeros((s.n, 3))
        want[:, 2 if dim == 2 else slice(None)] = inertia[:, None] if dim == 3 else inertia
        np.testing.assert_allclose(frame.particles.moment_inertia, want, rtol=1e-6)


def test_animate_draws_a_radius_line_per_disk():
    """plot.animate of a rough run draws one radius line per disk, turned by the spin summed
    over the samples (exact here: one disk spinning alone in a big box, no collision); a run
    without stored spins draws none."""
    pytest.importorskip("matplotlib")
    from granular import plot

    s = Scene([[0.5, 0.5]], [[0.0, 0.0]], 0.1, tangential_restitution=0.5,
              angular_velocities=[2.0])  # fmt: skip
    times = np.linspace(0.0, 1.0, 5)
    tr = Simulation(s).run(
        t_stop=1.0, sample_times=times, store=("positions", "angular_velocities")
    )
    anim = plot.animate(tr)
    anim.draw(3)
    lines = [c for c in anim.ax.collections if c.__class__.__name__ == "LineCollection"]
    assert len(lines) == 1
    (seg,) = lines[0].get_segments()
    angle = math.atan2(seg[1, 1] - seg[0, 1], seg[1, 0] - seg[0, 0])
    assert angle == pytest.approx(math.remainder(2.0 * times[3], 2 * math.pi), abs=1e-12)
    assert np.linalg.norm(seg[1] - seg[0]) == pytest.approx(0.1)
    plain = plot.animate(Simulation(s).run(t_stop=1.0, sample_times=times))
    assert not [c for c in plain.ax.collections if c.__class__.__name__ == "LineCollection"]
    with pytest.raises(ValueError, match="angular_velocities"):
        plot.animate(Simulation(s).run(t_stop=1.0, sample_times=times), spin=True)


def test_the_tc_models_elastic_collisions_are_smooth():
    """With the TC model a collision within t_c of either particle's previous one is
    elastic; for rough particles it is smooth too (it keeps the energy): with t_c longer
    than the run, once every particle has collided every collision is the TC model's: no
    spin changes again and the energy (translation + rotation) stays, to rounding (1e-12)."""
    s = _gas(2, n=100, tangential_restitution=0.0, restitution=0.8, contact_duration=1e6)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    assert sim.stats["tc_elastic_collisions"] > 0
    before = sim.scene
    assert np.any(before.angular_velocities != s.angular_velocities)  # rough at first
    plain = sim.stats["pair_collisions"] - sim.stats["tc_elastic_collisions"]
    sim.run(stop_when={"collisions_per_particle": 40}, store=())
    after = sim.scene
    # every particle had collided by then: every collision since was the TC model's
    assert sim.stats["pair_collisions"] - sim.stats["tc_elastic_collisions"] == plain
    assert np.array_equal(after.angular_velocities, before.angular_velocities)
    assert energy(after) == pytest.approx(energy(before), rel=1e-12)


def test_smooth_particles_keep_their_spins():
    """A smooth scene (beta = -1) with spins: the engine carries none, and the scene, samples
    and checkpoints keep them as given."""
    s = _gas(3, n=50, restitution=0.9)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.5, sample_times=[0.0, 0.5], store=("angular_velocities",))
    assert sim._engine.angular_velocities() is None
    assert np.array_equal(tr.angular_velocities[-1], s.angular_velocities)
    assert np.array_equal(sim.scene.angular_velocities, s.angular_velocities)
    assert tr.rotational_energy[-1] == s.rotational_energy


def test_a_hoomd_files_spins_are_read(tmp_path):
    """Scene.from_gsd of a file HOOMD could have written (granular's log absent): spins from
    particles/angmom, orientation and moment_inertia (S = im(q* P) / 2 in the body frame,
    turned into the box frame), and the inertia factor they share."""
    gsd = pytest.importorskip("gsd.hoomd")
    rng = np.random.default_rng(5)
    n = 8
    x = (np.arange(n)[:, None] * np.array([0.6, 0.35, 0.2]) % 2.0) - 1.0
    w = rng.normal(size=(n, 3))
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    inertia = 0.4 * 1.0 * 0.05**2
    # P = 2 q (0, S) with S the body-frame angular momentum I R(q)^T w
    from granular.gsd_io import _quat_mul

    conj = q * np.array([1.0, -1.0, -1.0, -1.0])
    s_body = _quat_mul(_quat_mul(conj, np.column_stack([np.zeros(n), inertia * w])), q)
    P = 2.0 * _quat_mul(q, s_body)
    frame = gsd.Frame()
    frame.configuration.box = [2.0, 2.0, 2.0, 0, 0, 0]
    frame.particles.N = n
    frame.particles.position = x.astype(np.float32)
    frame.particles.diameter = np.full(n, 0.1, np.float32)
    frame.particles.orientation = q.astype(np.float32)
    frame.particles.angmom = P.astype(np.float32)
    frame.particles.moment_inertia = np.full((n, 3), inertia, np.float32)
    with gsd.open(tmp_path / "h.gsd", "w") as f:
        f.append(frame)
    scene = Scene.from_gsd(tmp_path / "h.gsd")
    np.testing.assert_allclose(scene.angular_velocities, w, rtol=1e-5, atol=1e-5)
    assert scene.inertia_factor == pytest.approx(0.4, rel=1e-5)
