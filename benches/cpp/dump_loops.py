"""Write a closed mechanism of examples/robots (issue 27) for compare_loops.sh: its compiled tree in
dump_tree.py's format, then its loops and closed states, so that Pinocchio's C++
(`pinocchio_loops.cpp`) and the Rust core (`crates/kinedyn-core/benches/loops.rs`) build the same
model and compute on the same states.

    PYTHONPATH=python python benches/cpp/dump_loops.py OUT_DIR [NAME ...] [--states 64]
    (default: four_bar five_bar delta pushrod_leg)

After dump_tree.py's lines (its state: the first closed one, a = 0):

    loop KIND  BODY_A R00..R22 TX TY TZ  BODY_B R00..R22 TX TY TZ     (one per loop; KIND point|weld;
                                  BODY -1: the base; R, T: the frame's placement in the body)
    states K
    state q... v... tau... qdd...                                     (K lines: NQ + 3 NV numbers)

The states: kinedyn's generic closed configuration (``default_configuration``) with its scalar
coordinates moved by up to +-0.3 and projected back onto the loops (``project_configuration``),
kept when the loop Jacobian has the rank of the first one (no singular configuration); velocities
projected onto the loops' tangent space (``project_velocity``), torques uniform in [-1, 1];
``qdd`` is kinedyn's Python ``constrained_forward_dynamics`` (the third side of the check).
Friction is removed (Pinocchio leaves it out).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import without_friction  # noqa: E402
from dump_tree import fmt, tree_lines  # noqa: E402

EXAMPLES = {
    "four_bar": "four_bar.yaml",
    "five_bar": "five_bar.yaml",
    "delta": "delta.xml",
    "pushrod_leg": "pushrod_leg.urdf",
}
ROOT = Path(__file__).resolve().parents[2]


def closed_states(robot, count: int, rng) -> list[tuple]:
    from kinedyn.configuration import default_configuration

    q0 = default_configuration(robot)
    rank = np.linalg.matrix_rank(robot.loop_jacobian(q0), tol=1e-9)
    scalar = np.zeros(robot.nq, dtype=bool)  # the scalar coordinates (multi-DOF blocks kept)
    at = 0
    for j in robot.joints:
        scalar[at] = not j.is_multi_dof
        at += j.nq
    states, tries = [], 0
    while len(states) < count:
        tries += 1
        if tries > 50 * count:
            raise SystemExit(f"{robot.name}: only {len(states)} regular closed states in {tries} tries")
        start = q0 + np.where(scalar, rng.uniform(-0.3, 0.3, robot.nq), 0.0) if states else q0
        try:
            q = np.asarray(robot.project_configuration(start), dtype=float)
        except ValueError:
            continue
        if np.linalg.matrix_rank(robot.loop_jacobian(q), tol=1e-9) != rank:
            continue
        qd = np.asarray(robot.project_velocity(q, rng.uniform(-1, 1, robot.nv)), dtype=float)
        tau = rng.uniform(-1, 1, robot.nv)
        qdd = np.asarray(robot.constrained_forward_dynamics(q, qd, tau)[0], dtype=float)
        states.append((q, qd, tau, qdd))
    return states


def dump(name: str, path: Path, count: int, seed: int = 27) -> None:
    import kinedyn as kd

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # delta.xml: MuJoCo's soft-constraint settings, not modelled
        robot = without_friction(kd.load(str(ROOT / "examples" / "robots" / EXAMPLES[name])))
    states = closed_states(robot, count, np.random.default_rng(seed))
    q, qd, _, _ = states[0]
    lines = tree_lines(name, robot, q, qd, np.zeros(robot.nv))
    frames = robot.tree.frames
    for loop in robot.loops:
        words = ["loop", loop.kind]
        for frame_name in (loop.frame_a, loop.frame_b):
            frame = frames[robot.tree.frame_index(frame_name)]
            T = np.asarray(frame.placement, dtype=float)
            words += [str(frame.body), fmt(T[:3, :3]), fmt(T[:3, 3])]
        lines.append(" ".join(words))
    lines.append(f"states {len(states)}")
    lines += [f"state {fmt(np.concatenate(s))}" for s in states]
    path.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    args = sys.argv[1:]
    count = 64
    if "--states" in args:
        k = args.index("--states")
        count = int(args[k + 1])
        del args[k : k + 2]
    out = Path(args[0])
    out.mkdir(parents=True, exist_ok=True)
    for robot_name in args[1:] or list(EXAMPLES):
        dump(robot_name, out / f"{robot_name}.loops", count)
        print(out / f"{robot_name}.loops")
