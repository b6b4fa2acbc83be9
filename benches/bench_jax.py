"""JAX backend benchmark (issue 15 §3; not a timed test).

Per-state time of ``eom.compile(backend="jax")`` — ``jax.jit(jax.vmap(fn.tau))`` and ``fn.M`` over a
batch of N states (default 10^5) — against the Rust core's batch calls ``robot.inverse_dynamics`` and
``robot.mass_matrix`` on the same states, in the same run, and (for reference) the C backend of
``eom.compile``. Compile time of the jitted function is reported separately (first call). Best of
``--repeat`` runs. On a GPU (jax[cuda]) the JAX figures are the device's; the default is the CPU.

    PYTHONPATH=python python benches/bench_jax.py [--robot puma560|planar_2r|ur5] [--states N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import kinedyn as kd


def best(f, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", default="puma560")
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    if args.robot == "ur5":
        import os

        from kinedyn.testing import example_robot_data_dir

        robot = kd.Robot.from_urdf(os.path.join(example_robot_data_dir(), "ur_description", "urdf", "ur5_robot.urdf"))
    else:
        robot = getattr(kd.robots, args.robot)()
    import jax

    eom = robot.equations_of_motion(method="newton_euler", steps=False)
    t = time.perf_counter()
    fj = eom.compile(backend="jax", what=("M", "tau"))
    t_build = time.perf_counter() - t
    fc = eom.compile(backend="auto", what=("M", "tau"))
    rng = np.random.default_rng(0)
    N, n = args.states, robot.n
    Q, QD, QDD = (rng.uniform(-2, 2, size=(N, n)) for _ in range(3))
    tau = jax.jit(jax.vmap(fj.tau))
    mass = jax.jit(jax.vmap(fj.M))
    Qj, QDj, QDDj = (jax.device_put(x) for x in (Q, QD, QDD))
    t = time.perf_counter()
    tau(Qj, QDj, QDDj).block_until_ready()
    mass(Qj).block_until_ready()
    t_jit = time.perf_counter() - t
    err = float(np.abs(np.asarray(tau(Qj, QDj, QDDj)) - robot.inverse_dynamics(Q, QD, QDD)).max())
    rows = [
        ("tau  jax jit(vmap)", best(lambda: tau(Qj, QDj, QDDj).block_until_ready(), args.repeat)),
        ("tau  rust batch", best(lambda: robot.inverse_dynamics(Q, QD, QDD), args.repeat)),
        (f"tau  compile({fc.backend})", best(lambda: fc.tau(Q, QD, QDD), args.repeat)),
        ("M    jax jit(vmap)", best(lambda: mass(Qj).block_until_ready(), args.repeat)),
        ("M    rust batch", best(lambda: robot.mass_matrix(Q), args.repeat)),
        (f"M    compile({fc.backend})", best(lambda: fc.M(Q), args.repeat)),
    ]
    print(
        f"{robot.name}: n = {n}, {N} states, JAX {jax.__version__} on {jax.devices()[0].platform}; "
        f"build {t_build:.2f} s, jit compile (tau + M) {t_jit:.2f} s; max |tau_jax - tau_rust| = {err:.1e}"
    )
    per = dict(rows)
    for label, s in rows:
        print(f"  {label:22s} {s * 1e9 / N:9.1f} ns/state")
    print(
        f"  ratio jax/rust: tau {per['tau  jax jit(vmap)'] / per['tau  rust batch']:.2f}, "
        f"M {per['M    jax jit(vmap)'] / per['M    rust batch']:.2f}"
    )


if __name__ == "__main__":
    main()
