"""Identification benchmark (issue 16, Tests: the Panda from 60 s at 1 kHz in under 10 s
unconstrained and under 60 s consistent; not a timed test).

A simulated log of the Panda (example-robot-data's URDF, arm joints only) whose links are 10 %
heavier than the prior model's: 60 s at 1 kHz of a 5-harmonic Fourier excitation, viscous and Coulomb
friction, torque noise of 0.5 % of each joint's range, 17-bit encoders, positions and torques only.
Times, each the best of ``--repeat`` runs: ``load_log`` (filter, differentiate, decimate),
``identify`` unconstrained (OLS, WLS) and ``identify(consistent=True)`` (the SDP through cvxpy and
Clarabel), with the held-out torque RMS / noise per joint.

    PYTHONPATH=python python benches/bench_identify.py [--seconds 60] [--repeat 2]
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.testing import example_robot_data_dir

warnings.filterwarnings("ignore")


def panda():
    root = example_robot_data_dir()
    if root is None:
        raise SystemExit("example-robot-data is not installed (pip install 'kinedyn[peers]')")
    robot = kd.load(os.path.join(root, "panda_description", "urdf", "panda.urdf"))
    fingers = [j for j in robot.joint_names if "finger" in j]
    return robot.lock_joints(fingers) if fingers else robot


def make_log(robot, seconds: float, seed: int):
    ref = an.excitation(robot, harmonics=5, period=10.0, amplitude=0.5, seed=seed)
    t = np.arange(int(seconds * 1000)) / 1000.0
    q, qd, qdd = ref(t)
    tau = robot.inverse_dynamics(q, qd, qdd) + 0.4 * qd + 0.8 * np.sign(qd)
    sigma = 0.005 * (tau.max(axis=0) - tau.min(axis=0))
    tau += np.random.default_rng(seed).normal(size=tau.shape) * sigma
    step = 2 * np.pi / 2**17
    cols = {"t": t}
    for j in range(robot.n):
        cols[f"q{j + 1}"] = np.round(q[:, j] / step) * step
        cols[f"tau{j + 1}"] = tau[:, j]
    return cols, sigma


def best(f, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    prior = panda()
    pi = prior.inertial_parameters() * 1.1  # every body 10 % heavier, same shape
    true = an.with_inertial_parameters(prior, pi)
    cols, sigma = make_log(true, args.seconds, seed=1)
    held_out, _ = make_log(true, 20.0, seed=2)
    t_load, log = best(lambda: an.load_log(cols, n=prior.n), args.repeat)
    print(
        f"Panda ({prior.n} joints), {args.seconds:g} s at 1 kHz -> {len(log)} samples after filtering "
        f"(cut-off {log.cutoff:.3g} Hz, decimation {log.decimation})"
    )
    print(f"load_log                     {t_load:8.3f} s")
    for label, kw in (
        ("identify OLS", {}),
        ("identify WLS", dict(weighted=True)),
        ("identify consistent (SDP)", dict(consistent=True)),
    ):
        t_fit, res = best(lambda: an.identify(prior, log, **kw), args.repeat)
        ratio = res.validate(held_out).rms / sigma
        print(
            f"{label:<28} {t_fit:8.3f} s   load + fit {t_load + t_fit:8.3f} s   held-out RMS / noise per joint {np.round(ratio, 2)}"
        )


if __name__ == "__main__":
    main()
