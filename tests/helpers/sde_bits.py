"""The Langevin engine's output bits, case by case: a SHA-256 of every array a run returns.

tests/sde_bits.json holds these digests as the engine computed them BEFORE its inner loop
was batched (csrc/sde.c: the random numbers of up to GR_SDE_BATCH steps drawn together),
from the unchanged main build (commit 402792d) -- so the test against it says the batched
engine gives the very same bits as the old step-by-step one, for every model, exponent,
scheme, dimension, thread count and chunking, with and without TAMSD lags and sample
times.  Regenerate (only for a deliberate change of the numbers) with

    python tests/helpers/sde_bits.py > tests/sde_bits.json
"""

import hashlib
import json
import math
import sys

import numpy as np

from granular import langevin

G0, D0, TAU0 = 9.26, 0.072, 0.972
MODELS = {  # name: (model, tau0, exponent); a != 1 makes the engine use its per-step tables
    "langevin": ("langevin", math.inf, 1.0),
    "udsbm": ("udsbm", TAU0, 1.0),
    "udsbm_a0.6": ("udsbm", TAU0, 0.6),
}


def cases():
    """name -> (n, chunk or None, run's keywords).  Step counts are not multiples of any
    batch size; sample times and lags fall anywhere in a batch, so runs are cut into
    segments of every length; N x steps x draws gives thousands of draws off the
    ziggurat's fast path (2.8% of draws)."""
    out = {}
    for mname, (model, tau0, expo) in MODELS.items():
        for scheme in ("em", "exact"):
            for dim in (1, 2, 3):
                base = dict(
                    gamma0=G0,
                    D0=D0,
                    tau0=tau0,
                    model=model,
                    exponent=expo,
                    scheme=scheme,
                    dim=dim,
                    dt=0.05,
                )
                # plain: the default samples, no lags, one thread, 1000 particles
                out[f"{mname}-{scheme}-{dim}d-plain"] = (
                    1000,
                    None,
                    dict(base, t_stop=173 * 0.05, seed=11, threads=1),
                )
                # samples at irregular steps, stored positions, TAMSD lags, two threads
                out[f"{mname}-{scheme}-{dim}d-lags"] = (
                    150,
                    None,
                    dict(
                        base,
                        t_stop=211 * 0.05,
                        seed=12,
                        threads=2,
                        sample_times=np.array([0, 1, 2, 5, 17, 40, 41, 100, 163, 211]) * 0.05,
                        tamsd_lags=np.array([1, 3, 8, 13, 50, 120]) * 0.05,
                        store_positions=True,
                    ),
                )
    # one particle at a time in segments of 7919 steps (Python's chunking), 3 threads
    for mname, scheme, dim in (
        ("udsbm_a0.6", "exact", 3),
        ("langevin", "em", 2),
        ("udsbm", "exact", 1),
    ):
        model, tau0, expo = MODELS[mname]
        out[f"{mname}-{scheme}-{dim}d-segments"] = (
            5,
            7919,
            dict(
                gamma0=G0,
                D0=D0,
                tau0=tau0,
                model=model,
                exponent=expo,
                scheme=scheme,
                dim=dim,
                dt=0.01,
                t_stop=20011 * 0.01,
                seed=13,
                threads=3,
                tamsd_lags=np.array([1, 7, 64, 1001]) * 0.01,
            ),
        )
    return out


def digest(r):
    """SHA-256 over the result's arrays, in a fixed order, as raw float64 bytes."""
    h = hashlib.sha256()
    arrays = [
        r.final_positions,
        r.final_velocities,
        r.msd_total,
        r.msd_per_dimension,
        r.v2,
        r.tamsd_per_particle,
    ]
    if r.positions is not None:
        arrays.append(r.positions)
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def run_case(case, monkeypatch=None):
    n, chunk, kw = case
    old = langevin._CHUNK_PARTICLE_STEPS
    if chunk is not None:
        if monkeypatch is not None:
            monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", chunk)
        else:
            langevin._CHUNK_PARTICLE_STEPS = chunk
    try:
        return langevin.run(n, **kw)
    finally:
        if monkeypatch is None:
            langevin._CHUNK_PARTICLE_STEPS = old


if __name__ == "__main__":
    json.dump({name: digest(run_case(c)) for name, c in cases().items()}, sys.stdout, indent=1)
    sys.stdout.write("\n")
