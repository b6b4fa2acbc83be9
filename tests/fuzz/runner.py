"""Generating cases (deterministically, with Hypothesis) and running them in worker subprocesses.

Each worker (:mod:`fuzz.worker`) runs many cases under a memory limit; the parent gives each case a
time limit. A worker that does not answer in time is killed (the case is a hang), one that dies is
a crash (or a memory blow-up when Rust reported a failed allocation); either way the parent records
the case and starts a fresh worker. ``--jobs`` workers run side by side, each fed from one queue.
"""

from __future__ import annotations

import dataclasses
import os
import pickle
import queue
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import seed as hypothesis_seed

from . import strategies
from .strategies import KINDS, MARKER_ENV, Case
from .worker import CODE_EXEC, CRASH, DEFECTS, HANG, MEMORY, read_frame, write_frame

PACKAGE_PARENT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# share of each kind in --kind all
SHARES = {
    "urdf": 0.25,
    "yaml": 0.18,
    "toml": 0.10,
    "arrays": 0.20,
    "mjcf": 0.07,
    "mesh": 0.06,
    "log": 0.06,
    "viewer": 0.04,
    "output": 0.04,
}


# ============================================================================ generating
def generate(kind: str, count: int, seed: int = 0, issue: bool = True) -> list:
    """``count`` cases of ``kind`` ("urdf", "yaml", "toml", "arrays" or "all") drawn by Hypothesis
    from a fixed seed: the same arguments give the same cases on every run; ``issue``: preceded by
    the reproducers of issue 11 of that kind (:func:`fuzz.strategies.issue_cases`)."""
    first = [c for c in strategies.issue_cases() if kind in ("all", c.kind)] if issue else []
    for i, case in enumerate(first):
        case.index = 90000 + i  # ids issue-90000... apart from the drawn cases
    if kind == "all":
        out = first
        for k in KINDS:
            out += generate(k, max(1, round(count * SHARES[k])), seed, issue=False)
        return out
    out: list = []

    @settings(
        max_examples=count,
        database=None,
        phases=[Phase.generate],
        deadline=None,
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @hypothesis_seed(seed)
    @given(strategies.cases(kind))
    def collect(case):
        out.append(case)

    collect()
    for i, case in enumerate(out):
        case.index = i
    return first + out


def case_id(case: Case) -> str:
    return f"{'issue' if case.seed == 'issue 11' else case.kind}-{case.index:05d}"


# ============================================================================ running
def load_factor() -> float:
    """How many times over the machine's CPUs are busy (1 when it has CPUs to spare): the 1-minute
    load average per CPU, at least 1 (1 where the load average is unknown)."""
    try:
        return max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))
    except (AttributeError, OSError):
        return 1.0


class Worker:
    """One worker subprocess; restarted after a hang or a crash."""

    def __init__(self, memory: int = 2 << 30, start_timeout: float = 120.0):
        self.memory = memory
        self.start_timeout = start_timeout
        self.folder = tempfile.mkdtemp(prefix="kd-fuzz-")
        self.marker = os.path.join(self.folder, "canary-marker")
        self.proc: subprocess.Popen | None = None
        self.starts = 0

    def _start(self) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([PACKAGE_PARENT] + [p for p in sys.path if p])
        env[MARKER_ENV] = self.marker
        env["KD_FUZZ_MEMORY"] = str(self.memory)
        env.setdefault("OPENBLAS_NUM_THREADS", "1")
        env.setdefault("OMP_NUM_THREADS", "1")
        env.setdefault("MALLOC_ARENA_MAX", "2")  # glibc's per-thread arenas would eat the address-space limit
        env.pop(strategies.CANARY_ENV, None)
        self.err_path = os.path.join(self.folder, "stderr")
        self.err = open(self.err_path, "wb")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "fuzz.worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.err,
            cwd=self.folder,
            env=env,
            start_new_session=True,
        )
        self.starts += 1
        ready = self._answer(self.start_timeout)
        if not isinstance(ready, dict) or "ready" not in ready:
            raise RuntimeError(f"the fuzz worker did not start: {self._stderr_tail()}")

    def _answer(self, timeout: float):
        """The next frame from the worker, "timeout", or None when it died."""
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            return "timeout"
        try:
            return read_frame(self.proc.stdout)
        except (EOFError, pickle.UnpicklingError, OSError):
            return None

    def _stderr_tail(self, n: int = 1500) -> str:
        try:
            with open(self.err_path, "rb") as f:
                f.seek(0, os.SEEK_END)
                f.seek(max(0, f.tell() - n))
                return f.read().decode("utf-8", "replace").strip()
        except OSError:
            return ""

    def stop(self) -> None:
        if self.proc is not None:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self.proc.wait()
            self.proc.stdin.close()
            self.proc.stdout.close()
            self.err.close()
            self.proc = None

    def close(self) -> None:
        self.stop()
        shutil.rmtree(self.folder, ignore_errors=True)

    def run(self, case: Case, timeout: float) -> dict:
        if self.proc is None:
            self._start()
        start = time.perf_counter()
        # the limit is in the seconds of an idle machine: on a machine running more work than it has
        # CPUs (parallel test workers, other jobs), a case gets proportionally more wall time, so that
        # a slow answer on a loaded machine is not taken for a hang
        timeout = timeout * load_factor()
        try:
            write_frame(self.proc.stdin, case)
            answer = self._answer(timeout)
        except (BrokenPipeError, OSError):
            answer = None
        if isinstance(answer, dict):
            return answer
        seconds = time.perf_counter() - start
        if answer == "timeout":
            self.stop()
            result = {
                "index": case.index,
                "outcome": HANG,
                "detail": f"no answer in {timeout:.3g} s",
                "seconds": seconds,
            }
        else:
            code = self.proc.wait()
            tail = self._stderr_tail()
            self.stop()
            how = (
                f"killed by signal {-code} ({signal.Signals(-code).name})" if code < 0 else f"exited with status {code}"
            )
            outcome = MEMORY if "memory allocation of" in tail or "MemoryError" in tail else CRASH
            result = {
                "index": case.index,
                "outcome": outcome,
                "detail": f"the worker {how}: {tail[-600:]}",
                "seconds": seconds,
            }
        if os.path.exists(self.marker):  # the canary ran before the worker hung or died
            os.remove(self.marker)
            result["detail"] = f"the canary ran (was: {result['outcome']}: {result['detail']})"
            result["outcome"] = CODE_EXEC
        return result


def run(cases: list, jobs: int = 1, timeout: float = 10.0, memory: int = 2 << 30, progress=None) -> list:
    """Results (dicts with outcome, detail, seconds), in the order of ``cases``."""
    results: list = [None] * len(cases)
    todo: queue.Queue = queue.Queue()
    for i, _case in enumerate(cases):
        todo.put(i)
    done = Counter()
    lock = threading.Lock()
    errors: list = []

    def work():
        worker = Worker(memory)
        try:
            while True:
                try:
                    i = todo.get_nowait()
                except queue.Empty:
                    return
                results[i] = worker.run(cases[i], timeout)
                with lock:
                    done["n"] += 1
                    if progress is not None:
                        progress(done["n"], len(cases))
        except BaseException as e:  # noqa: BLE001  (reported by the caller)
            errors.append(e)
        finally:
            worker.close()

    threads = [threading.Thread(target=work, daemon=True) for _ in range(max(1, min(jobs, len(cases))))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return results


# ============================================================================ figures
ROWS = (
    ("inputs tried", None),
    ("clean errors", "clean_error"),
    ("successes (finite results)", "success"),
    ("panics (PanicException)", "panic"),
    ("crashes (signal, abort)", "crash"),
    ("hangs (time limit)", "hang"),
    ("memory blow-ups", "memory"),
    ("silent non-finite results", "nonfinite"),
    ("non-ValueError exceptions", "bad_exception"),
    ("code execution (canary ran)", "code_exec"),
    ("messages without the file name", "no_filename"),
    ("messages repeating the file name", "repeated_name"),
    ("errors deferred past load", "deferred"),
    ("bad input accepted (complex, NaN, dup. keys)", "bad_input_accepted"),
    ("valid input rejected", "valid_rejected"),
    ("outputs over an input (data loss)", "data_loss"),
)


def counts(cases: list, results: list) -> dict:
    """{kind: Counter(outcome)} plus "all"."""
    table: dict = {k: Counter() for k in KINDS if any(c.kind == k for c in cases)}
    table["all"] = Counter()
    for case, result in zip(cases, results):
        table[case.kind][result["outcome"]] += 1
        table["all"][result["outcome"]] += 1
    return table


def defect_count(table: dict) -> int:
    return sum(table["all"][d] for d in DEFECTS)


def format_table(table: dict) -> str:
    kinds = list(table)
    width = max(len(r[0]) for r in ROWS)
    lines = [f"{'':{width}}  " + "  ".join(f"{k:>7}" for k in kinds)]
    for label, key in ROWS:
        values = [sum(table[k].values()) if key is None else table[k][key] for k in kinds]
        lines.append(f"{label:{width}}  " + "  ".join(f"{v:>7}" for v in values))
    return "\n".join(lines)


def failures(cases: list, results: list) -> list:
    return [(c, r) for c, r in zip(cases, results) if r["outcome"] in DEFECTS]


def write_failures(cases: list, results: list, folder: str) -> int:
    """Each failing case as ``<folder>/<class>/<id>.<ext|pkl>`` plus ``<id>.txt`` (what was done, what
    happened); ``scripts/fuzz --replay <id>.pkl`` runs one again."""
    n = 0
    for case, result in failures(cases, results):
        sub = os.path.join(folder, result["outcome"])
        os.makedirs(sub, exist_ok=True)
        name = case_id(case)
        with open(os.path.join(sub, name + ".pkl"), "wb") as f:
            pickle.dump(case, f)
        if case.kind != "arrays":
            with open(os.path.join(sub, name + case.ext), "wb") as f:
                f.write(case.data if isinstance(case.data, bytes) else case.data.encode("utf-8", "surrogatepass"))
        with open(os.path.join(sub, name + ".txt"), "w", encoding="utf-8") as f:
            f.write(describe(case, result) + "\n")
        n += 1
    return n


def describe(case: Case, result: dict) -> str:
    lines = [f"{case_id(case)}: {result['outcome']} after {result['seconds']:.2f} s", f"  seed: {case.seed}"]
    if case.kind == "arrays":
        spec, method, args, kwargs = case.call
        lines.append(f"  call: {method}({len(args)} positional, keywords {sorted(kwargs)})")
    lines += [f"  op: {op}" for op in case.ops]
    lines.append(f"  result: {result['detail']}")
    return "\n".join(lines)


# ============================================================================ shrinking
def shrink(case: Case, outcome: str, timeout: float, memory: int, budget: int = 150) -> Case:
    """A smaller file case with the same outcome: delta debugging over lines, then over characters
    of the longest line (Zeller's ddmin, simplified). Array cases are returned as they are."""
    if case.kind == "arrays":
        return case
    worker = Worker(memory)
    tries = 0

    def same(data) -> bool:
        nonlocal tries
        tries += 1
        trial = dataclasses.replace(case, data=data)
        return worker.run(trial, timeout)["outcome"] == outcome

    try:
        binary = isinstance(case.data, bytes)
        sep = b"\n" if binary else "\n"
        parts = case.data.split(sep)
        chunk = max(1, len(parts) // 2)
        while chunk >= 1 and tries < budget:
            i, removed = 0, False
            while i < len(parts) and tries < budget:
                trial = parts[:i] + parts[i + chunk :]
                if trial and same(sep.join(trial)):
                    parts, removed = trial, True
                else:
                    i += chunk
            if not removed:
                chunk //= 2
        data = sep.join(parts)
        return dataclasses.replace(case, ops=case.ops + (f"shrunk to {len(data)} characters",), data=data)
    finally:
        worker.close()
