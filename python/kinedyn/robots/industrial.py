"""Industrial arms of the catalogue: the Unimation PUMA 560, the Stanford arm and the UR5.

Each function returns a standard-DH :class:`kinedyn.Robot` and takes keyword overrides (link
lengths, ``masses``, ``coms``, ``inertias``, ``gravity``...). Every number below carries its source;
where a published value had to be changed to describe a physically possible body the docstring
says which and why.

Notation: ``inertias[i]`` is the 3x3 inertia tensor of link i about its centre of mass in DH link
frame i's axes, or the diagonal ``(Ixx, Iyy, Izz)``; ``coms[i]`` is the centre of mass in link
frame i (metres); RTB's ``I = [Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` lists have all products zero here.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Sequence
from typing import Any, Union

import numpy as np

from .._math import rot_z
from ..description.dh import DHRow
from ..description.inertia import Inertia, PhysicalConsistencyWarning
from ..robot import Robot

__all__ = ["puma560", "stanford", "ur5", "UR5_URDF_BASE_FROM_DH_BASE", "UR5_DH_TOOL_FROM_URDF_TOOL0"]

_DEG = math.pi / 180
_INCH = 0.0254


def _published(factory):
    """Published tables are kept as published and their docstrings name the entries no rigid body
    can have, so building a catalogue robot does not repeat the PhysicalConsistencyWarning."""

    @functools.wraps(factory)
    def build(*args, **kwargs):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysicalConsistencyWarning)
            return factory(*args, **kwargs)

    return build


def _inertia(mass, com, tensor) -> Inertia:
    t = np.asarray(tensor, dtype=float)
    return Inertia(mass, tuple(com), np.diag(t) if t.shape == (3,) else t)


def _pick(given: Sequence | None, default: Sequence, what: str) -> list:
    if given is None:
        return list(default)
    if len(given) != len(default):
        raise ValueError(f"{what} needs {len(default)} entries, got {len(given)}")
    return list(given)


def _rows(kin, limits, masses, coms, inertias, drive, names) -> list:
    """DH rows from per-link kinematics (theta, d, a, alpha, kind), limits, inertial and drive data."""
    rows = []
    for i, (theta, d, a, alpha, kind) in enumerate(kin):
        lower, upper, velocity, effort = limits[i]
        gear, rotor, viscous, coulomb = drive[i]
        rows.append(
            DHRow(
                theta=theta,
                d=d,
                a=a,
                alpha=alpha,
                kind=kind,
                name=names[i],
                inertia=_inertia(masses[i], coms[i], inertias[i]),
                lower=lower,
                upper=upper,
                velocity_limit=velocity,
                effort_limit=effort,
                gear_ratio=gear,
                rotor_inertia=rotor,
                viscous=viscous,
                coulomb=coulomb,
            )
        )
    return rows


# ------------------------------------------------------------------------------------ PUMA 560
# Masses, centres of mass, inertias about the centre of mass: Armstrong, Khatib & Burdick (1986),
# "The explicit dynamic model and inertial parameters of the PUMA 560 arm", ICRA, as re-expressed
# in standard-DH link frames by Corke & Armstrong-Helouvry (1994), "A search for consensus among
# model parameters reported for the PUMA 560 robot", ICRA, pp. 1608-1613; values as in Corke's
# Robotics Toolbox for MATLAB, models/mdl_puma560.m ("params of 8/95").
PUMA560_MASSES = (0.0, 17.4, 4.8, 0.82, 0.34, 0.09)
PUMA560_COMS = (
    (0.0, 0.0, 0.0),
    (-0.3638, 0.006, 0.2275),
    (-0.0203, -0.0141, 0.070),
    (0.0, 0.019, 0.0),
    (0.0, 0.0, 0.0),
    (0.0, 0.0, 0.032),
)
PUMA560_INERTIAS = (
    (0.0, 0.35, 0.0),  # not a rigid body's (triangle inequality): see puma560's docstring
    (0.13, 0.524, 0.539),
    (0.066, 0.086, 0.0125),  # not a rigid body's: see puma560's docstring
    (1.8e-3, 1.3e-3, 1.8e-3),
    (0.3e-3, 0.4e-3, 0.3e-3),
    (0.15e-3, 0.15e-3, 0.04e-3),
)
# Motor inertia Jm [kg m^2], gear ratio G, motor viscous friction B [N m s/rad], motor Coulomb
# friction Tc (+, -) [N m], all measured at the motor: Corke & Armstrong-Helouvry (1994) via mdl_puma560.m.
PUMA560_MOTORS = (
    (200e-6, -62.6111, 1.48e-3, (0.395, -0.435)),
    (200e-6, 107.815, 0.817e-3, (0.126, -0.071)),
    (200e-6, -53.7063, 1.38e-3, (0.132, -0.105)),
    (33e-6, 76.0364, 71.2e-6, (11.2e-3, -16.9e-3)),
    (33e-6, 71.923, 82.6e-6, (9.26e-3, -14.5e-3)),
    (33e-6, 76.686, 36.7e-6, (3.96e-3, -10.5e-3)),
)
# Joint limits [deg]: Wang & Chen (1991), IEEE Trans. Robotics and Automation 7(4), as quoted in mdl_puma560.m.
PUMA560_LIMITS_DEG = ((-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266))


@_published
def puma560(
    a2: float = 0.4318,
    a3: float = 0.0203,
    d3: float = 0.15005,
    d4: float = 0.4318,
    masses: Sequence | None = None,
    coms: Sequence | None = None,
    inertias: Sequence | None = None,
    gravity=(0.0, 0.0, -9.81),
    motors: bool = True,
    friction: Union[bool, str] = False,
) -> Robot:
    """The Unimation PUMA 560 in standard DH (Corke's ``p560``), gravity along -z0.

    ====  =====  =======  ======  ======
    link  theta  d        a       alpha
    1     q1     0        0       +90 deg
    2     q2     0        a2      0
    3     q3     d3       a3      -90 deg
    4     q4     d4       0       +90 deg
    5     q5     0        0       -90 deg
    6     q6     0        0       0
    ====  =====  =======  ======  ======

    Sources: kinematics a2 = 0.4318, a3 = 0.0203, d4 = 0.4318 m and d3 = 0.15005 m (Corke's 2/8/95
    value, "closer to data from Lee, AKB86 and Tarn"); masses, centres of mass and inertias about the
    centre of mass from Armstrong, Khatib & Burdick (1986) re-expressed in these frames by Corke &
    Armstrong-Helouvry (1994); motor data (Jm, G, B, Tc) from Corke & Armstrong-Helouvry (1994);
    joint limits from Wang & Chen (1991); all as tabulated in Corke's Robotics Toolbox
    ``mdl_puma560.m`` (module constants ``PUMA560_*`` hold them).

    Two published inertias are not those of any rigid body (link 1's (0, 0.35, 0) and link 3's
    Izz = 0.0125 < Iyy - Ixx fail the triangle inequality of principal moments); they are kept as
    published, so kinedyn agrees with other tools using the same table. Link 1 has zero mass and turns about y1 only,
    so its Ixx and Izz never enter the dynamics.

    ``motors=True`` adds the reflected rotor inertia G^2 Jm to each joint (gear_ratio = G,
    rotor_inertia = Jm). ``friction=True`` adds the motor friction referred to the joint as Corke's
    model does (RTB ``Link.friction``: ``B G^2 qd + |G| Tc+`` for qd > 0 and ``|G| Tc-`` for qd < 0):
    viscous = B G^2 and direction-dependent Coulomb levels coulomb = |G| Tc+ (qd > 0),
    coulomb_negative = |G| |Tc-| (qd < 0), the sign of Tc chosen by the joint rate, as RTB does.
    ``friction="symmetric"`` keeps one Coulomb level, the mean |G| (Tc+ - Tc-) / 2 of the two.
    ``masses``/``coms``/``inertias`` replace the six-entry tables above.
    """
    kin = [
        (0.0, 0.0, 0.0, math.pi / 2, "revolute"),
        (0.0, 0.0, a2, 0.0, "revolute"),
        (0.0, d3, a3, -math.pi / 2, "revolute"),
        (0.0, d4, 0.0, math.pi / 2, "revolute"),
        (0.0, 0.0, 0.0, -math.pi / 2, "revolute"),
        (0.0, 0.0, 0.0, 0.0, "revolute"),
    ]
    limits = [(lo * _DEG, hi * _DEG, math.inf, math.inf) for lo, hi in PUMA560_LIMITS_DEG]
    if friction not in (True, False, "symmetric"):
        raise ValueError(
            f"friction must be True (Corke's two Coulomb levels), 'symmetric' (their mean) or False, got {friction!r}"
        )
    drive = []
    for jm, gear, b, (tc_pos, tc_neg) in PUMA560_MOTORS:
        viscous = b * gear**2 if friction else 0.0
        if friction == "symmetric":
            coulomb: Any = abs(gear) * (tc_pos - tc_neg) / 2
        elif friction:
            coulomb = (abs(gear) * tc_pos, abs(gear) * -tc_neg)  # (qd > 0, qd < 0) levels, both >= 0
        else:
            coulomb = 0.0
        drive.append((gear, jm if motors else 0.0, viscous, coulomb))
    rows = _rows(
        kin,
        limits,
        _pick(masses, PUMA560_MASSES, "masses"),
        _pick(coms, PUMA560_COMS, "coms"),
        _pick(inertias, PUMA560_INERTIAS, "inertias"),
        drive,
        [f"q{i}" for i in range(1, 7)],
    )
    return Robot.from_dh(
        rows,
        gravity=gravity,
        name="puma560",
        source="Corke & Armstrong-Helouvry 1994; Armstrong, Khatib & Burdick 1986; Corke RTB mdl_puma560.m",
    )


# ------------------------------------------------------------------------------------ Stanford arm
# Kinematics: Scheinman, "Design of a computer controlled manipulator", Stanford AIM-92 (1969) /
# AIM-177 Fig. 2.3, in the standard DH form of Corke's Robotics Toolbox models/mdl_stanford.m
# (also Spong, Hutchinson & Vidyasagar, Robot Modeling and Control, Example 3.4 / Table 3.4).
# Dynamics: Paul, "Robot Manipulators: Mathematics, Programming and Control" (1981), Tables 6.5
# and 6.6, as tabulated in mdl_stanford.m (gear ratios unknown: Jm is the reflected armature inertia).
STANFORD_MASSES = (9.29, 5.01, 4.25, 1.08, 0.630, 0.51)
STANFORD_COMS = (
    (0.0, 0.0175, -0.1105),
    (0.0, -1.054, 0.0),
    (0.0, 0.0, -6.447),
    (0.0, 0.092, -0.054),
    (0.0, 0.566, 0.003),
    (0.0, 0.0, 1.554),
)
STANFORD_INERTIAS = (
    (0.276, 0.255, 0.071),
    (0.108, 0.018, 0.100),
    (2.51, 2.51, 0.006),
    (0.002, 0.001, 0.001),
    (0.003, 0.0004, 0.0),  # not a rigid body's: see stanford's docstring
    (0.013, 0.013, 0.0003),
)
STANFORD_ROTOR_INERTIAS = (0.953, 2.193, 0.782, 0.106, 0.097, 0.020)
STANFORD_LIMITS = (
    (-170 * _DEG, 170 * _DEG),
    (-170 * _DEG, 170 * _DEG),
    (12 * _INCH, (12 + 38) * _INCH),
    (-170 * _DEG, 170 * _DEG),
    (-90 * _DEG, 90 * _DEG),
    (-170 * _DEG, 170 * _DEG),
)


@_published
def stanford(
    d1: float = 0.412,
    d2: float = 0.154,
    d6: float = 0.263,
    masses: Sequence | None = None,
    coms: Sequence | None = None,
    inertias: Sequence | None = None,
    gravity=(0.0, 0.0, -9.81),
    motors: bool = True,
) -> Robot:
    """The Stanford (Scheinman) arm, RRPRRR, in standard DH (Corke's ``stanf``), gravity along -z0.

    ====  =========  ====  ===  =======
    link  theta      d     a    alpha
    1     q1         d1    0    -90 deg
    2     q2         d2    0    +90 deg
    3     -90 deg    q3    0    0        (prismatic)
    4     q4         0     0    -90 deg
    5     q5         0     0    +90 deg
    6     q6         0     0    0
    ====  =========  ====  ===  =======

    and the tool d6 = 0.263 m along z6 from the wrist centre, in a tool transform, as the published
    model has it (Corke's ``mdl_stanford.m``: link 6 with d = 0 and ``tool = transl(0, 0, 0.263)``),
    so link 6's centre of mass (0, 0, 1.554) is measured from the wrist centre, as tabulated.
    (Putting 0.263 m into d6 instead would move link 6's frame, and with it its centre of mass,
    changing M, g and C.)

    Sources: kinematics d1 = 0.412, d2 = 0.154, d6 = 0.263 m from Stanford AIM-177 Fig. 2.3;
    joint limits (+-170 deg, wrist pitch +-90 deg) from Dobrotin & Scheinman (1973), IJCAI, and the
    boom's stroke 12 to 50 inches (38 inch rack) as estimated by Corke; masses, centres of mass,
    inertias and reflected armature inertias Jm from Paul (1981) Tables 6.5 and 6.6; all as
    tabulated in Corke's Robotics Toolbox ``mdl_stanford.m`` (module constants ``STANFORD_*``).

    Link 5's published ``I = (0.003, 0.0004, 0)`` fails the triangle inequality Iyy + Izz >= Ixx;
    it is kept as published.
    The published centres of mass of links 2, 3 and 6 (e.g. -6.447 m along z3) are kept as
    tabulated by Corke although they look like a unit slip; pass ``coms=`` to use others.

    ``motors=True`` puts Jm on each joint as rotor inertia with gear ratio 1 (so the armature
    G^2 Jm = Jm, as in Corke's model).
    """
    kin = [
        (0.0, d1, 0.0, -math.pi / 2, "revolute"),
        (0.0, d2, 0.0, math.pi / 2, "revolute"),
        (-math.pi / 2, 0.0, 0.0, 0.0, "prismatic"),
        (0.0, 0.0, 0.0, -math.pi / 2, "revolute"),
        (0.0, 0.0, 0.0, math.pi / 2, "revolute"),
        (0.0, 0.0, 0.0, 0.0, "revolute"),  # d6 = 0: frame 6 at the wrist centre, as published
    ]
    limits = [(lo, hi, math.inf, math.inf) for lo, hi in STANFORD_LIMITS]
    drive = [(1.0, jm if motors else 0.0, 0.0, 0.0) for jm in STANFORD_ROTOR_INERTIAS]
    rows = _rows(
        kin,
        limits,
        _pick(masses, STANFORD_MASSES, "masses"),
        _pick(coms, STANFORD_COMS, "coms"),
        _pick(inertias, STANFORD_INERTIAS, "inertias"),
        drive,
        [f"q{i}" for i in range(1, 7)],
    )
    tool = np.eye(4)
    tool[2, 3] = d6  # the published tool transform, transl(0, 0, 0.263)
    return Robot.from_dh(
        rows,
        gravity=gravity,
        name="stanford",
        tool=tool,
        source="Stanford AIM-177; Paul 1981 Tables 6.5-6.6; Corke RTB mdl_stanford.m",
    )


# ---------------------------------------------------------------------------------------- UR5
# Kinematics, masses and centres of mass (in DH link frames): Universal Robots, "DH parameters for
# calculations of kinematics and dynamics" (universal-robots.com/articles/ur/application-installation/
# dh-parameters-for-calculations-of-kinematics-and-dynamics), UR5 (CB3) table; the same DH table is
# in the UR5 CB3 user manual, "Robot DH parameter", UR5 series 3.
UR5_MASSES = (3.7, 8.393, 2.33, 1.219, 1.219, 0.1879)
UR5_COMS = (
    (0.0, -0.02561, 0.00193),
    (0.2125, 0.0, 0.11336),
    (0.15, 0.0, 0.0265),
    (0.0, -0.0018, 0.01634),
    (0.0, 0.0018, 0.01634),
    (0.0, 0.0, -0.001159),
)
# UR publishes no UR5 inertia tensors. Solid cylinders of the link dimensions used by ROS-Industrial's
# ur_description (ur5.urdf.xacro, cylinder_inertial: radius 0.06 m, lengths 0.15, 0.56, 0.5, 0.12,
# 0.12, 0.12 m), with their symmetry axis along these DH-frame axes (found by comparing frames):
UR5_CYLINDERS = (
    (0.06, 0.15, "y"),
    (0.06, 0.56, "x"),
    (0.06, 0.5, "x"),
    (0.06, 0.12, "z"),
    (0.06, 0.12, "y"),
    (0.06, 0.12, "y"),
)
# Joint limits: +-360 deg on every joint (UR5 CB3 technical specifications); velocity [rad/s] and
# effort [N m] limits as in ur_description's ur5.urdf.xacro.
UR5_VELOCITY_LIMITS = (3.15, 3.15, 3.15, 3.2, 3.2, 3.2)
UR5_EFFORT_LIMITS = (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)

# Fixed frames between example-robot-data's ur5_robot.urdf and this DH model, found by comparing
# poses at random configurations (tests/test_catalogue.py checks them):
#   urdf_base_link_from_tool0(q) = UR5_URDF_BASE_FROM_DH_BASE @ dh_base_from_tool(q) @ UR5_DH_TOOL_FROM_URDF_TOOL0
# The URDF's base_link is the DH base turned by 180 deg about z (its child frame "base" is the DH
# base); tool0 coincides with DH frame 6. Joint angles are the same in both models.
UR5_URDF_BASE_FROM_DH_BASE = np.asarray(rot_z(math.pi)).round(15) + 0.0
UR5_DH_TOOL_FROM_URDF_TOOL0 = np.eye(4)


def ur5(
    d1: float = 0.089159,
    a2: float = -0.425,
    a3: float = -0.39225,
    d4: float = 0.10915,
    d5: float = 0.09465,
    d6: float = 0.0823,
    masses: Sequence | None = None,
    coms: Sequence | None = None,
    inertias: Sequence | None = None,
    gravity=(0.0, 0.0, -9.81),
) -> Robot:
    """Universal Robots UR5 (CB3) in UR's standard DH, gravity along -z0.

    ====  =====  ========  ========  =======
    link  theta  d         a         alpha
    1     q1     d1        0         +90 deg
    2     q2     0         a2        0
    3     q3     0         a3        0
    4     q4     d4        0         +90 deg
    5     q5     d5        0         -90 deg
    6     q6     d6        0         0
    ====  =====  ========  ========  =======

    Sources: DH parameters (d1 = 0.089159, a2 = -0.425, a3 = -0.39225, d4 = 0.10915, d5 = 0.09465,
    d6 = 0.0823 m), masses (3.7, 8.393, 2.33, 1.219, 1.219, 0.1879 kg) and centres of mass in the
    DH link frames from Universal Robots' "DH parameters for calculations of kinematics and
    dynamics" page; joint position limits +-360 deg from the UR5 technical specifications;
    velocity/effort limits from ROS-Industrial ur_description. UR gives no inertia tensors: each
    link is a solid cylinder (``Inertia.cylinder``) with ur_description's dimensions (radius 0.06 m;
    ur_description's wrist links say 0.6 m, a tenfold slip we do not copy) and UR's mass.

    ``UR5_URDF_BASE_FROM_DH_BASE`` and ``UR5_DH_TOOL_FROM_URDF_TOOL0`` relate this model to
    example-robot-data's ``ur5_robot.urdf`` (base_link -> tool0).
    """
    masses = _pick(masses, UR5_MASSES, "masses")
    coms = _pick(coms, UR5_COMS, "coms")
    if inertias is None:
        inertias = [
            np.array(Inertia.cylinder(m, r, length, axis).inertia)
            for m, (r, length, axis) in zip(masses, UR5_CYLINDERS)
        ]
    kin = [
        (0.0, d1, 0.0, math.pi / 2, "revolute"),
        (0.0, 0.0, a2, 0.0, "revolute"),
        (0.0, 0.0, a3, 0.0, "revolute"),
        (0.0, d4, 0.0, math.pi / 2, "revolute"),
        (0.0, d5, 0.0, -math.pi / 2, "revolute"),
        (0.0, d6, 0.0, 0.0, "revolute"),
    ]
    limits = [(-2 * math.pi, 2 * math.pi, v, e) for v, e in zip(UR5_VELOCITY_LIMITS, UR5_EFFORT_LIMITS)]
    drive = [(1.0, 0.0, 0.0, 0.0)] * 6
    names = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    rows = _rows(kin, limits, masses, coms, _pick(inertias, UR5_CYLINDERS, "inertias"), drive, names)
    return Robot.from_dh(
        rows,
        gravity=gravity,
        name="ur5",
        source="Universal Robots DH parameters page (UR5); ur_description ur5.urdf.xacro",
    )
