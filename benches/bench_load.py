"""URDF loading time against size: it should grow linearly (issue 11, section 2).

    python benches/bench_load.py [--sizes 500,1000,2000,4000] [--pinocchio]

Generated URDFs of three shapes, each of N links: a fixed chain (one revolute joint, then N fixed
links: the case whose default-tool search was cubic, 56 s for N = 2000), a moving chain (N revolute
joints in series) and a wide tree (N revolute joints on the root). Prints the median load time
(parse, checks, Robot construction; not the native model, built on first numeric call) and the
time per link, whose staying flat as N doubles is the linearity claim (the process CPU time per link
beside it is steadier than wall time on a shared machine). With ``--pinocchio``, the
same files through ``pinocchio.buildModelFromXML`` for scale, on chains of at most 2,000 links:
Pinocchio 4.1 crashes the process (segmentation fault, a recursion through the chain) on a
4,000-link chain, fixed or moving.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import kinedyn as kd

PIN_DEEPEST = 2000  # Pinocchio segfaults on deeper chains (see the docstring)
BODY = '<inertial><origin xyz="0.01 0 0.05" rpy="0 0.2 0"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'


def urdf(shape: str, n: int) -> str:
    links, joints, parent = ['<link name="base"/>'], [], "base"
    for i in range(n):
        links.append(f'<link name="l{i}">{BODY}</link>')
        if shape == "fixed chain":
            kind = "revolute" if i == 0 else "fixed"
        else:
            kind = "revolute"
        if shape == "wide tree":
            parent = "base"
        joints.append(
            f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="0 0 0.1" rpy="0 0.1 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>'
        )
        parent = f"l{i}"
    return '<robot name="bench">\n' + "\n".join(links + joints) + "\n</robot>\n"


def median_time(fn, repeats: int, clock=time.perf_counter) -> float:
    times = []
    for _ in range(repeats):
        start = clock()
        fn()
        times.append(clock() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="500,1000,2000,4000")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--pinocchio", action="store_true")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    pin = None
    if args.pinocchio:
        import pinocchio as pin
    warnings.simplefilter("ignore")
    header = f"{'shape':<12} {'links':>6} {'kinedyn s':>10} {'us/link':>8} {'CPU us/link':>12}" + (
        f" {'pinocchio s':>12}" if pin else ""
    )
    print(header)
    for shape in ("fixed chain", "moving chain", "wide tree"):
        for n in sizes:
            xml = urdf(shape, n)
            t = median_time(lambda: kd.Robot.from_urdf(xml), args.repeats)
            cpu = median_time(lambda: kd.Robot.from_urdf(xml), args.repeats, time.process_time)
            row = f"{shape:<12} {n:>6} {t:>10.3f} {1e6 * t / n:>8.0f} {1e6 * cpu / n:>12.0f}"
            if pin and (shape == "wide tree" or n <= PIN_DEEPEST):
                row += f" {median_time(lambda: pin.buildModelFromXML(xml), args.repeats):>12.3f}"
            elif pin:
                row += f" {'(crashes)':>12}"
            print(row, flush=True)


if __name__ == "__main__":
    main()
