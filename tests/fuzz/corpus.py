"""The real texts the fuzzer mutates: URDFs of example-robot-data (when installed) and of examples/,
the project's YAML/TOML robot files, and files written by ``kd.save`` of the built-in robots and of
loaded URDFs (the tree flavour). Seeds are read once per process and cached; the order is fixed so
that a seed index means the same file on every run."""

from __future__ import annotations

import functools
import os
import site
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


@dataclass(frozen=True)
class Seed:
    name: str  # where the text came from
    kind: str  # "urdf" | "yaml" | "toml"
    text: str


def erd_robots_dir():
    """example-robot-data's robots/ folder, or None when it is not installed."""
    for sp_dir in site.getsitepackages():
        candidate = os.path.join(sp_dir, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(candidate):
            return candidate
    return None


def _read(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        return f.read()


@functools.lru_cache(maxsize=None)
def seeds(kind: str) -> tuple:
    """The seed texts of one kind ("urdf", "yaml" or "toml"), in a fixed order."""
    if kind == "urdf":
        out = [Seed("examples/robots/planar_2r.urdf", "urdf", _read(os.path.join(ROOT, "examples", "robots", "planar_2r.urdf")))]
        erd = erd_robots_dir()
        if erd is not None:
            out += [Seed(f"example-robot-data/{p}", "urdf", _read(os.path.join(erd, p))) for p in ERD_URDFS if os.path.exists(os.path.join(erd, p))]
        return tuple(out)
    if kind not in ("yaml", "toml"):
        raise ValueError(f"unknown seed kind {kind!r}")
    ext = {"yaml": (".yaml", ".yml"), "toml": (".toml",)}[kind]
    folder = os.path.join(ROOT, "examples", "robots")
    out = [Seed(f"examples/robots/{f}", kind, _read(os.path.join(folder, f))) for f in sorted(os.listdir(folder)) if f.endswith(ext)]
    return tuple(out) + _saved(kind)


@functools.lru_cache(maxsize=None)
def _saved(kind: str) -> tuple:
    """``Robot.save`` of every built-in robot (DH flavour) and of two URDF robots (tree flavour)."""
    import kinedyn as kd

    robots = [(f"kd.robots.{name}", kd.robots.get(name)) for name in kd.robots.names()]
    erd = erd_robots_dir()
    for p in ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", "ur_description/urdf/ur5_robot.urdf"):
        if erd is not None and os.path.exists(os.path.join(erd, p)):
            robots.append((f"example-robot-data/{p}", kd.Robot.from_urdf(os.path.join(erd, p))))
    if not robots[-1][0].startswith("example"):  # no example-robot-data: the project's own URDF
        robots.append(("examples/robots/planar_2r.urdf", kd.Robot.from_urdf(os.path.join(ROOT, "examples", "robots", "planar_2r.urdf"))))
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, robot in robots:
            path = os.path.join(tmp, f"seed.{kind}")
            robot.save(path)
            out.append(Seed(f"Robot.save({name})", kind, _read(path)))
    return tuple(out)
