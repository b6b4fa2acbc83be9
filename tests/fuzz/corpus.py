"""The real texts the fuzzer mutates: URDFs of example-robot-data (when installed) and of examples/,
the project's YAML/TOML robot files, and files written by ``kd.save`` of the built-in robots and of
loaded URDFs (the tree flavour). Seeds are read once per process and cached; the order is fixed so
that a seed index means the same file on every run."""

from __future__ import annotations

import functools
import os
import tempfile
from dataclasses import dataclass

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# small, varied URDFs of example-robot-data (fast to load, so many mutations per second):
# serial arms, a gripper, trees (legged robots, a hand), floating bases, continuous and prismatic joints
ERD_URDFS = (
    "ur_description/urdf/ur5_robot.urdf",
    "panda_description/urdf/panda.urdf",
    "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
    "asr_twodof_description/urdf/TwoDofs.urdf",
    "z1_description/urdf/z1.urdf",
    "solo_description/robots/solo.urdf",
    "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "so_arm_description/urdf/so100.urdf",
)


# hand-written files that use every optional field of docs/model-files.md (the saved built-ins
# leave out offset, coulomb, base_pose, frames, post ...), so that mutations reach those readers too
FULL_DH_YAML = """\
# every field of the DH flavour
name: full_dh
convention: standard
gravity: [0, -9.81, 0]
units: {angle: deg}
source: docs/model-files.md, DH flavour
base_pose: {xyz: [0, 0, 0.5], rpy: [0, 0, 90]}
tool: {xyz: [0.1, 0, 0], rpy: [0, 90, 0]}
joints:
  - {name: shoulder, theta: 10, d: 0.1, a: 1.0, alpha: 90, type: revolute,
     limits: {lower: -170, upper: 170, velocity: 180, effort: 40},
     mass: 1.0, com: [-0.5, 0, 0], inertia: {ixx: 0.001, ixy: 0.0001, ixz: 0.0, iyy: 0.0833, iyz: 0.0, izz: 0.0833},
     gear_ratio: 50, rotor_inertia: 1.0e-5, viscous: 0.1, coulomb: 0.05}
  - {name: slide, theta: 0, d: 0.2, a: 0.0, alpha: -90, type: prismatic,
     limits: {lower: 0.0, upper: 0.5, velocity: 0.3, effort: 100},
     mass: 0.7, com: [0, 0, -0.1], inertia: [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.002]],
     gear_ratio: 10, rotor_inertia: 2.0e-5, viscous: 0.5, coulomb: 0.2}
  - {name: elbow, a: 0.8, mass: 0.5, com: [-0.4, 0, 0], inertia: {iyy: 0.0267, izz: 0.0267}}
frames:
  - {name: camera, link: link3, origin: {xyz: [0.06, 0, 0], rpy: [0, 0, 0]}}
"""
FULL_TREE_YAML = """\
# every field of the tree flavour
name: full_tree
gravity: [0, 0, -9.81]
units: {angle: rad}
source: docs/model-files.md, tree flavour
base: world
tool: camera
links:
  - name: pan
    joint: {name: pan_joint, type: revolute, axis: [0, 0, 1], origin: {xyz: [0, 0, 0.1], rpy: [0, 0, 0.3]},
            offset: 0.1, limits: {lower: -3.0, upper: 3.0, velocity: 2.0, effort: 10.0},
            gear_ratio: 100, rotor_inertia: 1.0e-6, viscous: 0.01, coulomb: 0.02}
    inertial: {mass: 0.4, com: [0, 0, 0.02], inertia: {ixx: 1e-4, ixy: 1e-6, ixz: 0, iyy: 1e-4, iyz: 0, izz: 1.5e-4}}
  - name: tilt
    parent: pan
    joint: {name: tilt_joint, type: continuous, axis: [0, 1, 0], origin: {xyz: [0, 0, 0.05]}}
    inertial: {mass: 0.2, com: [0.03, 0, 0], inertia: {ixx: 5e-5, iyy: 8e-5, izz: 8e-5}}
    post: {xyz: [0.01, 0, 0], rpy: [0, 0, 0]}
  - name: slider
    parent: tilt
    joint: {name: slide_joint, type: prismatic, axis: [1, 0, 0], origin: {xyz: [0.05, 0, 0]},
            limits: {lower: 0.0, upper: 0.2}, viscous: 1.0}
    inertial: {mass: 0.1, com: [0.01, 0, 0], inertia: {ixx: 1e-5, iyy: 1e-5, izz: 1e-5}}
  - name: bracket
    parent: slider
    joint: {name: bracket_joint, type: fixed, origin: {xyz: [0.02, 0, 0]}}
    inertial: {mass: 0.05, com: [0, 0, 0], inertia: {ixx: 1e-6, iyy: 1e-6, izz: 1e-6}}
frames:
  - {name: camera, link: bracket, origin: {xyz: [0.06, 0, 0], rpy: [0, 0, 0]}}
  - {name: mount, origin: {xyz: [0, 0, 0.01]}}
"""


@dataclass(frozen=True)
class Seed:
    name: str  # where the text came from
    kind: str  # "urdf" | "yaml" | "toml"
    text: str


def erd_robots_dir():
    """example-robot-data's robots/ folder, or None when it is not installed."""
    from kinedyn.testing import example_robot_data_dir

    return example_robot_data_dir()


def _read(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        return f.read()


@functools.cache
def seeds(kind: str) -> tuple:
    """The seed texts of one kind ("urdf", "yaml" or "toml"), in a fixed order."""
    if kind == "urdf":
        out = [
            Seed(
                "examples/robots/planar_2r.urdf",
                "urdf",
                _read(os.path.join(ROOT, "examples", "robots", "planar_2r.urdf")),
            )
        ]
        erd = erd_robots_dir()
        if erd is not None:
            out += [
                Seed(f"example-robot-data/{p}", "urdf", _read(os.path.join(erd, p)))
                for p in ERD_URDFS
                if os.path.exists(os.path.join(erd, p))
            ]
        return tuple(out)
    if kind not in ("yaml", "toml"):
        raise ValueError(f"unknown seed kind {kind!r}")
    ext = {"yaml": (".yaml", ".yml"), "toml": (".toml",)}[kind]
    folder = os.path.join(ROOT, "examples", "robots")
    out = [
        Seed(f"examples/robots/{f}", kind, _read(os.path.join(folder, f)))
        for f in sorted(os.listdir(folder))
        if f.endswith(ext)
    ]
    for name, text in (("full_dh", FULL_DH_YAML), ("full_tree", FULL_TREE_YAML)):
        if kind == "toml":
            import tomli_w
            import yaml

            text = tomli_w.dumps(yaml.safe_load(text))
        out.append(Seed(f"tests/fuzz/corpus.py:{name}", kind, text))
    return tuple(out) + _saved(kind)


@functools.cache
def _saved(kind: str) -> tuple:
    """``Robot.save`` of every built-in robot (DH flavour) and of two URDF robots (tree flavour)."""
    import kinedyn as kd

    robots = [(f"kd.robots.{name}", kd.robots.get(name)) for name in kd.robots.names()]
    erd = erd_robots_dir()
    for p in ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", "ur_description/urdf/ur5_robot.urdf"):
        if erd is not None and os.path.exists(os.path.join(erd, p)):
            robots.append((f"example-robot-data/{p}", kd.Robot.from_urdf(os.path.join(erd, p))))
    if not robots[-1][0].startswith("example"):  # no example-robot-data: the project's own URDF
        robots.append(
            (
                "examples/robots/planar_2r.urdf",
                kd.Robot.from_urdf(os.path.join(ROOT, "examples", "robots", "planar_2r.urdf")),
            )
        )
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, robot in robots:
            path = os.path.join(tmp, f"seed.{kind}")
            robot.save(path)
            out.append(Seed(f"Robot.save({name})", kind, _read(path)))
    return tuple(out)
