"""Simulation throughput: simulated seconds per wall-clock second, RK4 at 1 kHz, free motion.

Rows, per robot (PUMA 560 from kinedyn's catalogue, Panda from example-robot-data's URDF):
- kinedyn, one trajectory and a batch of 1,000 initial states (the whole run is one native call);
- the same RK4 written in Python driving ``pinocchio.aba`` (one call per stage), one trajectory and
  the batch state by state (the PUMA is rebuilt in Pinocchio from kinedyn's compiled tree);
- MuJoCo (``mujoco`` on PyPI) with its RK4 integrator on the same URDF (visuals and collisions
  stripped, contacts disabled), one trajectory with ``mj_step`` and the batch with
  ``mujoco.rollout`` (the PUMA has no URDF: not loaded).
Never run in CI. Ratios are taken in one run; see docs/simulation.md for recorded figures.

    PYTHONPATH=python python benches/bench_simulate.py [--batch 1000]
"""

from __future__ import annotations

import argparse
import os
import re
import time

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np  # noqa: E402
from common import PEER_URDFS, erd_robots_dir, load_pair  # noqa: E402

import kinedyn as kd  # noqa: E402

DT = 1e-3


def pin_from_kinedyn(robot):
    """A Pinocchio model with kinedyn's compiled bodies (placements, axes, inertias, armature)."""
    import pinocchio as pin

    model = pin.Model()
    model.gravity.linear = np.array(robot.gravity, dtype=float)
    ids = [0]
    for _k, b in enumerate(robot.tree.bodies):
        T = np.asarray(b.placement, dtype=float)
        j = b.joint
        if float(j.offset) != 0.0:
            raise ValueError("joint offsets are not mapped in this helper")
        axis = np.asarray(j.axis, dtype=float)
        jm = pin.JointModelRevoluteUnaligned(axis) if j.kind == "revolute" else pin.JointModelPrismaticUnaligned(axis)
        parent = ids[b.parent + 1] if b.parent >= 0 else 0
        jid = model.addJoint(parent, jm, pin.SE3(T[:3, :3], T[:3, 3]), j.name)
        inertia = b.inertia
        model.appendBodyToJoint(
            jid,
            pin.Inertia(
                float(inertia.mass), np.array(inertia.com, dtype=float), np.array(inertia.inertia, dtype=float)
            ),
            pin.SE3.Identity(),
        )
        ids.append(jid)
    model.armature = np.array([float(j.armature) for j in robot.joints])
    return model


def rk4_pinocchio(model, data, q, v, steps, dt=DT):
    import pinocchio as pin

    # pinocchio.aba ignores model.damping; kinedyn applies the URDF's joint damping as viscous friction
    b = np.asarray(model.damping)
    for _ in range(steps):
        a1 = pin.aba(model, data, q, v, -b * v)
        q2, v2 = q + 0.5 * dt * v, v + 0.5 * dt * a1
        a2 = pin.aba(model, data, q2, v2, -b * v2)
        q3, v3 = q + 0.5 * dt * v2, v + 0.5 * dt * a2
        a3 = pin.aba(model, data, q3, v3, -b * v3)
        q4, v4 = q + dt * v3, v + dt * a3
        a4 = pin.aba(model, data, q4, v4, -b * v4)
        q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    return q, v


def mujoco_model(name):
    """The example-robot-data URDF in MuJoCo, without meshes, RK4 at 1 kHz, contacts off."""
    import mujoco

    text = (erd_robots_dir() / PEER_URDFS[name]).read_text()
    text = re.sub(r"<visual>.*?</visual>|<collision>.*?</collision>", "", text, flags=re.S)
    text = (
        text.replace("<robot ", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" ', 1)
        if "xmlns:xacro" not in text
        else text
    )
    m = mujoco.MjModel.from_xml_string(text)
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    return m


def timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--batch", type=int, default=1000)
    ap.add_argument("--seconds", type=float, default=2.0, help="simulated seconds of a single kinedyn run")
    args = ap.parse_args()

    rows = []
    for name in ("puma560", "panda"):
        if name == "puma560":
            robot = kd.robots.puma560(friction=False)
            pmodel = pin_from_kinedyn(robot)
        else:
            robot, pmodel = load_pair("panda")
        n = robot.n
        rng = np.random.default_rng(0)
        X = np.column_stack(
            [robot.random_configuration(rng, size=args.batch) * 0.5, rng.normal(size=(args.batch, n)) * 0.5]
        )
        # agreement check: kinedyn RK4 == Pinocchio-driven RK4 on the same model after 0.1 s
        traj = kd.simulate(robot, 0.1, X[0], dt=DT)
        qp, vp = rk4_pinocchio(pmodel, pmodel.createData(), X[0, :n].copy(), X[0, n:].copy(), 100)
        agree = float(np.abs(traj.q[-1] - qp).max())

        T1 = args.seconds
        kd_single = T1 / timed(lambda: kd.simulate(robot, T1, X[0], dt=DT, record_every=100, progress=False))
        Tb = 0.2
        kd_batch = args.batch * Tb / timed(lambda: kd.simulate(robot, Tb, X, dt=DT, record_every=100, progress=False))
        pdata = pmodel.createData()
        pin_single = 0.5 / timed(lambda: rk4_pinocchio(pmodel, pdata, X[0, :n].copy(), X[0, n:].copy(), 500))
        nb = min(args.batch, 200)  # Pinocchio batch: states one after the other (rate per state is what counts)
        Tp = 0.05
        pin_batch = (
            nb
            * Tp
            / timed(
                lambda: [
                    rk4_pinocchio(pmodel, pdata, X[i, :n].copy(), X[i, n:].copy(), int(Tp / DT)) for i in range(nb)
                ]
            )
        )
        mj_single = mj_batch = None
        mj_note = "no URDF for the PUMA 560"
        if name in PEER_URDFS:
            try:
                import mujoco
                from mujoco import rollout

                m = mujoco_model(name)
                d = mujoco.MjData(m)
                mj_note = f"nq={m.nq}"
                if m.nq != n:
                    # Panda's fingers: keep them at 0 (they are free in MuJoCo's copy of the URDF)
                    mj_note += " (fingers free)"

                def mj_run():
                    mujoco.mj_resetData(m, d)
                    d.qpos[:n] = X[0, :n]
                    d.qvel[:n] = X[0, n:]
                    for _ in range(int(T1 / DT)):
                        mujoco.mj_step(m, d)

                mj_single = T1 / timed(mj_run)
                spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
                size = mujoco.mj_stateSize(m, spec)
                init = np.zeros((args.batch, size))
                for i in range(args.batch):
                    mujoco.mj_resetData(m, d)
                    d.qpos[:n] = X[i, :n]
                    d.qvel[:n] = X[i, n:]
                    mujoco.mj_getState(m, d, init[i], spec)
                nstep = int(Tb / DT)
                datas = [mujoco.MjData(m) for _ in range(os.cpu_count() or 1)]
                mj_batch = (
                    args.batch
                    * Tb
                    / timed(lambda: rollout.rollout(m, datas, init, np.zeros((args.batch, nstep, m.nu))))
                )
            except Exception as e:  # noqa: BLE001 - report and go on
                mj_note = f"not loaded: {type(e).__name__}: {e}"[:120]
        rows.append((name, n, agree, kd_single, kd_batch, pin_single, pin_batch, mj_single, mj_batch, mj_note))

    print(
        f"RK4 at {1 / DT:g} Hz, free motion; simulated seconds per wall second (higher is better); batch = {args.batch} initial states"
    )
    print(f"{'robot':<9} {'':<22} {'single':>10} {'batch':>10}")
    for name, _n, agree, ks, kb, ps, pb, ms, mb, note in rows:
        print(f"{name:<9} {'kinedyn (Rust core)':<22} {ks:10.1f} {kb:10.1f}")
        print(f"{'':<9} {'pinocchio.aba from Py':<22} {ps:10.1f} {pb:10.1f}")
        print(
            f"{'':<9} {'mujoco RK4':<22} {ms if ms else float('nan'):10.1f} {mb if mb else float('nan'):10.1f}   {note}"
        )
        print(
            f"{'':<9} ratios kinedyn / pinocchio-from-Python: single {ks / ps:.1f}x, batch {kb / pb:.1f}x"
            + (f"; kinedyn / mujoco: single {ks / ms:.2f}x, batch {kb / mb:.2f}x" if ms and mb else "")
        )
        print(f"{'':<9} kinedyn RK4 vs pinocchio-driven RK4 after 0.1 s: max |dq| = {agree:.2e}")


if __name__ == "__main__":
    main()
