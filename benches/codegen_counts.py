"""Operation counts of the robot-specialised programs (kinedyn.codegen): per robot and algorithm, the
arithmetic after recording (constants folded, repeated operations merged, dead code dropped) and
after the exact rewrites (negations absorbed), with the arithmetic floor's terms (adds + muls,
divides, sin_cos). Counts, not times: deterministic, so a table to compare with the timings of the
specialised kernels (operations per call against the machine's peak).

    PYTHONPATH=python python benches/codegen_counts.py [--robots ur5 panda iiwa]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import kinedyn as kd
from kinedyn import codegen


def load(name: str):
    """ur5 (built-in), panda (example-robot-data, fingers locked), iiwa (pybullet_data's KUKA iiwa)."""
    if name == "panda":
        from common import load_pair

        return load_pair("panda")[0]
    if name == "iiwa":
        import pybullet_data

        return kd.load(str(Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"))
    return kd.robots.get(name)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robots", nargs="+", default=["ur5", "panda", "iiwa"])
    args = p.parse_args()
    print("| robot | algorithm | recorded +/-,* | ÷ | neg | optimised +/-,* | ÷ | neg | sin_cos | record+optimise ms |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in args.robots:
        robot = load(name)
        for algorithm in codegen.ALGORITHMS:
            t = time.perf_counter()
            c = codegen.operation_counts(robot, algorithm)
            ms = (time.perf_counter() - t) * 1e3
            r, o = c["recorded"], c["optimized"]
            print(
                f"| {name} | {algorithm} | {r['add']}+{r['mul']} = {r['add_mul']} | {r['div']} | {r['neg']} "
                f"| {o['add']}+{o['mul']} = {o['add_mul']} | {o['div']} | {o['neg']} | {o['sincos']} | {ms:.0f} |"
            )


if __name__ == "__main__":
    main()
