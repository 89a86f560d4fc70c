"""A slow, obvious Langevin/UDSBM integrator in Python: the reference the C engine
(csrc/sde.c) is tested against, as reference_edmd.py is for EDMD.

It draws the SAME random numbers as the engine -- csrc/rng.h's counter-based stream
(SplitMix64 keyed by (key, step, particle)) and its 128-layer ziggurat, rewritten here in
Python integers (exact 64-bit arithmetic by masking) with the tables computed by the same
libm calls (Python's ``math`` module calls the C library's exp, log and sqrt) -- and then
integrates each particle step by step, written from the equations rather than from the C:

    dx = v dt,   dv = -gamma(t) v dt + sqrt(2 D(t)) gamma(t) dW
    Langevin: gamma0, D0;   UDSBM: gamma0 (1 + t/tau0)^-a, D0 (1 + t/tau0)^-a, a = exponent
    (a = 1: the thesis' gamma0 / (1 + t/tau0), D0 / (1 + t/tau0))

- "em": Euler-Maruyama, thesis (2.92)/(2.110), coefficients at the start of the step;
- "exact": the exact Gaussian update of the Ornstein-Uhlenbeck process over a step (mean
  and 2x2 covariance of (x, v) written out, sampled by a Cholesky factor with the
  velocity first), coefficients frozen at the step's midpoint for UDSBM.
- with an external force (uniform acceleration g, harmonic trap w = k/m per axis): the
  force at the start of the step for EM; for the exact scheme the step's mean and
  covariance from Van Loan's matrix exponentials (``force_step``), not the C core's
  series and doubling.

Step k (1-based) goes from (k-1) dt to k dt and draws from the stream of (key, k-1,
particle): for each axis in turn one normal (EM) or two (exact: the first drives v).
O(N x steps) Python-level work: tests only.
"""

import math

import numpy as np

MASK = (1 << 64) - 1
GOLDEN = 0x9E3779B97F4A7C15


def mix64(z):
    """SplitMix64's finaliser on a 64-bit integer."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def _ziggurat_tables():
    """Marsaglia & Tsang (2000), 128 layers: the start r of the tail and the area vn of
    each layer give every layer's edge; k is the integer acceptance bound, w the scale
    and f the density at each edge."""
    m1, vn = 2147483648.0, 9.91256303526217e-3
    dn = tn = 3.442619855899
    q = vn / math.exp(-0.5 * dn * dn)
    k, w, f = [0] * 128, [0.0] * 128, [0.0] * 128
    k[0] = int((dn / q) * m1)
    w[0], w[127] = q / m1, dn / m1
    f[0], f[127] = 1.0, math.exp(-0.5 * dn * dn)
    for i in range(126, 0, -1):
        dn = math.sqrt(-2.0 * math.log(vn / dn + math.exp(-0.5 * dn * dn)))
        k[i + 1] = int((dn / tn) * m1)
        tn = dn
        f[i] = math.exp(-0.5 * dn * dn)
        w[i] = dn / m1
    return k, w, f


ZIG_K, ZIG_W, ZIG_F = _ziggurat_tables()
ZIG_R = 3.442619855899


class Stream:
    """The draws of one (step, particle) under a key."""

    def __init__(self, key, step, particle):
        self.state = mix64((key + mix64((step * GOLDEN + particle) & MASK) * GOLDEN) & MASK)

    def next64(self):
        self.state = (self.state + GOLDEN) & MASK
        return mix64(self.state)

    def uniform(self):
        """In (0, 1): the top 53 bits, centred in their interval."""
        return (float(self.next64() >> 11) + 0.5) * (1.0 / 9007199254740992.0)

    def normal(self):
        """A standard normal: layer from the top 7 bits, signed magnitude from the low 32."""
        while True:
            u = self.next64()
            iz = u >> 57
            hz = u & 0xFFFFFFFF
            hz = hz - (1 << 32) if hz >= 1 << 31 else hz
            x = hz * ZIG_W[iz]
            if abs(hz) < ZIG_K[iz]:
                return x  # inside the layer's rectangle: most draws
            if iz == 0:  # the tail beyond r
                while True:
                    xx = -math.log(self.uniform()) / ZIG_R
                    yy = -math.log(self.uniform())
                    if yy + yy >= xx * xx:
                        return ZIG_R + xx if hz > 0 else -ZIG_R - xx
            if ZIG_F[iz] + self.uniform() * (ZIG_F[iz - 1] - ZIG_F[iz]) < math.exp(-0.5 * x * x):
                return x  # under the density in the layer's wedge


def coefficients(model, gamma0, D0, tau0, t, exponent=1.0):
    """gamma(t), D(t)."""
    s = 1.0 if model == "langevin" else (1.0 + t / tau0) ** -exponent
    return gamma0 * s, D0 * s


def ou_step(gamma, D, dt):
    """The exact update of (x, v) over dt at constant gamma, D: the mean is
    (x + v (1 - c)/gamma, c v) with c = exp(-gamma dt), and the noise covariance
    Var v = D gamma (1 - c^2), Cov(x, v) = D (1 - c)^2,
    Var x = (D / gamma) (2 h - 3 + 4 c - c^2), h = gamma dt.
    Returns c, (1 - c)/gamma and the lower Cholesky factor of the covariance ordered
    (v, x), so that (noise_v, noise_x) = L @ (z1, z2)."""
    h = gamma * dt
    c = math.exp(-h)
    cov = np.array(
        [
            [D * gamma * (1 - c * c), D * (1 - c) ** 2],
            [D * (1 - c) ** 2, D / gamma * (2 * h - 3 + 4 * c - c * c)],
        ]
    )
    return c, (1 - c) / gamma, np.linalg.cholesky(cov)


def force_step(gamma, D, w, dt):
    """The exact step of one axis under the linear force per mass f(X) = g - w (X - c):
    by Van Loan's block matrix exponentials (scipy.linalg.expm, a Pade approximant with
    scaling and squaring: a method independent of the C core's Taylor series and
    doubling),
        expm([[A, e2], [0, 0]] dt) = [[E, J], [0, 1]],
        expm([[-A, Q], [0, A^T]] dt) = [[., G12], [0, G22]],  E = G22^T, S = G22^T G12,
    with A = [[0, 1], [-w, -gamma]], Q = diag(0, 2 D gamma^2).  Returns E (2x2), J (2,) and
    the noise covariance S (2x2) of (x, v).  Accurate to ~1e-13 relative for steps not far
    from the rates (Van Loan's errors are relative to the largest entries)."""
    from scipy.linalg import expm

    A = np.array([[0.0, 1.0], [-w, -gamma]])
    M = np.zeros((3, 3))
    M[:2, :2], M[1, 2] = A * dt, dt
    F = expm(M)
    Q = np.diag([0.0, 2.0 * D * gamma * gamma])
    C = np.zeros((4, 4))
    C[:2, :2], C[:2, 2:], C[2:, 2:] = -A * dt, Q * dt, A.T * dt
    G = expm(C)
    E = G[2:, 2:].T
    return E, F[:2, 2], E @ G[:2, 2:]


def force_step_stationary(gamma, D, w, dt):
    """The step's covariance from the stationary one (w > 0): S = S_inf - E S_inf E^T,
    S_inf = diag(D gamma / w, D gamma) (equipartition: k <x^2> = m <v^2> = T, T/m = D gamma),
    with E from scipy.linalg.expm: a third check, cancelling badly for short steps but exact
    in form, and the form that shows the stationary state is kept."""
    from scipy.linalg import expm

    E = expm(np.array([[0.0, 1.0], [-w, -gamma]]) * dt)
    S_inf = np.diag([D * gamma / w, D * gamma])
    return S_inf - E @ S_inf @ E.T


def force_coefficients(gamma, D, w, dt):
    """What the exact step with a force uses, from ``force_step``: (e12, e22, j1) of the
    mean and the Cholesky factor of the covariance ordered (v, x), as ``ou_step``."""
    E, J, S = force_step(gamma, D, w, dt)
    L = np.linalg.cholesky(np.array([[S[1, 1], S[0, 1]], [S[0, 1], S[0, 0]]]))
    return E[0, 1], E[1, 1], J[0], L


def em_trap_spectral_radius(gamma, w, dt):
    """The spectral radius of Euler-Maruyama's map on the mean in a trap,
    [[1, dt], [-w dt, 1 - gamma dt]]: the scheme is stable iff it is below 1."""
    return max(abs(np.linalg.eigvals(np.array([[1.0, dt], [-w * dt, 1.0 - gamma * dt]]))))


def em_trap_stationary(gamma, D, w, dt):
    """Euler-Maruyama's own stationary covariance of (x, v) in a trap: the solution of the
    discrete Lyapunov equation S = M S M^T + diag(0, 2 D gamma^2 dt), M its map (solved as
    a linear system): what EM converges to instead of diag(D gamma / w, D gamma)."""
    M = np.array([[1.0, dt], [-w * dt, 1.0 - gamma * dt]])
    Q = np.array([0.0, 0.0, 0.0, 2.0 * D * gamma * gamma * dt])
    vec = np.linalg.solve(np.eye(4) - np.kron(M, M), Q)
    return vec.reshape(2, 2)


def run(
    v0,
    key,
    *,
    model,
    scheme,
    gamma0,
    D0,
    tau0,
    dt,
    n_steps,
    first=0,
    exponent=1.0,
    accel=None,
    stiffness=None,
    origin=None,
):
    """Positions (n_steps + 1, N, d) and velocities (n_steps + 1, N, d) at every step of
    particles first .. first + N - 1 starting at the origin with velocities v0 (N, d).
    With ``accel`` g and ``stiffness`` w (d each; Langevin model only) the force per mass
    g - w (X - c) acts, X - c = origin + x (origin (N, d): the starts relative to the
    trap's centre); Euler-Maruyama takes it at the start of the step, the exact scheme
    steps with ``force_coefficients``."""
    v0 = np.asarray(v0, dtype=np.float64)
    n, d = v0.shape
    xs = np.zeros((n_steps + 1, n, d))
    vs = np.zeros((n_steps + 1, n, d))
    vs[0] = v0
    if accel is not None or stiffness is not None:
        g = np.zeros(d) if accel is None else np.asarray(accel, dtype=np.float64)
        w = np.zeros(d) if stiffness is None else np.asarray(stiffness, dtype=np.float64)
        o = np.zeros((n, d)) if origin is None else np.asarray(origin, dtype=np.float64)
        coef = [force_coefficients(gamma0, D0, w[a], dt) for a in range(d)]
        for i in range(n):
            x, v = [0.0] * d, list(v0[i])
            for k in range(1, n_steps + 1):
                rs = Stream(key, k - 1, first + i)
                for a in range(d):
                    f = g[a] - w[a] * (o[i, a] + x[a])
                    if scheme == "em":
                        dW = math.sqrt(dt) * rs.normal()
                        x[a], v[a] = (
                            x[a] + v[a] * dt,
                            v[a] + (f - gamma0 * v[a]) * dt + math.sqrt(2 * D0) * gamma0 * dW,
                        )
                    else:
                        e12, e22, j1, L = coef[a]
                        z1, z2 = rs.normal(), rs.normal()
                        x[a] += v[a] * e12 + f * j1 + L[1, 0] * z1 + L[1, 1] * z2
                        v[a] = e22 * v[a] + e12 * f + L[0, 0] * z1
                xs[k, i], vs[k, i] = x, v
        return xs, vs
    for i in range(n):
        x, v = [0.0] * d, list(v0[i])
        for k in range(1, n_steps + 1):
            rs = Stream(key, k - 1, first + i)
            if scheme == "em":
                g, D = coefficients(model, gamma0, D0, tau0, (k - 1) * dt, exponent)
                for a in range(d):
                    dW = math.sqrt(dt) * rs.normal()
                    x[a], v[a] = x[a] + v[a] * dt, v[a] - g * v[a] * dt + math.sqrt(2 * D) * g * dW
            else:
                g, D = coefficients(model, gamma0, D0, tau0, (k - 0.5) * dt, exponent)
                c, drift, L = ou_step(g, D, dt)
                for a in range(d):
                    z1, z2 = rs.normal(), rs.normal()
                    x[a] += v[a] * drift + L[1, 0] * z1 + L[1, 1] * z2
                    v[a] = c * v[a] + L[0, 0] * z1
            xs[k, i], vs[k, i] = x, v
    return xs, vs


def stride(lag, estimator="strided"):
    """The spacing of window starts, from csrc/tamsd.h's definition: every step for "all";
    for "strided" the largest power of two <= max(1, lag // 4)."""
    if estimator == "all":
        return 1
    s = 1
    while 2 * s <= lag // 4:
        s *= 2
    return s


def tamsd_per_particle(xs, lag, stride):
    """(N,) time-averaged MSD at a lag (in steps) over the windows the engine averages:
    starting at steps 0, stride, 2 stride, ... while they end by the last step."""
    starts = np.arange(0, len(xs) - lag, stride)
    d = xs[starts + lag] - xs[starts]
    return (d * d).sum(axis=2).mean(axis=0)


def engine(
    v0,
    key,
    *,
    model,
    scheme,
    gamma0,
    D0,
    tau0,
    dt,
    n_steps,
    lags=(),
    first=0,
    n=None,
    sample_steps=None,
    estimator="strided",
    threads=1,
    exponent=1.0,
    accel=None,
    stiffness=None,
    origin=None,
):
    """The C engine's raw entry point (``_core.sde_run``) over a whole run, with fresh
    buffers, for comparison with ``run``: samples at every step unless ``sample_steps``.
    Returns positions (T, N, d), final velocities (N, d), x2 (T, d) summed over the
    particles, and the per-particle TAMSD sums (N, L) over the windows."""
    from granular import _core

    v = np.array(v0, dtype=np.float64)
    count, d = v.shape
    n = count if n is None else n
    steps = (
        np.arange(n_steps + 1, dtype=np.int64)
        if sample_steps is None
        else np.asarray(sample_steps, dtype=np.int64)
    )
    lags = np.asarray(lags, dtype=np.int64).reshape(-1)
    x = np.zeros((count, d))
    x2, v2 = np.zeros((len(steps), d)), np.zeros((len(steps), d))
    positions = np.zeros((len(steps), n, d))
    tamsd = np.zeros((n, len(lags)))
    code = ("strided", "all").index(estimator)
    ring = np.zeros(_core.sde_ring_size(d, lags, code))
    _core.sde_run(
        dim=d,
        model=("langevin", "udsbm").index(model),
        scheme=("em", "exact").index(scheme),
        gamma0=gamma0,
        D0=D0,
        tau0=tau0 if model == "udsbm" else math.inf,
        dt=dt,
        key=key,
        n=n,
        first=first,
        step_from=0,
        step_to=n_steps,
        n_steps=n_steps,
        x=x,
        v=v,
        sample_steps=steps,
        x2=x2,
        v2=v2,
        positions=positions,
        lags=lags,
        tamsd=tamsd,
        ring=ring,
        carry=None,
        threads=threads,
        tamsd_estimator=code,
        exponent=exponent,
        **_force_args(accel, stiffness, origin),
    )
    return positions[:, first : first + count], v, x2, tamsd[first : first + count]


def _force_args(accel, stiffness, origin):
    """sde_run's force keywords as fresh float64 arrays, only those given."""
    out = {}
    for name, value in (("accel", accel), ("stiffness", stiffness), ("origin", origin)):
        if value is not None:
            out[name] = np.array(value, dtype=np.float64)
    return out


def one_step_args(**changes):
    """Keyword arguments of ``_core.sde_run`` for one 3D particle over one exact UDSBM step
    (fresh arrays each call), with ``changes`` applied: the base the binding's own checks
    are tried on."""
    args = dict(
        dim=3,
        model=1,
        scheme=1,
        gamma0=1.0,
        D0=1.0,
        tau0=1.0,
        dt=0.01,
        key=1,
        n=1,
        first=0,
        step_from=0,
        step_to=1,
        n_steps=1,
        x=np.zeros((1, 3)),
        v=np.zeros((1, 3)),
        sample_steps=np.array([0, 1]),
        x2=np.zeros((2, 3)),
        v2=np.zeros((2, 3)),
        positions=None,
        lags=np.zeros(0, np.int64),
        tamsd=np.zeros((1, 0)),
        ring=np.zeros(0),
    )
    return args | changes
