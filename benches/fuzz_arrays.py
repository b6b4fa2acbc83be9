"""Array-call fuzzing of every public numeric method, thousands of cases (issue 11, "Tests and
figures"): the hypothesis strategies of tests/test_trust_native.py (wrong shapes and dtypes,
complex numbers, text, NaN/inf, values up to 1.7e308, batches), run on the Puma 560 and the UR5,
counting what each call did. Every case must be a clean error or a finite result; the script
exits 1 if any was not. A crash or hang of the process would stop the run itself (run it under
`timeout`).

    PYTHONPATH=python python3 benches/fuzz_arrays.py [--examples 3000] [--seed 0]
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_tests():
    spec = importlib.util.spec_from_file_location("test_trust_native", ROOT / "tests" / "test_trust_native.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=3000, help="cases per robot")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    from hypothesis import HealthCheck, given, seed, settings
    from hypothesis import strategies as st

    import kinedyn as kd

    tests = load_tests()
    counts: collections.Counter = collections.Counter()
    defects: list = []
    for robot in (kd.robots.puma560(), kd.robots.ur5()):

        @seed(args.seed)
        @settings(max_examples=args.examples, deadline=None, database=None, suppress_health_check=list(HealthCheck))
        @given(data=st.data(), name=st.sampled_from(tests.FUZZ_NAMES))
        def run(data, name):
            outcome = tests.fuzz_case(robot, data, name)
            counts[outcome.split(":")[0]] += 1
            if outcome not in ("clean error", "finite"):
                defects.append((robot.name, name, outcome))

        run()
    total = sum(counts.values())
    print(f"inputs tried: {total}")
    for kind in ("clean error", "finite", "non-finite result"):
        print(f"  {kind:20s} {counts.get(kind, 0)}")
    for kind, k in counts.items():
        if kind not in ("clean error", "finite", "non-finite result"):
            print(f"  {kind:20s} {k}")
    for d in defects[:20]:
        print("DEFECT", *d)
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
