"""Names and units of the entries of q (nq) and of qd (nv): what every table, page and command line
labels a configuration or a velocity with (docs/conventions.md, "Configurations and velocities")."""

from __future__ import annotations

#: the names of a joint's entries of q and of qd (docs/conventions.md, "Configurations and velocities")
Q_ENTRIES = {
    "floating": ("x", "y", "z", "qx", "qy", "qz", "qw"),
    "spherical": ("qx", "qy", "qz", "qw"),
    "planar": ("x", "y", "cos θ", "sin θ"),
}
V_ENTRIES = {
    "floating": ("vx", "vy", "vz", "ωx", "ωy", "ωz"),
    "spherical": ("ωx", "ωy", "ωz"),
    "planar": ("vx", "vy", "ω"),
}


def coordinate_labels(robot) -> list[str]:
    """One label per entry of q (nq): a 1-DOF joint's name, ``joint.x`` ... ``joint.qw`` for a
    multi-DOF joint's block."""
    return [
        label
        for j in robot.joints
        for label in ([f"{j.name}.{e}" for e in Q_ENTRIES[j.kind]] if j.is_multi_dof else [j.name])
    ]


def velocity_labels(robot) -> list[str]:
    """One label per degree of freedom (nv: entries of qd, rows and columns of M, columns of J): a
    1-DOF joint's name, ``joint.vx`` ... ``joint.ωz`` for a multi-DOF joint (velocities in its child's frame)."""
    return [
        label
        for j in robot.joints
        for label in ([f"{j.name}.{e}" for e in V_ENTRIES[j.kind]] if j.is_multi_dof else [j.name])
    ]


def coordinate_units(robot) -> list[str]:
    """Per entry of q: "rad", "m", or "" (a quaternion's or a (cos θ, sin θ) pair's entries)."""
    out: list[str] = []
    for j in robot.joints:
        if j.kind == "floating":
            out += ["m"] * 3 + [""] * 4
        elif j.kind == "spherical":
            out += [""] * 4
        elif j.kind == "planar":
            out += ["m"] * 2 + [""] * 2
        else:
            out.append("rad" if j.kind == "revolute" else "m")
    return out


def in_multi_dof_block(robot) -> list[bool]:
    """Per entry of q: whether it belongs to a multi-DOF joint's block."""
    return [j.is_multi_dof for j in robot.joints for _ in range(j.nq)]
