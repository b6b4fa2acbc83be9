"""Write a floating-base robot's compiled tree and one state to a plain text file, for the C++
(Pinocchio) and Rust (kinedyn-core) sides of compare_core.sh, which build their models from it
without a URDF parser.

    PYTHONPATH=python python benches/cpp/dump_tree.py OUT_DIR [ROBOT ...]   (default: talos solo12 anymal)

A name ending in ``_fixed`` (``talos_fixed``) is the same URDF with its root link fixed to the world
(no free-flyer): beside the floating robot it shows what the free-flyer itself costs on each side.
``ur5``, ``panda`` and ``iiwa`` are the fixed-base arms of ``common.ARMS`` (the URDFs, not the DH
models of the `quick` bench; the Panda's fingers locked): compare_codegen.sh's robots.

Bodies in kinedyn's order (``robot.tree.bodies``: fixed joints merged, parents before children).
Format, one record a line, numbers in full precision (``%.17g``):

    robot NAME
    sizes NQ NV NBODIES
    gravity GX GY GZ
    body PARENT KIND AX AY AZ  R00 R01 R02 R10 R11 R12 R20 R21 R22  TX TY TZ  MASS CX CY CZ  I00 I01 I02 I10 I11 I12 I20 I21 I22
    ...
    q ... (NQ)   v ... (NV)   a ... (NV)
    expect_rnea ... (NV)

PARENT: the parent body's index (-1: the base); KIND: free (Pinocchio's free-flyer, q block
(x, y, z, qx, qy, qz, qw)), spherical (a ball joint, q block (qx, qy, qz, qw); its axis a placeholder),
revolute or prismatic with its unit axis; R, T: the joint frame's placement
in the parent body (q = 0); MASS, C, I: the body's mass, centre of mass and rotational inertia about the
centre of mass, in the body frame. ``expect_rnea``: kinedyn's Python ``inverse_dynamics`` of the robot
(friction removed, as both harnesses leave it out) at this state: the three sides must agree.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import ARMS, FLOATING_URDFS, erd_robots_dir, load_arm, random_state, without_friction  # noqa: E402

KINDS = {"floating": "free", "spherical": "spherical", "revolute": "revolute", "prismatic": "prismatic"}


def fmt(values) -> str:
    return " ".join(f"{float(x):.17g}" for x in np.ravel(values))


def dump(name: str, path: Path, seed: int = 14) -> None:
    import kinedyn as kd

    urdf = name.removesuffix("_fixed")
    if name in ARMS:
        robot = without_friction(load_arm(name))
    else:  # every joint its own coordinate, as Pinocchio builds the file (mimic="independent")
        robot = without_friction(
            kd.Robot.from_urdf(
                str(erd_robots_dir() / FLOATING_URDFS[urdf]), floating_base=urdf == name, mimic="independent"
            )
        )
    q, v, a = random_state(robot, np.random.default_rng(seed))
    path.write_text("\n".join(tree_lines(name, robot, q, v, a)) + "\n")


def tree_lines(name: str, robot, q, v, a) -> list[str]:
    """The file's lines for ``robot`` (friction already removed) at the state ``(q, v, a)``."""
    if np.any(np.asarray(robot.armature) != 0):
        raise SystemExit(f"{name}: the harnesses leave rotor inertia (armature) out; this robot has some")
    bodies = robot.tree.bodies
    lines = [f"robot {name}", f"sizes {robot.nq} {robot.nv} {len(bodies)}", f"gravity {fmt(robot.gravity)}"]
    for body in bodies:
        j = body.joint
        if j.kind not in KINDS:
            raise SystemExit(
                f"{name}: joint '{j.name}' of kind {j.kind}: the harnesses build free, spherical, revolute and "
                "prismatic joints only"
            )
        T = np.asarray(body.placement, dtype=float)
        inertia = body.inertia
        lines.append(
            " ".join(
                [
                    "body",
                    str(body.parent),
                    KINDS[j.kind],
                    fmt(j.axis if j.axis is not None else (0.0, 0.0, 1.0)),  # none for a free or ball joint
                    fmt(T[:3, :3]),
                    fmt(T[:3, 3]),
                    fmt([inertia.mass]),
                    fmt(np.asarray(inertia.com, dtype=float)),
                    fmt(np.asarray(inertia.inertia, dtype=float)),
                ]
            )
        )
    return lines + [f"q {fmt(q)}", f"v {fmt(v)}", f"a {fmt(a)}", f"expect_rnea {fmt(robot.inverse_dynamics(q, v, a))}"]


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for robot_name in sys.argv[2:] or list(FLOATING_URDFS):
        dump(robot_name, out / f"{robot_name}.tree")
        print(out / f"{robot_name}.tree")
