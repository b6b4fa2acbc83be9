"""Identification methods compared on simulated arms with known truth (issue 29), in the spirit of
BIRDy's protocol (Leboutet, Roux, Janot, Guadarrama-Olvera & Cheng, "Inertial parameter
identification in robotics: a survey", Applied Sciences 11(9), 2021): each arm tracks a Fourier
reference under a controller that reads a noisy encoder (closed loop), or follows it exactly with
noisy torques (open loop); Monte Carlo repetitions over the noise seeds; for each method the
relative error of the base parameters ``|theta - theta*| / |theta*|`` and the held-out torque error
(RMS of the prediction error on another run over the RMS torque), median over the repetitions.

Arms (``--arms``):

- ``2r``: a vertical 2R with motors behind gears (armature, viscous and per-direction Coulomb
  friction), PD-controlled, prior masses 20 % off;
- ``puma560``: kinedyn's built-in PUMA 560 with Corke's motor and friction table, under computed
  torque with a prior model 15 % light;
- ``tx40``: a Staubli-like 6R, the TX40 of BIRDy's robot description (Leboutet et al. 2021,
  ``TX40.m``: modified DH geometry, masses, first moments and inertias about each DH frame, the
  armatures ``Ia``, gear ratios, viscous ``Fv`` and Coulomb ``Fc`` friction from Gautier, Janot &
  Vandanjon's identifications of the real TX40), without its joint 5-6 friction coupling (no kinedyn
  term for it); BIRDy's PD gains, a prior 15 % light;
- ``panda``: example-robot-data's Franka Panda URDF (7 DOF, fingers locked) with a drive train of
  our choosing (armature 0.1-0.3 kg m^2, viscous 0.5-1 N m s, Coulomb 0.6-1.2 N m per direction);
  computed torque with a prior 15 % light.

The truth's base parameters (links and every joint's armature) come from the true robot's
parameters through the same grouping. Every fit leaves out the rows where a joint moves slower than
``--min-speed`` (0.05 rad/s): where the arm sticks (the PUMA's 25 N m Coulomb level against the
controller's friction compensation) the friction is not ``Fc sign(qd)``, and those rows bias every
method (benches/NOTES.md).

    PYTHONPATH=python python benches/bench_identification.py            # --quick: a few minutes
    PYTHONPATH=python python benches/bench_identification.py --full     # the noise grid, 3 reps
    ... [--arms 2r puma560 tx40 panda] [--noise 5e-4 2e-3] [--reps 3] [--seconds 6]
        [--methods ols wls irls iv didim] [--data closed open] [--min-speed 0.05]

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


def lighter(true, controller_gains=(100.0, 20.0), amplitude=0.5, harmonics=4):
    """The prior (every body 15 % lighter: a scaled body stays physical), the reference and a computed
    torque controller on the prior model."""
    pi = true.inertial_parameters().reshape(true.n, 10) * 0.85
    prior = with_inertial_parameters(true, pi.reshape(-1))
    ref = an.excitation(true, harmonics=harmonics, period=6.0, amplitude=amplitude, seed=0)
    kp, kd = controller_gains
    controller = ComputedTorque(prior, np.full(true.n, kp), np.full(true.n, kd), ref, model=prior)
    return true, prior, ref, controller


# The TX40 of BIRDy's TX40.m (Leboutet, Roux, Janot, Guadarrama-Olvera & Cheng 2021): modified DH
# (alpha_{i-1}, a_{i-1}, theta offset, d_i); mass; first moment m c and inertia about the DH frame
# (XX, XY, XZ, YY, YZ, ZZ), both in link frame i; armature Ia; gear ratio; Fv; Fc.
TX40 = [
    (0.0, 0.0, 0.0, 0.0, 8.61, (0, 0, -0.05 * 8.61), (0.424, 0, 0, 0.424, 0, 0.352), 0.362, 32, 7.9379, 6.9822),
    (
        -np.pi / 2,
        0.0,
        -np.pi / 2,
        0.0,
        4.85,
        (0.392, -7.2e-3, 0.162),
        (1.63e-2, 7.85e-4, -1.57e-2, 8.81e-2, 3.24e-4, 8.28e-2),
        0.507,
        32,
        5.6948,
        7.8301,
    ),
    (
        0.0,
        0.225,
        np.pi / 2,
        0.035,
        4.07,
        (3.26e-2, 2.44e-2, 0.265),
        (2.23e-2, -1.95e-4, -1.16e-3, 2.24e-2, -2.22e-3, 4.41e-3),
        8.29e-2,
        45,
        1.9804,
        6.1939,
    ),
    (
        np.pi / 2,
        0.0,
        0.0,
        0.225,
        3.62,
        (1.45e-2, -7.24e-3, -0.586),
        (0.109, 2.9e-5, 1.35e-3, 0.108, -1.17e-3, 4.07e-3),
        3.41e-2,
        48,
        1.1141,
        2.4063,
    ),
    (
        -np.pi / 2,
        0.0,
        0.0,
        0.0,
        1.02,
        (0.0, -3.06e-3, -1.02e-3),
        (1.01e-3, 0, 0, 1.00e-3, -3.06e-6, 1.01e-3),
        3.61e-2,
        45,
        1.60,
        3.4092,
    ),
    (
        np.pi / 2,
        0.0,
        np.pi,
        0.0,
        0.2,
        (0.0, 0.0, 8.4e-3),
        (3.53e-3, 0, 0, 3.53e-3, 0, 3.53e-4),
        1.14e-2,
        32,
        0.6894,
        1.8313,
    ),
]


def tx40():
    rows = []
    for alpha, a, theta, d, m, mc, (xx, xy, xz, yy, yz, zz), ia, gear, fv, fc in TX40:
        inertia = kd.Inertia.from_parameters([m, *mc, xx, xy, yy, xz, yz, zz])
        rows.append(
            dict(
                alpha=alpha, a=a, theta=theta, d=d, inertia=inertia,
                gear_ratio=float(gear), rotor_inertia=ia / gear**2, viscous=fv, coulomb=fc,
            )
        )  # fmt: skip
    true = kd.Robot.from_dh(rows, convention="modified", name="tx40")
    true, prior, ref, _ = lighter(true)
    # BIRDy's TX40 PD gains (TX40.m, controlParameters.Kp and Kd): no gravity compensation, stiff
    # enough for the wrist's Coulomb levels (a computed torque at wn = 10 rad/s left joint 6 stuck)
    kp = 0.75 * np.array([455.8254, 500.0, 253.7919, 200.2182, 244.3226, 478.4783])
    kd_ = np.array([2.5361, 4.1174, 1.1793, 0.5462, 0.5714, 0.1954])
    return true, prior, ref, PD(np.diag(kp), np.diag(kd_), ref)


def panda():
    from kinedyn.testing import example_robot_data_dir  # only this arm needs example-robot-data

    root = example_robot_data_dir()
    if root is None:
        raise SystemExit("the panda arm needs example-robot-data (pip install 'kinedyn[peers]')")
    robot = kd.load(f"{root}/panda_description/urdf/panda.urdf")
    robot = robot.lock_joints([j for j in robot.joint_names if "finger" in j])
    armature = (0.3, 0.3, 0.25, 0.25, 0.15, 0.12, 0.1)
    links = []
    for link in robot.links:
        if link.joint.name in robot.joint_names:
            j = robot.joint_names.index(link.joint.name)
            joint = dataclasses.replace(
                link.joint,
                gear_ratio=100.0,
                rotor_inertia=armature[j] / 1e4,
                viscous=1.0 - 0.07 * j,
                coulomb=1.2 - 0.08 * j,
                coulomb_negative=1.0 - 0.06 * j,
            )
            link = dataclasses.replace(link, joint=joint)
        links.append(link)
    return lighter(robot.replace(links=links), amplitude=0.4)


ARMS = {"2r": two_r, "puma560": puma, "tx40": tx40, "panda": panda}


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


QUICK = dict(arms=list(ARMS), noise=[5e-4], reps=1, seconds=6.0)
FULL = dict(arms=list(ARMS), noise=[2e-4, 5e-4, 2e-3], reps=3, seconds=6.0)


def run_fit(prior, log, method, controller, options):
    """(the fit, seconds) or (None, the reason) for a fit that cannot be made."""
    t0 = time.perf_counter()
    try:
        r = an.identify(
            prior, log, method=method, controller=controller if method in ("iv", "didim") else None, **options
        )
    except ValueError as e:  # an estimate that cannot be simulated
        return None, str(e)
    return r, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    grid = ap.add_mutually_exclusive_group()
    grid.add_argument("--quick", action="store_true", help="the default: every arm, 0.5 mrad, 1 rep, 6 s")
    grid.add_argument("--full", action="store_true", help="every arm, 0.2, 0.5 and 2 mrad, 3 reps, 6 s")
    ap.add_argument("--arms", nargs="+", choices=list(ARMS))
    ap.add_argument("--noise", nargs="+", type=float, help="encoder noise, rad")
    ap.add_argument("--reps", type=int)
    ap.add_argument("--seconds", type=float)
    ap.add_argument("--cutoff", type=float, default=10.0)
    ap.add_argument("--min-speed", type=float, default=0.05, help="rows slower than this are left out (rad/s)")
    ap.add_argument("--data", nargs="+", default=["closed", "open"], choices=["closed", "open"])
    ap.add_argument("--methods", nargs="+", default=["ols", "wls", "irls", "iv", "didim"])
    args = ap.parse_args()
    preset = FULL if args.full else QUICK
    for key, value in preset.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    print(f"<!-- {vars(args)} -->")
    print(
        "| arm | data | encoder noise (rad) | method | parameter error (median) | held-out torque error (median) "
        "| fits | time / fit |"
    )
    print("|---|---|---|---|---|---|---|---|")
    options = dict(friction="viscous+asymmetric", armature=True, min_speed=args.min_speed)
    for arm in args.arms:
        true, prior, ref, controller = ARMS[arm]()
        base = base_parameters_with_rotors(true, tuple(range(true.n)))
        truth = dict(zip(base.names, base.values))
        for data in args.data:
            methods = [m for m in args.methods if data == "closed" or m not in ("iv", "didim")]
            for noise in args.noise:
                errors: dict = {m: [] for m in methods}
                held: dict = {m: [] for m in methods}
                times: dict = {m: [] for m in methods}
                for rep in range(args.reps):
                    if data == "closed":
                        fit = closed_loop(true, ref, controller, args.seconds, noise, seed=10 * rep + 1)
                        other = closed_loop(true, ref, controller, args.seconds, noise, seed=10 * rep + 2)
                    else:
                        fit = open_loop(true, ref, args.seconds, noise, seed=10 * rep + 1)
                        other = open_loop(true, ref, args.seconds, noise, seed=10 * rep + 2)
                    log = an.load_log(fit, n=true.n, cutoff=args.cutoff)
                    for m in methods:
                        r, seconds = run_fit(prior, log, m, controller, options)
                        if r is None:
                            print(f"<!-- {arm} {data} {noise} {m} rep {rep}: {seconds} -->")
                            continue
                        times[m].append(seconds)
                        names = [nm for nm in truth if nm in r.names]
                        est = np.array([r.estimates[list(r.names).index(nm)] for nm in names])
                        ref_values = np.array([truth[nm] for nm in names])
                        errors[m].append(np.linalg.norm(est - ref_values) / np.linalg.norm(ref_values))
                        check = r.validate(other, cutoff=args.cutoff)
                        held[m].append(
                            float(np.sqrt(np.mean(check.residuals**2)) / np.sqrt(np.mean(check.measured**2)))
                        )
                for m in methods:
                    if not errors[m]:
                        print(f"| {arm} | {data}-loop | {noise:g} | {m} | failed | | 0/{args.reps} | |", flush=True)
                        continue
                    print(
                        f"| {arm} | {data}-loop | {noise:g} | {m} | {100 * np.median(errors[m]):.2f} % | "
                        f"{100 * np.median(held[m]):.2f} % | {len(errors[m])}/{args.reps} | {np.median(times[m]):.2f} s |",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
