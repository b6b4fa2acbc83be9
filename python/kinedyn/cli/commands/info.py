"""``kinedyn info ROBOT``: the joint table, the DH table and the mass properties of a robot (a robot
file with symbolic parameters is shown as it is)."""

from __future__ import annotations

import math

import numpy as np
from rich.table import Table

from .. import app
from ..app import console, emit, esc, fmt
from ..options import robot_argument


def add_arguments(p) -> None:
    robot_argument(p)


def _value(v):
    """A parameter for display: a float, or the text of a symbolic expression (``info`` shows a
    robot file with symbols as it is)."""
    try:
        return float(v)
    except TypeError:
        return str(v)


def _mimic(robot, joint: str):
    """A reduced mimic follower's relation to its leader (``q = multiplier * q_leader + offset``), else None."""
    relation = robot.mimic_joints.get(joint)
    if relation is None:
        return None
    return {"leader": relation.leader, "multiplier": float(relation.multiplier), "offset": float(relation.offset)}


def _headline(robot) -> str:
    """How many degrees of freedom and joints: a mimic follower is a joint without a coordinate of its
    own, a multi-DOF joint has several coordinates."""
    moving = len(robot.tree.bodies)
    followers = len(robot.mimic_joints)
    if not followers and not robot.has_multi_dof_joints:
        return f"{robot.n} joints"
    parts = [
        f"{robot.n} degrees of freedom (nv), {robot.nq} coordinates (nq)"
        if robot.nq != robot.n
        else f"{robot.n} degrees of freedom"
    ]
    parts.append(
        f"{moving} moving joints"
        + (f", {followers} of them mimic joints (no coordinate of their own)" if followers else "")
    )
    return ", ".join(parts)


def run(args) -> int:
    robot = app.robot(args)
    joints = []
    for b in robot.tree.bodies:
        j = b.joint
        joints.append(
            {
                "name": j.name,
                "link": b.name,
                "type": j.kind,
                "parent": robot.tree.bodies[b.parent].name if b.parent >= 0 else robot.base,
                "axis": [_value(a) for a in j.axis],
                "offset": _value(j.offset),
                "lower": j.lower,
                "upper": j.upper,
                "velocity_limit": j.velocity_limit,
                "effort_limit": j.effort_limit,
                "gear_ratio": _value(j.gear_ratio),
                "rotor_inertia": _value(j.rotor_inertia),
                "viscous": _value(j.viscous),
                "coulomb": _value(j.coulomb),
                "coulomb_negative": _value(j.coulomb_levels[1]),  # the level for qd < 0 (= coulomb if symmetric)
                "mimics": _mimic(robot, j.name),
            }
        )
    bodies = [
        {
            "link": b.name,
            "mass": _value(b.inertia.mass),
            "com": [_value(c) for c in b.inertia.com],
            "inertia_about_com": [
                [_value(x) for x in row] for row in np.asarray(b.inertia.inertia, dtype=object).tolist()
            ],
        }
        for b in robot.tree.bodies
    ]
    dh = None
    if robot.dh is not None:
        dh = [
            {"theta": _value(r.theta), "d": _value(r.d), "a": _value(r.a), "alpha": _value(r.alpha), "type": r.kind}
            for r in robot.dh
        ]
    payload = {
        "name": robot.name,
        "n": robot.n,
        "source": robot.source,
        "gravity": [_value(g) for g in robot.gravity],
        "tool": robot.tool,
        "frames": robot.frame_names,
        "joints": joints,
        "dh_convention": robot.dh_convention,
        "dh": dh,
        "bodies": bodies,
        "total_mass": _value(sum(b.inertia.mass for b in robot.tree.bodies)),
        "symbols": sorted(str(s) for s in robot.symbols),
        "loops": [
            {"name": lp.name, "frame_a": lp.frame_a, "frame_b": lp.frame_b, "kind": lp.kind, "rows": lp.rows}
            for lp in robot.loops
        ],
    }

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: {_headline(robot)}, tool frame '{esc(robot.tool)}', gravity {esc(payload['gravity'])} m/s^2"
        )
        if robot.source:
            c.print(f"source: {esc(robot.source)}")
        t = Table(title="joints", title_justify="left")
        for col in ("#", "joint", "type", "parent -> link", "axis", "offset", "limits", "vel / effort"):
            t.add_column(col)
        for i, j in enumerate(joints, 1):
            unit = "rad" if j["type"] == "revolute" else "m"
            mimic = j["mimics"]
            kind = j["type"]
            if mimic is not None:  # q = multiplier q_leader + offset: no coordinate of its own
                m, o = mimic["multiplier"], mimic["offset"]
                if m == 1 and o == 0:
                    kind += f", mimics {mimic['leader']}"
                else:
                    kind += f", mimic: q = {fmt(m)} q({mimic['leader']})" + (f" + {fmt(o)}" if o else "")
            t.add_row(
                str(i),
                esc(j["name"]),
                esc(kind),
                esc(f"{j['parent']} -> {j['link']}"),
                esc(" ".join(fmt(a) for a in j["axis"])),
                esc(fmt(j["offset"])),
                f"[{fmt(j['lower'])}, {fmt(j['upper'])}] {unit}",
                f"{fmt(j['velocity_limit'])} / {fmt(j['effort_limit'])}",
            )
        c.print(t)
        if dh is not None:
            t = Table(title=f"DH table ({robot.dh_convention})", title_justify="left")
            for col in ("link", "theta", "d", "a", "alpha", "type"):
                t.add_column(col, justify="right")
            for i, r in enumerate(dh, 1):
                var = "q" if r["type"] == "revolute" else "d"
                t.add_row(
                    str(i),
                    esc(f"q{i} + {fmt(r['theta'])}" if var == "q" else fmt(r["theta"])),
                    esc(f"q{i} + {fmt(r['d'])}" if var == "d" else fmt(r["d"])),
                    esc(fmt(r["a"])),
                    f"{fmt(math.degrees(r['alpha']))} deg"
                    if isinstance(r["alpha"], float)
                    else esc(f"{r['alpha']} rad"),
                    r["type"],
                )
            c.print(t)
        t = Table(title="mass properties (body frames = joint frames)", title_justify="left")
        for col in ("link", "mass [kg]", "centre of mass [m]", "Ixx Iyy Izz about COM [kg m^2]"):
            t.add_column(col)
        for b in bodies:
            I = b["inertia_about_com"]
            t.add_row(
                esc(b["link"]),
                esc(fmt(b["mass"])),
                esc(" ".join(fmt(x) for x in b["com"])),
                esc(" ".join(fmt(I[k][k]) for k in range(3))),
            )
        c.print(t)
        c.print(f"total moving mass: {esc(fmt(payload['total_mass']))} kg")
        if payload["loops"]:  # closed loops (docs/closed-loops.md): constraints between two frames of the tree
            t = Table(title="closed loops (frame_a meets frame_b)", title_justify="left")
            for col in ("loop", "frame_a", "frame_b", "kind", "rows"):
                t.add_column(col)
            for lp in payload["loops"]:
                what = "point (origins meet)" if lp["kind"] == "point" else "weld (frames meet)"
                t.add_row(esc(lp["name"]), esc(lp["frame_a"]), esc(lp["frame_b"]), what, str(lp["rows"]))
            c.print(t)
        if payload["symbols"]:
            c.print(
                f"symbolic parameters: {', '.join(payload['symbols'])} (numeric commands take their values: --set NAME=VALUE)"
            )

    emit(args, payload, render)
    return 0
