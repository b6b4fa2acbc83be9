"""The fuzz suite in CI (issue 11): a few hundred mutated robot files and hostile numeric calls, each
run in a worker subprocess under a time and a memory limit, and not one defect.

The cases are drawn by Hypothesis from a fixed seed, so a failure here is reproducible with
``scripts/fuzz --seed 11 --cases 520 --timeout 5`` (which also writes the failing inputs to a
folder). Defect classes: see :mod:`fuzz.worker`; docs/testing.md explains the figures.
"""

import os

import pytest
from fuzz import runner
from fuzz.strategies import KINDS, Case
from fuzz.worker import CLASSES, DEFECTS

SEED = 11
CASES = 520  # ~60 s on 2 cores with --jobs 2 (generation ~6 s)
TIMEOUT = 5.0  # seconds per case; every loader and call should answer in milliseconds
MEMORY = 2 << 30  # bytes of address space per worker
JOBS = max(1, min(2, os.cpu_count() or 1))


@pytest.fixture(scope="module")
def figures():
    cases = runner.generate("all", CASES, SEED)
    results = runner.run(cases, jobs=JOBS, timeout=TIMEOUT, memory=MEMORY)
    table = runner.counts(cases, results)
    print(f"\nfuzz figures (seed {SEED}, {len(cases)} cases):\n" + runner.format_table(table))
    return cases, results, table


def test_the_harness_classifies_misbehaviour():
    """The classes themselves: a clean error, the canary evaluated, a segfault, an abort, a hang and
    a memory blow-up, each done on purpose inside a worker, are each seen as what they are."""
    expected = {
        "clean": "clean_error",
        "canary": "code_exec",
        "segfault": "crash",
        "abort": "crash",
        "hang": "hang",
        "memory": "memory",
    }
    cases = [Case(kind="selftest", seed="selftest", ops=(what,), data=what, index=i) for i, what in enumerate(expected)]
    results = runner.run(cases, jobs=JOBS, timeout=3.0, memory=MEMORY)
    got = {c.data: r["outcome"] for c, r in zip(cases, results)}
    assert got == expected
    assert "fuzzcase.yaml" in results[0]["detail"]  # the clean error names the file


def _canonical(x) -> str:
    """A text that is equal for equal values (arrays by dtype, shape and bytes), whatever objects are
    shared (a pickle would differ with string interning)."""
    import numpy as np

    if isinstance(x, np.ndarray):
        # (object arrays by value; long doubles too: their padding bytes are uninitialised)
        data = _canonical(x.tolist()) if x.dtype in (object, np.longdouble) else x.tobytes().hex()
        return f"array({x.dtype.str},{x.shape},{data})"
    if isinstance(x, (list, tuple)):
        return type(x).__name__ + "[" + ",".join(_canonical(v) for v in x) + "]"
    if isinstance(x, dict):
        return "{" + ",".join(f"{_canonical(k)}:{_canonical(v)}" for k, v in x.items()) + "}"
    return repr(x)


def _fingerprint(cases) -> str:
    import hashlib

    return hashlib.sha256(_canonical([(c.kind, c.seed, c.ops, c.data, c.call) for c in cases]).encode()).hexdigest()


def test_the_cases_are_the_same_on_every_run():
    """The same seed gives the same cases, arrays included, in this process and in a fresh one."""
    import subprocess
    import sys

    a = runner.generate("all", 60, SEED)
    assert _fingerprint(a) == _fingerprint(runner.generate("all", 60, SEED))
    code = f"import sys; sys.path[:0] = {sys.path!r}; from fuzz import runner; import test_fuzz; print(test_fuzz._fingerprint(runner.generate('all', 60, {SEED})))"
    other = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=os.path.dirname(__file__)
    )
    assert other.stdout.strip() == _fingerprint(a), other.stderr[-2000:]
    assert {c.kind for c in a} == set(KINDS)
    assert len({c.ops for c in a}) > 50  # varied, not one mutation over and over


@pytest.mark.parametrize("defect", DEFECTS)
def test_no_defect(figures, defect):
    cases, results, table = figures
    bad = [(c, r) for c, r in zip(cases, results) if r["outcome"] == defect]
    examples = "\n\n".join(runner.describe(c, r) for c, r in bad[:5])
    if bad:  # (pytest.fail: the message without a repr of the cases)
        pytest.fail(
            f"{len(bad)} cases of '{defect}':\n{runner.format_table(table)}\n\nfirst of them:\n{examples}",
            pytrace=False,
        )


def test_every_case_was_classified(figures):
    cases, results, table = figures
    assert sum(table["all"].values()) == len(cases) >= CASES - 5
    assert set(table["all"]) <= set(CLASSES)
    assert table["all"]["clean_error"] > 0 and table["all"]["success"] > 0  # the mutations reach both sides
