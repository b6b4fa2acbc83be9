"""Self-checks: seeded random robots and the identities between kinedyn's algorithms.

``random_robot(seed, n, branching)`` builds a physically valid random chain or tree (random joint
kinds, axes, placements, inertias, offsets, rotor inertia and friction). ``check_identities(robot)``
evaluates the identities of docs/architecture.md ("Checking ourselves") at random states and returns their residuals, so a test, the
report and a user can all ask "does the engine agree with itself on this robot?".
"""

from __future__ import annotations

import math

import numpy as np

from ._math import homogeneous, rot_axis
from .description.inertia import Inertia
from .description.joint import Joint
from .description.link import Frame, Link
from .robot import Robot

__all__ = ["random_robot", "random_inertia", "check_identities", "example_robot_data_dir"]


def example_robot_data_dir() -> str | None:
    """The ``robots/`` folder of an installed example-robot-data (its wheel ships the URDFs and meshes
    under ``site-packages/cmeel.prefix/share/example-robot-data/robots``), or None."""
    import os
    import site

    for root in [*site.getsitepackages(), site.getusersitepackages()]:
        folder = os.path.join(root, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(folder):
            return folder
    return None


def _unit(rng) -> np.ndarray:
    while True:
        v = rng.uniform(-1, 1, 3)
        n = np.linalg.norm(v)
        if 0.1 < n <= 1:
            return v / n


def _rotation(rng) -> np.ndarray:
    return np.asarray(rot_axis(_unit(rng), rng.uniform(-math.pi, math.pi)))[:3, :3]


def random_inertia(rng) -> Inertia:
    """A real body: principal moments of a random solid box, in random axes, random centre of mass."""
    m = rng.uniform(0.5, 3.0)
    a, b, c = rng.uniform(0.05, 0.5, 3)
    principal = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12
    R = _rotation(rng)
    return Inertia(m, tuple(rng.uniform(-0.3, 0.3, 3)), R @ principal @ R.T)


def random_robot(
    seed: int = 0,
    n: int = 6,
    branching: bool = False,
    prismatic: float = 0.25,
    fixed: int = 1,
    friction: bool = True,
    floating: bool = False,
    spherical: float = 0.0,
    planar: float = 0.0,
) -> Robot:
    """A random robot of ``n`` moving joints (plus ``fixed`` fixed links with inertia, merged at
    compile time). ``branching=True`` gives a tree (each link's parent is any earlier link).
    ``floating=True``: the first joint is a free-flyer; ``spherical`` / ``planar``: the chance that
    a later joint is spherical / planar (normal z, Pinocchio's JointModelPlanar)."""
    rng = np.random.default_rng(seed)
    links = []
    names: list[str] = []
    for i in range(n + fixed):
        moving = i < n
        parent = None if i == 0 else (names[int(rng.integers(0, i))] if branching else names[-1])
        # (drawn only when asked for, so that the robots of a seed stay those of earlier versions)
        draw = rng.uniform() if spherical or planar else 1.0
        multi = (
            "floating"
            if floating and i == 0
            else ("spherical" if draw < spherical else "planar" if draw < spherical + planar else None)
        )
        if moving and multi is not None and i > 0 or (moving and multi == "floating"):
            joint = Joint(f"j{i + 1}", multi, (0.0, 0.0, 1.0))
        elif moving:
            kind = "prismatic" if rng.uniform() < prismatic else "revolute"
            joint = Joint(
                f"j{i + 1}",
                kind,
                tuple(_unit(rng)),
                offset=rng.uniform(-0.5, 0.5),
                gear_ratio=rng.uniform(1, 50) if friction else 1.0,
                rotor_inertia=rng.uniform(0, 1e-4) if friction else 0.0,
                viscous=rng.uniform(0, 0.5) if friction else 0.0,
                coulomb=rng.uniform(0, 0.3) if friction else 0.0,
            )
        else:
            joint = Joint(f"fixed{i - n + 1}", "fixed")
        name = f"link{i + 1}" if moving else f"fixed_link{i - n + 1}"
        placement = homogeneous(_rotation(rng), rng.uniform(-0.5, 0.5, 3))
        links.append(Link(name, parent, joint, placement, np.eye(4), random_inertia(rng)))
        names.append(name)
    tool = Frame("tool", names[n - 1], homogeneous(_rotation(rng), rng.uniform(-0.2, 0.2, 3)))
    return Robot(links, [tool], gravity=(0.0, 0.0, -9.81), name=f"random_{'tree' if branching else 'chain'}_{seed}")


def check_identities(robot: Robot, states: int = 5, seed: int | None = 0, h: float = 1e-6) -> dict:
    """Largest residual of each identity over ``states`` random states, as {name: residual}.

    Each residual is an absolute difference scaled by max(1, |reference|) of the quantities
    compared; values near 1e-12 mean the routes agree to rounding, near 1e-7 for finite-difference
    checks. Without friction terms where an identity needs them excluded (see each line)."""
    rng = np.random.default_rng(seed)
    n = robot.n
    worst: dict = {}

    def record(name, a, b):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        scale = max(1.0, float(np.abs(b).max(initial=0.0)))
        worst[name] = max(worst.get(name, 0.0), float(np.abs(a - b).max(initial=0.0)) / scale)

    pi = robot.inertial_parameters()
    armature = robot.armature
    for _ in range(states):
        q = robot.random_configuration(rng)
        qd = rng.normal(size=n)
        qdd = rng.normal(size=n)
        M = robot.mass_matrix(q)
        g = robot.gravity_torque(q)
        C = robot.coriolis_matrix(q, qd)
        friction = robot.friction_torque(qd)
        tau = robot.inverse_dynamics(q, qd, qdd)
        bias = robot.bias_torque(q, qd)
        record("rnea == M qdd + C qd + g + friction", tau, M @ qdd + C @ qd + g + friction)
        record("bias == C qd + g", bias, C @ qd + g)
        record("g == rnea(q, 0, 0)", g, robot.inverse_dynamics(q, np.zeros(n), np.zeros(n)))
        record("aba(rnea(qdd)) == qdd", robot.forward_dynamics(q, qd, tau), qdd)
        record("M symmetric", M, M.T)
        record("M^-1 M == I", robot.mass_matrix_inverse(q) @ M, np.eye(n))
        record("K == qd M qd / 2", robot.kinetic_energy(q, qd), qd @ M @ qd / 2)
        Y = robot.regressor(q, qd, qdd)
        record("Y pi == tau (no friction, no rotor)", Y @ pi, tau - friction - armature * qdd)
        # finite differences along q(t) = q ⊕ t qd (q + t qd for 1-DOF joints; robot.integrate)
        Mp, Mm = robot.mass_matrix(robot.integrate(q, qd, h)), robot.mass_matrix(robot.integrate(q, qd, -h))
        Mdot = (Mp - Mm) / (2 * h)
        record("dM/dt == C + C^T (finite differences)", Mdot, C + C.T)
        S = Mdot - 2 * C
        record("dM/dt - 2C skew (finite differences)", S, -S.T)
        dP = np.array(
            [
                (robot.potential_energy(robot.integrate(q, e, h)) - robot.potential_energy(robot.integrate(q, e, -h)))
                / (2 * h)
                for e in np.eye(n)
            ]
        )
        record("g == dP/dq (finite differences)", g, dP)
    return worst
