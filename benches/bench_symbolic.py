"""Symbolic derivation benchmark (issue 4; not a timed test).

Time to derive and simplify the equations of motion of the planar 2R and 3R arms, the elbow arm and
the PUMA 560 with kinedyn (Lagrange with steps, and the customised Newton-Euler model), beside
sympy.physics.mechanics LagrangesMethod and KanesMethod on the same mechanisms built from the same
description, in the same run; operation counts before and after common-subexpression elimination.

    PYTHONPATH=python python benches/bench_symbolic.py [--puma-lagranges] [--repeat N]
    PYTHONPATH=python python benches/bench_symbolic.py --cse-only [--expanded]   # issue 12 §5 cases alone
    PYTHONPATH=python python benches/bench_symbolic.py --derive-only   # issue 23: documents a person reads

Issue 23 cases (section "derive for a reader"): `kinedyn derive puma560 --format latex` (numeric
parameters, the default) beside the same with `--general`, in the same run: time and size ratios
(target: at most 2 each); `derive ur5` and example-robot-data's `ur5_robot.urdf` (near-right angles
snapped) likewise.

Issue 12 §5 cases (section "CSE form"): `kinedyn derive puma560 --general --method newton_euler` in
every --format and `derive ur5 --general`, CLI wall time in a child process; M, C, g in CSE form
(kinedyn.symbolic.cse) of the PUMA 560 and the Panda (7 joints, example-robot-data's URDF) beside
KanesMethod forming the same arm's equations (its mass matrix and forcing), ratios printed.

LagrangesMethod on the PUMA 560 takes minutes: it runs only with --puma-lagranges, once, in a
subprocess capped at 400 s.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
import warnings

import numpy as np
import sympy as sp

import kinedyn as kd
from kinedyn.description.dh import DHRow
from kinedyn.description.inertia import Inertia
from kinedyn.symbolic.robot_eom import general_parameters, newton_euler_eom
from kinedyn.symbolic.steps import op_counts as _ops
from kinedyn.symbolic.values import exact as _exact
from kinedyn.symbolic.values import matrix as _matrix

warnings.filterwarnings("ignore")


def elbow_symbolic():
    try:
        return kd.robots.elbow_3r(symbolic=True)
    except Exception:  # the description cannot yet build it with an exact pi/2 twist
        L1, L2, L3, m1, m2, m3, g = sp.symbols("L1 L2 L3 m1 m2 m3 g", positive=True)
        rod = lambda m, L: Inertia(m, (L / 2 - L, 0, 0), ((0, 0, 0), (0, m * L**2 / 12, 0), (0, 0, m * L**2 / 12)))
        link1 = Inertia(m1, (0, -L1 / 2, 0), ((m1 * L1**2 / 12, 0, 0), (0, 0, 0), (0, 0, m1 * L1**2 / 12)))
        rows = [
            DHRow(d=L1, alpha=math.pi / 2, inertia=link1),
            DHRow(a=L2, inertia=rod(m2, L2)),
            DHRow(a=L3, inertia=rod(m3, L3)),
        ]
        return kd.Robot.from_dh(rows, gravity=(0, 0, -g), name="elbow_3r")


def mechanics_model(robot):
    """The robot as sympy.physics.mechanics bodies (same placements, axes, inertias, gravity)."""
    from sympy.physics.mechanics import Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

    n = robot.n
    q = dynamicsymbols(f"q1:{n + 1}")
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    frames, origins, bodies, loads = [], [], [], []
    gN = _exact(robot.gravity[0]) * N.x + _exact(robot.gravity[1]) * N.y + _exact(robot.gravity[2]) * N.z
    for i, b in enumerate(robot.tree.bodies):
        pf, po = (N, O) if b.parent < 0 else (frames[b.parent], origins[b.parent])
        T = _matrix(b.placement)
        R = sp.Matrix([row[:3] for row in T[:3]])
        p = [row[3] for row in T[:3]]
        F = ReferenceFrame(f"P{i + 1}")
        F.orient_explicit(pf, R)
        a = [_exact(x) for x in b.joint.axis]
        avec = a[0] * F.x + a[1] * F.y + a[2] * F.z
        jo = po.locatenew(f"J{i + 1}", p[0] * pf.x + p[1] * pf.y + p[2] * pf.z)
        off = _exact(b.joint.offset)
        if b.joint.kind == "revolute":
            B = ReferenceFrame(f"B{i + 1}")
            B.orient_axis(F, avec, q[i] + off)
            bo = jo
        else:
            B = F
            bo = jo.locatenew(f"O{i + 1}", (q[i] + off) * avec)
        inert = b.inertia
        c = [_exact(x) for x in inert.com]
        com = bo.locatenew(f"C{i + 1}", c[0] * B.x + c[1] * B.y + c[2] * B.z)
        com.set_vel(N, com.pos_from(O).dt(N))
        I = [[_exact(x) for x in row] for row in inert.inertia]
        m = _exact(inert.mass)
        body = RigidBody(
            f"b{i + 1}", com, B, m, (inertia(B, I[0][0], I[1][1], I[2][2], I[0][1], I[1][2], I[0][2]), com)
        )
        body.potential_energy = -m * gN.dot(com.pos_from(O))
        frames.append(B)
        origins.append(bo)
        bodies.append(body)
        loads.append((com, m * gN))
    return N, q, bodies, loads


def lagranges(robot):
    from sympy.physics.mechanics import LagrangesMethod, Lagrangian

    N, q, bodies, _ = mechanics_model(robot)
    t = time.perf_counter()
    LM = LagrangesMethod(Lagrangian(N, *bodies), q)
    eqs = LM.form_lagranges_equations()
    return time.perf_counter() - t, list(eqs)


def kanes(robot):
    from sympy.physics.mechanics import KanesMethod, dynamicsymbols

    N, q, bodies, loads = mechanics_model(robot)
    u = dynamicsymbols(f"u1:{robot.n + 1}")
    t = time.perf_counter()
    KM = KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=[qi.diff() - ui for qi, ui in zip(q, u)])
    fr, frstar = KM.kanes_equations(bodies, loads)
    return time.perf_counter() - t, list(fr + frstar)


def counts(exprs):
    before = _ops(exprs)["total"]
    repl, red = sp.cse(exprs, order="none")
    after = _ops([e for _, e in repl] + list(red))["total"]
    return before, after


def ours(robot, method):
    t = time.perf_counter()
    eom = robot.equations_of_motion(method=method, steps=False)
    if method == "lagrange":
        exprs = list(eom.tau)  # forms and simplifies M, C, g and tau
    else:
        exprs = [e for _, e in eom.program.assignments] + list(eom.program.outputs["tau"])
    return time.perf_counter() - t, exprs, eom


def row(name, what, seconds, exprs):
    b, a = counts(exprs)
    print(f"{name:10s} {what:34s} {seconds:9.3f} s   ops {b:8d}   after cse {a:7d}", flush=True)


def panda_robot():
    import os

    from kinedyn.testing import example_robot_data_dir

    path = os.path.join(example_robot_data_dir(), "panda_description/urdf/panda.urdf")
    return kd.Robot.from_urdf(path).lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})


def closed_form_time(robot, parameters=None):
    """Seconds to M, C, g in CSE form (from the robot, Newton-Euler program included), and op counts."""
    from kinedyn.symbolic.cse import closed_form
    from kinedyn.symbolic.lagrange import state_symbols

    q, qd, qdd = state_symbols(robot)
    t = time.perf_counter()
    cf = closed_form(robot, q, qd, qdd, parameters=parameters)
    sec = time.perf_counter() - t
    return sec, sum(cf[k].op_count()["total"] for k in ("M", "C", "g"))


def kanes_child(which):
    robot = panda_robot() if which == "panda" else kd.robots.puma560()
    sec, eqs = kanes(robot)
    print(f"{sec:.3f}")


class _Seconds(float):
    """Wall seconds of a child command, with its CPU seconds (user + system) as ``.cpu``: on a shared
    machine the CPU time is what the command itself cost, the wall time adds the wait for a core."""

    cpu = 0.0


def fmt(sec) -> str:
    return f"{float(sec):8.2f} s wall {getattr(sec, 'cpu', float('nan')):6.2f} s CPU"


def cli_seconds(args, timeout=600):
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "kinedyn", *args], capture_output=True, text=True, timeout=timeout)
    sec = _Seconds(time.perf_counter() - t)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    sec.cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-400:])
    return sec


def cse_section(expanded=False):
    print("\n== CSE form (issue 12 §5); the machine may be shared: compare the ratios, not the seconds ==", flush=True)
    base = cli_seconds(["--version"])
    print(f"{'kinedyn --version (start-up only)':58s} {fmt(base)}", flush=True)
    for output in ("text", "latex", "markdown", "mathml", "python", "numpy", "c"):
        sec = cli_seconds(
            ["derive", "puma560", "--general", "--method", "newton_euler", "--format", output, "-o", "/dev/null"]
        )
        print(f"{'derive puma560 --general --method newton_euler --format ' + output:58s} {fmt(sec)}", flush=True)
    sec = cli_seconds(["derive", "puma560", "--general", "--method", "newton_euler", "--json"])
    print(f"{'derive puma560 --general --method newton_euler --json':58s} {fmt(sec)}", flush=True)
    sec = cli_seconds(["derive", "ur5", "--general", "-o", "/dev/null"])
    print(f"{'derive ur5 --general (lagrange)':58s} {fmt(sec)}", flush=True)
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        sec = cli_seconds(["report", "puma560", "--eom-joints", "6", "-o", f"{tmp}/puma.html"])
    print(f"{'report puma560 --eom-joints 6':58s} {fmt(sec)}", flush=True)
    if expanded:  # the former path: every entry expanded and printed (minutes)
        try:
            sec = cli_seconds(
                ["derive", "puma560", "--general", "--method", "newton_euler", "--form", "expanded", "-o", "/dev/null"],
                timeout=900,
            )
            print(f"{'  same, --form expanded (the former output)':58s} {fmt(sec)}", flush=True)
        except subprocess.TimeoutExpired:
            print(f"{'  same, --form expanded (the former output)':58s} > 900 s (stopped)", flush=True)
    for name, robot in (("puma560", kd.robots.puma560()), ("panda", panda_robot())):
        ours_sec, ops = closed_form_time(robot)
        try:
            out = subprocess.run(
                [sys.executable, __file__, "--child", f"kanes-{name}"], capture_output=True, text=True, timeout=400
            )
            kane = float(out.stdout.split()[-1])
            peer = f"KanesMethod {kane:8.2f} s   ratio Kane/kinedyn {kane / ours_sec:6.1f}"
        except subprocess.TimeoutExpired:
            peer = "KanesMethod > 400 s (stopped)"
        print(f"{name:8s} M, C, g in CSE form {ours_sec:8.2f} s ({ops} ops)   {peer}", flush=True)
    sec, ops = closed_form_time(kd.robots.puma560(), general_parameters(kd.robots.puma560()))
    print(f"{'puma560 general inertias: M, C, g in CSE form':58s} {sec:8.2f} s ({ops} ops)", flush=True)


def derive_section():
    """Issue 23: the default derive documents against the --general one, wall time and bytes."""
    import os
    import tempfile

    from kinedyn.testing import example_robot_data_dir

    print("\n== derive for a reader (issue 23); compare the ratios, not the seconds ==", flush=True)
    root = example_robot_data_dir()
    cases = [["puma560"], ["puma560", "--general"], ["ur5"]]
    if root is not None:
        cases.append([os.path.join(root, "ur_description", "urdf", "ur5_robot.urdf")])
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k, case in enumerate(cases):
            out = f"{tmp}/{k}.tex"
            sec = cli_seconds(["derive", *case, "--format", "latex", "-o", out])
            results[" ".join(case)] = (float(sec), os.path.getsize(out))
            label = "derive " + " ".join(os.path.basename(c) for c in case) + " --format latex"
            print(f"{label:58s} {fmt(sec)} {os.path.getsize(out) / 1000:8.1f} kB", flush=True)
    (t_n, b_n), (t_g, b_g) = results["puma560"], results["puma560 --general"]
    print(f"{'puma560 numeric / --general':58s} time {t_n / t_g:5.2f}  size {b_n / b_g:5.2f}  (targets <= 2)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--puma-lagranges", action="store_true", help="also run LagrangesMethod on the PUMA 560 (minutes; once, capped)"
    )
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument(
        "--cse-only", action="store_true", help="only the issue 12 §5 cases (CSE form, CLI wall times, Panda)"
    )
    ap.add_argument("--derive-only", action="store_true", help="only the issue 23 cases (derive documents)")
    ap.add_argument(
        "--expanded",
        action="store_true",
        help="also time derive PUMA --general --form expanded (the former output; minutes)",
    )
    args = ap.parse_args(argv)
    if args.child and args.child.startswith("kanes-"):
        kanes_child(args.child[len("kanes-") :])
        return
    if args.cse_only:
        cse_section(args.expanded)
        return
    if args.derive_only:
        derive_section()
        return
    if args.child == "puma-lagranges":
        sec, eqs = lagranges(kd.robots.puma560())
        print(f"{sec:.3f} {_ops(eqs)['total']}")
        return
    arms = [
        ("planar_2r", kd.robots.planar_2r(symbolic=True)),
        ("planar_3r", kd.robots.planar_3r(symbolic=True)),
        ("elbow_3r", elbow_symbolic()),
    ]
    print(f"{'robot':10s} {'method':34s} {'time':>11s}")
    for name, robot in arms:
        sec, exprs, _ = ours(robot, "lagrange")
        row(name, "kinedyn lagrange (simplified tau)", sec, exprs)
        sec, exprs, _ = ours(robot, "newton_euler")
        row(name, "kinedyn newton_euler (program)", sec, exprs)
        sec, eqs = lagranges(robot)
        row(name, "sympy LagrangesMethod", sec, eqs)
        sec, eqs = kanes(robot)
        row(name, "sympy KanesMethod", sec, eqs)
    puma = kd.robots.puma560()
    sec, exprs, eom = ours(puma, "lagrange")
    row("puma560", "kinedyn lagrange (simplified tau)", sec, exprs)
    t = time.perf_counter()
    eom.M, eom.g  # noqa: B018 (computed on first access: the time printed below)
    print(
        f"{'puma560':10s} {'  of which M and g closed form':34s} (M, g ready {time.perf_counter() - t:.3f} s after tau)"
    )
    sec, exprs, ne = ours(puma, "newton_euler")
    row("puma560", "kinedyn newton_euler (numbers)", sec, exprs)
    print(f"{'':10s} {'  ops of the customised model':34s} {ne.op_count()}")
    t = time.perf_counter()
    neg = newton_euler_eom(puma, parameters=general_parameters(puma))
    sec = time.perf_counter() - t
    exprs = [e for _, e in neg.program.assignments] + list(neg.program.outputs["tau"])
    row("puma560", "kinedyn newton_euler (general I)", sec, exprs)
    print(f"{'':10s} {'  ops of the customised model':34s} {neg.op_count()}")
    sec, eqs = kanes(puma)
    row("puma560", "sympy KanesMethod", sec, eqs)
    if args.puma_lagranges:
        try:
            out = subprocess.run(
                [sys.executable, __file__, "--child", "puma-lagranges"], capture_output=True, text=True, timeout=400
            )
            sec, ops = out.stdout.split()
            print(f"{'puma560':10s} {'sympy LagrangesMethod':34s} {float(sec):9.3f} s   ops {int(ops):8d}")
        except subprocess.TimeoutExpired:
            print(f"{'puma560':10s} {'sympy LagrangesMethod':34s} > 400 s (stopped)")
    else:
        print(f"{'puma560':10s} {'sympy LagrangesMethod':34s} skipped (about 190 s here; --puma-lagranges)")
    # generated C for the PUMA's inverse dynamics vs the numeric engine's Newton-Euler
    f = ne.compile(what=("tau",), backend="c")
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.normal(size=(3, 6))
    reps = 20000
    t = time.perf_counter()
    for _ in range(reps):
        f.tau(q, qd, qdd)
    c_single = (time.perf_counter() - t) / reps * 1e6
    Q, QD, QDD = rng.normal(size=(3, 10000, 6))
    t = time.perf_counter()
    f.tau(Q, QD, QDD)
    c_batch = (time.perf_counter() - t) / 10000 * 1e6
    print(
        f"generated C (PUMA tau): {c_single:.2f} us per call from Python, {c_batch:.3f} us per state in a batch of 10000 ({f.backend})"
    )
    try:
        puma.inverse_dynamics(q, qd, qdd)
        t = time.perf_counter()
        for _ in range(reps):
            puma.inverse_dynamics(q, qd, qdd)
        n_single = (time.perf_counter() - t) / reps * 1e6
        t = time.perf_counter()
        puma.inverse_dynamics(Q, QD, QDD)
        n_batch = (time.perf_counter() - t) / 10000 * 1e6
        print(
            f"numeric engine RNEA  : {n_single:.2f} us per call from Python, {n_batch:.3f} us per state in a batch of 10000"
        )
        print(f"ratio numeric/generated: single {n_single / c_single:.2f}, batch {n_batch / c_batch:.2f}")
    except Exception as exc:  # the native module may not be built
        print(f"numeric engine unavailable: {exc}")
    cse_section(args.expanded)


if __name__ == "__main__":
    main()
