"""Fuzz: COUNT (1500) seeded random bad and edge inputs to Scene, Scene.random, Simulation.run,
langevin.run (and its threads=), TabulatedRestitution tables, scenes with a vibrating wall and
Simulation.load of damaged or crafted checkpoints (tests/helpers/fuzz_cases.py makes them and
says what passes). Each ends in a clear exception or a result that keeps the invariants --
never a crash, a hang or garbage.

One worker process runs the cases one after another and answers each over a pipe; a case that
takes longer than TIMEOUT, or kills the worker (a segfault, an abort under ASan), is recorded
and a new worker goes on with the next case. About 3 s on the 2-core development machine, plus
TIMEOUT for each case that hangs (under ASan about 8 s plus that).
"""

import json
import os
import select
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

from helpers.fuzz_cases import describe, make_cases

SEED = 20261125
COUNT = 1500
# A case's calls are small (n <= 50, <= 20000 events, <= a few hundred Langevin steps x 50
# particles): tens of ms, far below this. Sanitizer builds run slower: GRANULAR_FUZZ_TIMEOUT.
TIMEOUT = float(os.environ.get("GRANULAR_FUZZ_TIMEOUT", 10.0))
# Memory: refused or failed allocations must be clean errors; the worker's address space is
# capped so that an input asking for too much fails fast instead of swapping the machine
# (not under ASan, which reserves terabytes of shadow address space).
MEMORY_CAP = 8 << 30
HERE = Path(__file__).resolve().parent


class Worker:
    """A python process running fuzz_cases.worker; ask(i) -> (status, detail)."""

    def __init__(self):
        self.log = tempfile.TemporaryFile()
        code = (
            f"import sys; sys.path.insert(0, {str(HERE)!r}); import resource; "
            "from helpers import fuzz_cases\n"
            f"if 'asan' not in __import__('os').environ.get('LD_PRELOAD', ''):\n"
            f"    resource.setrlimit(resource.RLIMIT_AS, ({MEMORY_CAP}, {MEMORY_CAP}))\n"
            f"fuzz_cases.worker({SEED}, {COUNT})"
        )
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        # cwd: the tests directory, so `import granular` finds the installed package the
        # parent uses (under make test-asan, the sanitized one), as a user's script would
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
            cwd=HERE,
            env=env,
        )
        self.buffer, self.eof = b"", False
        assert self._line(60.0) == "ready", f"the fuzz worker did not start: {self._log()}"

    def _line(self, timeout):
        """The next line from the worker, or None on a timeout or (self.eof) its death."""
        deadline = time.monotonic() + timeout
        fd = self.proc.stdout.fileno()
        while b"\n" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                self.eof = True
                return None
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\n", 1)
        return line.decode()

    def _log(self):
        self.log.seek(0)
        return self.log.read().decode(errors="replace")[-1500:]

    def ask(self, i):
        self.proc.stdin.write(f"{i}\n".encode())
        self.proc.stdin.flush()
        line = self._line(TIMEOUT)
        if line is not None:
            return json.loads(line)
        self.close()
        if not self.eof:
            return "FAIL", f"no answer within {TIMEOUT:g} s (a hang, or far too slow)"
        return "FAIL", f"the worker died (exit code {self.proc.returncode}): {self._log()}"

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


def test_fuzz_inputs_end_in_a_clear_error_or_a_valid_result():
    cases = make_cases(SEED, COUNT)
    outcomes, worker = [], None
    try:
        for i in range(COUNT):
            try:
                if worker is None:
                    worker = Worker()
                status, detail = worker.ask(i)
            except BrokenPipeError:  # it died before reading the case
                status, detail = "FAIL", f"the worker died: {worker._log()}"
            if status == "FAIL" and worker.proc.poll() is not None:
                worker = None
            outcomes.append((status, detail))
    finally:
        if worker is not None:
            worker.proc.stdin.close()
            worker.close()

    tally = Counter((c["kind"], status) for c, (status, _) in zip(cases, outcomes, strict=True))
    failures = [
        f"#{i} {describe(cases[i])}\n    -> {detail}"
        for i, (status, detail) in enumerate(outcomes)
        if status == "FAIL"
    ]
    assert not failures, (
        f"{len(failures)} of {COUNT} fuzz cases failed "
        f"(tally {dict(tally)}):\n" + "\n".join(failures)
    )
    # not a vacuous run: every entry point both accepted inputs and refused some
    for kind in (
        "scene",
        "random",
        "run",
        "langevin",
        "table",
        "checkpoint",
        "threads",
        "stress",
        "vibrating",
        "falling",
    ):
        assert tally[kind, "ok"] >= 10 and tally[kind, "error"] >= 10, dict(tally)
