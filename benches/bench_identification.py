"""Identification methods compared on simulated arms with known truth (issue 29), in the spirit of
BIRDy's protocol (Leboutet, Roux, Janot, Guadarrama-Olvera & Cheng, "Inertial parameter
identification in robotics: a survey", Applied Sciences 11(9), 2021): each arm tracks a Fourier
reference under a controller that reads a noisy encoder (closed loop), or follows it exactly with
noisy torques (open loop); Monte Carlo repetitions over the noise seeds; for each method the
relative error of the base parameters ``|theta - theta*| / |theta*|`` and the held-out torque error
(RMS of the prediction error on another run over the RMS torque), median over the repetitions.

Arms: a vertical 2R with motors behind gears (armature, viscous and per-direction Coulomb
friction), PD-controlled; the PUMA 560 (kinedyn's built-in with Corke's motor and friction table),
under computed torque with a prior model 15 % off. The truth's base parameters (links and every
joint's armature) come from the true robot's parameters through the same grouping.

    PYTHONPATH=python python benches/bench_identification.py [--arms 2r puma560] [--noise 5e-4 2e-3]
        [--reps 3] [--seconds 6] [--methods ols wls irls iv didim]

Not a test: it prints a Markdown table (figures in benches/NOTES.md).
"""

from __future__ import annotations

import argparse
import dataclasses
import time
import warnings

import numpy as np

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.analysis.parameters import base_parameters_with_rotors, with_inertial_parameters
from kinedyn.simulate.control import PD, ComputedTorque

warnings.filterwarnings("ignore")
DT = 1e-3


def two_r():
    base = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=3.0, m2=2.0)
    drives = {"q1": (0.35, 0.8, (1.5, 1.1)), "q2": (0.12, 0.4, (0.7, 0.9))}
    links = []
    for link in base.links:
        if link.joint.name in drives:
            a, fv, fc = drives[link.joint.name]
            j = dataclasses.replace(
                link.joint, gear_ratio=40.0, rotor_inertia=a / 1600.0, viscous=fv, coulomb=fc[0], coulomb_negative=fc[1]
            )
            link = dataclasses.replace(link, joint=j)
        links.append(link)
    true = base.replace(links=links)
    prior = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=2.4, m2=2.5)
    ref = an.excitation(true, harmonics=4, period=6.0, amplitude=1.0, seed=0)
    controller = PD(np.diag([400.0, 200.0]), np.diag([40.0, 20.0]), ref)
    return true, prior, ref, controller


def puma():
    true = kd.robots.puma560(friction=True)
    pi = true.inertial_parameters().reshape(true.n, 10).copy()
    pi *= 0.85  # the prior: every body 15 % lighter (a scaled body stays physical)
    prior = with_inertial_parameters(true, pi.reshape(-1))
    ref = an.excitation(true, harmonics=4, period=6.0, amplitude=0.5, seed=0)
    controller = ComputedTorque(prior, np.full(6, 100.0), np.full(6, 20.0), ref, model=prior)
    return true, prior, ref, controller


ARMS = {"2r": two_r, "puma560": puma}


def closed_loop(true, ref, controller, seconds, noise, seed):
    """Columns of a log: encoder positions (the controller reads them) and the controller's torques."""
    steps = int(round(seconds / DT))
    e = np.random.default_rng(seed).normal(scale=noise, size=(steps + 1, true.n))

    def noisy(t, q, qd):
        return controller(t, q + e[int(round(t / DT))], qd)

    q0, qd0, _ = ref(np.zeros(1))
    run = kd.simulate(true, seconds, np.concatenate([q0[0], qd0[0]]), controller=noisy, method="rk4", dt=DT, hold=True)
    q = run.q + e[: len(run.t)]
    tau = np.array([controller(t, a, b) for t, a, b in zip(run.t, q, run.qd)])
    return columns(run.t, q, tau)


def open_loop(true, ref, seconds, noise, seed):
    """The reference followed exactly, encoder noise on q, torque noise of 1 % of each joint's range."""
    t = np.arange(int(round(seconds / DT)) + 1) * DT
    q, qd, qdd = ref(t)
    tau = true.inverse_dynamics(q, qd, qdd)
    rng = np.random.default_rng(seed)
    tau = tau + rng.normal(size=tau.shape) * 0.01 * (tau.max(axis=0) - tau.min(axis=0))
    return columns(t, q + rng.normal(scale=noise, size=q.shape), tau)


def columns(t, q, tau):
    cols = {"t": t}
    for j in range(q.shape[1]):
        cols[f"q{j + 1}"], cols[f"tau{j + 1}"] = q[:, j], tau[:, j]
    return cols


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--arms", nargs="+", default=list(ARMS), choices=list(ARMS))
    ap.add_argument("--noise", nargs="+", type=float, default=[5e-4, 2e-3], help="encoder noise, rad")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=6.0)
    ap.add_argument("--cutoff", type=float, default=10.0)
    ap.add_argument("--methods", nargs="+", default=["ols", "wls", "irls", "iv", "didim"])
    args = ap.parse_args()
    print(
        "| arm | data | encoder noise (rad) | method | parameter error (median) | held-out torque error (median) | time / fit |"
    )
    print("|---|---|---|---|---|---|---|")
    for arm in args.arms:
        true, prior, ref, controller = ARMS[arm]()
        joints = tuple(range(true.n))
        base = base_parameters_with_rotors(true, joints)
        truth = dict(zip(base.names, base.values))
        options = dict(friction="viscous+asymmetric", armature=True, cutoff=args.cutoff)
        for data in ("closed", "open"):
            for noise in args.noise:
                errors: dict = {m: [] for m in args.methods}
                held: dict = {m: [] for m in args.methods}
                times: dict = {m: [] for m in args.methods}
                for rep in range(args.reps):
                    if data == "closed":
                        fit = closed_loop(true, ref, controller, args.seconds, noise, seed=10 * rep + 1)
                        other = closed_loop(true, ref, controller, args.seconds, noise, seed=10 * rep + 2)
                    else:
                        fit = open_loop(true, ref, args.seconds, noise, seed=10 * rep + 1)
                        other = open_loop(true, ref, args.seconds, noise, seed=10 * rep + 2)
                    log = an.load_log(fit, n=true.n, cutoff=args.cutoff)
                    for m in args.methods:
                        if m in ("iv", "didim") and data == "open":
                            continue
                        t0 = time.perf_counter()
                        try:
                            r = an.identify(
                                prior,
                                log,
                                method=m,
                                controller=controller if m in ("iv", "didim") else None,
                                **{k: v for k, v in options.items() if k != "cutoff"},
                            )
                        except ValueError as e:  # an estimate that cannot be simulated
                            print(f"<!-- {arm} {data} {noise} {m} rep {rep}: {e} -->")
                            continue
                        times[m].append(time.perf_counter() - t0)
                        est = np.array([r.estimates[list(r.names).index(nm)] for nm in truth if nm in r.names])
                        ref_values = np.array([truth[nm] for nm in truth if nm in r.names])
                        errors[m].append(np.linalg.norm(est - ref_values) / np.linalg.norm(ref_values))
                        check = r.validate(other, cutoff=args.cutoff)
                        held[m].append(
                            float(np.sqrt(np.mean(check.residuals**2)) / np.sqrt(np.mean(check.measured**2)))
                        )
                for m in args.methods:
                    if not errors[m]:
                        continue
                    print(
                        f"| {arm} | {data}-loop | {noise:g} | {m} | {100 * np.median(errors[m]):.2f} % | "
                        f"{100 * np.median(held[m]):.2f} % | {np.median(times[m]):.2f} s |",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
