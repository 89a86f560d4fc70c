"""Corrupted checkpoints, two ways.

- ``python checkpoint_fuzz.py COUNT``: corrupted engine states fed to the C restore
  (EDMD.restore_state), past the file's checksums.  Each case must end in ValueError (refused)
  or, when it passes the checks, in a bounded run that returns or raises a GranularError.
  Prints one JSON line of counts; a crash kills the process (the test sees its return code),
  and the case being tried is printed before each attempt so that a crash names it.
- ``apply_edits(data, edits, velocities)``: a checkpoint file's bytes damaged or crafted at
  every level -- the zip archive (truncated, bytes flipped, fields of its headers, members
  compressed, added or dropped), the .npy headers of its arrays, the meta JSON, and the
  engine state with its checksum made to match (header fields, words, particle records,
  image counters) -- for the "checkpoint" cases of tests/helpers/fuzz_cases.py.
"""

import hashlib
import io
import json
import sys
import zipfile

import numpy as np

from granular import GranularError, Scene, Simulation


def scenes():
    yield Scene.random(40, 0.03, dim=2, restitution=0.5, contact_duration=1e-4, seed=1), {}
    yield (
        Scene.random(40, 0.06, dim=3, boundary="walls", wall_restitution=0.9, seed=2),
        {},
    )
    yield Scene.random(60, 0.1, dim=3, seed=3), {"shell": 0.25}  # neighbour lists
    sheared = Scene.random(60, 0.1, dim=3, seed=5).replace(shear_rate=2.0)
    yield sheared, {"shell": 0.25}  # lists through sliding faces, shrinking shells
    pos = np.array([[0.5, 0.5], [0.1, 0.1], [0.9, 0.1], [0.1, 0.9], [0.9, 0.9], [0.2, 0.5]])
    radii = np.array([0.15, 0.02, 0.02, 0.02, 0.02, 0.02])  # one big particle
    vel = np.random.default_rng(4).normal(size=pos.shape)
    yield Scene(pos, vel, radii, box=1.0, boundary="walls"), {}


SPECIAL_INTS = [-(2**31), -(2**31) + 1, -100, -9, -8, -7, -3, -2, -1, 0, 1, 2, 63, 64, 2**31 - 1]
SPECIAL_DOUBLES = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1e308, -1e308, 5e-324, 1.0]


def corrupt(state, rng, n):
    data = bytearray(state)
    kind = int(rng.integers(0, 6))
    if kind == 0:  # truncated
        return bytes(data[: int(rng.integers(0, len(data)))]), "truncate"
    if kind == 1:  # bytes appended
        return bytes(data) + bytes(int(rng.integers(1, 16))), "append"
    if kind == 2:  # random bytes flipped
        for _ in range(int(rng.integers(1, 6))):
            data[int(rng.integers(0, len(data)))] ^= int(rng.integers(1, 256))
        return bytes(data), "flip"
    if kind in (3, 4):  # an aligned int32 overwritten with an index near a range's ends
        values = [*SPECIAL_INTS, n - 1, n, n + 1, -n, int(rng.integers(-(2**31), 2**31))]
        k = 4 * int(rng.integers(0, len(data) // 4))
        v = int(values[int(rng.integers(0, len(values)))])
        data[k : k + 4] = np.int32(v).tobytes()
        return bytes(data), f"int32 {v} at {k}"
    k = 8 * int(rng.integers(0, len(data) // 8))  # a double overwritten
    v = SPECIAL_DOUBLES[int(rng.integers(0, len(SPECIAL_DOUBLES)))]
    data[k : k + 8] = np.float64(v).tobytes()
    return bytes(data), f"double {v} at {k}"


def main(count):
    rng = np.random.default_rng(20261126)
    cases = []
    for scene, knobs in scenes():
        sim = Simulation(scene, **knobs)
        sim.run(stop_when={"events": 300})
        cases.append((scene, knobs, sim._engine.save_state()))
    counts = {"refused": 0, "accepted": 0, "ran": 0, "run_errors": 0}
    for k in range(count):
        scene, knobs, state = cases[k % len(cases)]
        bad, what = corrupt(state, rng, scene.n)
        print(f"case {k}: {what}", file=sys.stderr, flush=True)
        sim = Simulation(scene, **knobs)
        try:
            sim._engine.restore_state(bad)
        except ValueError:
            counts["refused"] += 1
            continue
        counts["accepted"] += 1
        try:
            sim.run(stop_when={"events": 2000}, store=())
            counts["ran"] += 1
        except (GranularError, ValueError, RuntimeError, MemoryError):
            counts["run_errors"] += 1
    print(json.dumps(counts))


# -- a checkpoint file, damaged or crafted ---------------------------------------------------


def _members(data):
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        return {info.filename: zf.read(info) for info in zf.infolist()}


def _zip(members, compress=zipfile.ZIP_STORED):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compress) as zf:
        for name, blob in members.items():
            zf.writestr(name, blob)
    return buf.getvalue()


def _npy_parts(blob):
    """(header dict, data bytes) of an .npy file's bytes."""
    fp = io.BytesIO(blob)
    np.lib.format.read_magic(fp)
    shape, fortran, dtype = np.lib.format.read_array_header_1_0(fp)
    header = {"descr": np.lib.format.dtype_to_descr(dtype), "fortran_order": fortran}
    return dict(header, shape=shape), blob[fp.tell() :]


def _npy(header, body):
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue() + body


def _meta(members):
    header, body = _npy_parts(members["meta.npy"])
    return json.loads(str(np.frombuffer(body, np.dtype(header["descr"]))[0]))


def _with_meta(members, meta):
    buf = io.BytesIO()
    np.save(buf, np.array(json.dumps(meta)))
    return dict(members, **{"meta.npy": buf.getvalue()})


def _with_state(members, state):
    """The members with the engine state replaced and its checksum made to match."""
    header, _ = _npy_parts(members["engine_state.npy"])
    out = dict(members, **{"engine_state.npy": _npy(dict(header, shape=(len(state),)), state)})
    meta = _meta(members)
    meta["engine_state_sha256"] = hashlib.sha256(state).hexdigest()
    return _with_meta(out, meta)


def _records_at(state, velocities):
    """Offsets of the particle records, masses and image counters in an engine state: the
    records (x, v, clock, radius each, padded to 8 doubles) start d doubles before particle
    0's velocity (no renumbering below 4096 particles: scene order), then come n masses,
    then n x d images."""
    n, d = velocities.shape
    at = state.find(velocities[0].tobytes()) - 8 * d
    if at < 0:
        return None
    masses = at + 8 * n * 8
    return at, masses, masses + 8 * n


def _edit_state(state, edit, velocities):
    state = bytearray(state)
    kind = edit[0]
    n, d = velocities.shape
    if kind == "state_int":  # a header field (at an offset) or any aligned word (a fraction)
        _, at, width, value = edit
        k = at if isinstance(at, int) else width * int(at * (len(state) // width))
        if k + width <= len(state):
            state[k : k + width] = np.array(value, dtype=f"<i{width}").tobytes()
    elif kind == "state_double":
        _, frac, value = edit
        k = 8 * int(frac * (len(state) // 8))
        if k + 8 <= len(state):
            state[k : k + 8] = np.float64(value).tobytes()
    elif kind in ("record", "image"):
        where = _records_at(bytes(state), velocities)
        if where is None:
            return bytes(state)
        records, _, images = where
        _, i, field, value = edit
        i %= n
        if kind == "record":  # field: 0..d-1 position, d..2d-1 velocity, 2d clock, 2d+1 radius
            k = records + 8 * (i * 8 + field % (2 * d + 2))
            state[k : k + 8] = np.float64(value).tobytes()
        else:
            k = images + 8 * (i * d + field % d)
            state[k : k + 8] = np.int64(value).tobytes()
    return bytes(state)


# the engine state header's fields (csrc/checkpoint.c `header`): (name, offset, width)
STATE_HEADER = [
    ("version", 8, 4),
    ("total", 24, 8),
    ("n", 32, 8),
    ("dim", 40, 4),
    ("stride", 44, 4),
    ("lists", 48, 4),
    ("nb", 52, 4),
    ("ncells", 56, 4),
    ("cap", 72, 4),
    ("big_n", 76, 4),
]


def apply_edits(data, edits, velocities):
    """The checkpoint bytes ``data`` with ``edits`` applied in turn; ``velocities`` (N, d):
    the saved state's, which locate the particle records.  Edits that change the engine
    state make its checksum match (a file crafted past the checksum)."""
    for edit in edits:
        kind = edit[0]
        try:
            members = _members(data)
        except Exception:  # noqa: BLE001 -- an earlier edit broke the archive: edit bytes only
            members = None
        if kind == "truncate":
            data = data[: int(edit[1] * len(data))]
        elif kind == "flip":
            b = bytearray(data)
            if b:
                b[int(edit[1] * len(b)) % len(b)] ^= edit[2]
            data = bytes(b)
        elif kind == "zip_field":  # a field of the first member's local and central headers
            _, field, value = edit
            at = {"flags": (6, 8), "method": (8, 10), "size": (22, 24), "offset": (None, 42)}
            b = bytearray(data)
            for sig, k in zip((b"PK\x03\x04", b"PK\x01\x02"), at[field], strict=True):
                pos = b.find(sig)
                if k is not None and pos >= 0:
                    width = 2 if field in ("flags", "method") else 4
                    b[pos + k : pos + k + width] = (value % 256**width).to_bytes(width, "little")
            data = bytes(b)
        elif members is None:
            continue
        elif kind == "rezip":
            data = _zip(members)
        elif kind == "compress":
            data = _zip(members, zipfile.ZIP_DEFLATED)
        elif kind == "extra_member":
            _, name, size = edit
            extra = {name: bytes(size)}
            data = _zip(dict(members, **extra), zipfile.ZIP_DEFLATED)
        elif kind == "drop_member":
            names = sorted(members)
            members.pop(names[edit[1] % len(names)])
            data = _zip(members)
        elif kind == "npy_header":  # a member's .npy header made to claim something else
            _, index, key, value = edit
            names = sorted(members)
            name = names[index % len(names)]
            header, body = _npy_parts(members[name])
            header[key] = value
            try:
                members[name] = _npy(header, body)
            except ValueError:  # NumPy cannot even write such a header
                continue
            data = _zip(members)
        elif kind == "meta":  # one field of the JSON set to a value
            _, path, value = edit
            try:
                meta = _meta(members)
            except Exception:  # noqa: BLE001 -- an earlier edit broke it
                continue
            node = meta
            for key in path[:-1]:
                node = node.setdefault(key, {}) if isinstance(node, dict) else node
            if isinstance(node, dict):
                node[path[-1]] = value
            data = _zip(_with_meta(members, meta))
        elif kind == "meta_raw":  # the JSON replaced by text (a piece, repeated)
            buf = io.BytesIO()
            np.save(buf, np.array(edit[1] * edit[2]))
            data = _zip(dict(members, **{"meta.npy": buf.getvalue()}))
        elif kind.startswith(("state_", "record", "image")):
            try:
                _, body = _npy_parts(members["engine_state.npy"])
                data = _zip(_with_state(members, _edit_state(body, edit, velocities)))
            except Exception:  # noqa: BLE001 -- an earlier edit broke the state's packaging
                continue
    return data


if __name__ == "__main__":
    main(int(sys.argv[1]))
