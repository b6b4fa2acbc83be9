"""Textbook arms of the seed: the tutorial's two-link arm, its elbow manipulator, the Cartesian arm.

Every parameter is a keyword argument; ``symbolic=True`` replaces the defaults by SymPy symbols so
the symbolic engine derives the textbook's general formulas.
"""

from __future__ import annotations

import functools
import inspect
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar, cast

from .._lazy import LazyModule
from ..description.dh import DHRow
from ..description.inertia import Inertia
from ..robot import Robot

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["planar_2r", "planar_3r", "elbow_3r", "cartesian_2p"]


_F = TypeVar("_F", bound=Callable[..., Robot])


def _symbolic_defaults(names: str) -> Callable[[_F], _F]:
    """With ``symbolic=True``, every parameter in ``names`` that the caller did not give becomes the
    positive SymPy symbol of its name; a value given (``planar_2r(symbolic=True, lc1=1.0)``) is kept.
    (The functions used to overwrite every parameter with its symbol, so given values were ignored.)"""
    symbols = names.split()

    def decorate(fn: _F) -> _F:
        signature = inspect.signature(fn)

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            given = signature.bind(*args, **kwargs).arguments
            if given.get("symbolic"):
                for name in symbols:
                    if name not in given or given[name] is None:
                        kwargs[name] = sp.Symbol(name, positive=True)
            return fn(*args, **kwargs)

        return cast(_F, wrapper)

    return decorate


def _rod_x(m, length, lc, I, I_axial=0):
    """A link along its DH frame's -x axis (frame i sits at the far end of link i, standard DH):
    centre of mass lc from the joint, i.e. at x = lc - length; inertia I about the z axis
    (and about y), ``I_axial`` about the rod's own axis (none for a thin rod)."""
    return Inertia(m, (lc - length, 0, 0), ((I_axial, 0, 0), (0, I, 0), (0, 0, I)))


@_symbolic_defaults("l1 l2 lc1 lc2 m1 m2 I1 I2 g")
def planar_2r(l1=2.0, l2=3.0, m1=1.0, m2=1.0, lc1=None, lc2=None, I1=None, I2=None, g=9.81, symbolic=False) -> Robot:
    """The tutorial's two-link planar arm (Spong §9.4.2's planar elbow): joints about z, links along x,
    gravity -g along y, tool at the end of link 2.

    Defaults: l1 = 2 m, l2 = 3 m (tutorial Q2), uniform rods of m1 = m2 = 1 kg with the centre of mass
    at mid-length and I = m l^2 / 12 about it. ``symbolic=True`` uses symbols l1, l2, lc1, lc2, m1, m2,
    I1, I2, g instead; any keyword given explicitly keeps its value (``symbolic=True, lc1=1.0``).
    """
    lc1 = l1 / 2 if lc1 is None else lc1
    lc2 = l2 / 2 if lc2 is None else lc2
    I1 = m1 * l1**2 / 12 if I1 is None else I1
    I2 = m2 * l2**2 / 12 if I2 is None else I2
    rows = [
        DHRow(a=l1, inertia=_rod_x(m1, l1, lc1, I1)),
        DHRow(a=l2, inertia=_rod_x(m2, l2, lc2, I2)),
    ]
    return Robot.from_dh(
        rows,
        gravity=(0, -g, 0),
        name="planar_2r",
        source="METR4202 Tutorial 4 Q1-Q3; Spong, Hutchinson & Vidyasagar, Robot Modeling and Control, §9.4.2",
    )


@_symbolic_defaults("l1 l2 l3 m1 m2 m3 g")
def planar_3r(l1=1.0, l2=1.0, l3=0.5, m1=1.0, m2=1.0, m3=0.5, g=9.81, symbolic=False) -> Robot:
    """A planar 3R arm (uniform rods), joints about z, gravity -g along y. ``symbolic=True`` uses
    symbols l1, l2, l3, m1, m2, m3, g for the parameters not given (a keyword given keeps its value)."""
    rows = [DHRow(a=l, inertia=_rod_x(m, l, l / 2, m * l**2 / 12)) for l, m in ((l1, m1), (l2, m2), (l3, m3))]
    return Robot.from_dh(rows, gravity=(0, -g, 0), name="planar_3r", source="textbook planar 3R arm")


@_symbolic_defaults("L1 L2 L3 m1 m2 m3 g radius")
def elbow_3r(L1=3.0, L2=2.0, L3=1.0, m1=1.0, m2=1.0, m3=1.0, g=9.81, radius=0.05, symbolic=False) -> Robot:
    """The tutorial's challenge arm: an elbow (articulated, RRR) manipulator, Spong's DH (Table 3.3):

    ====  =====  ====  ===  =====
    link  theta  d     a    alpha
    1     q1     L1    0    +90 deg
    2     q2     0     L2   0
    3     q3     0     L3   0
    ====  =====  ====  ===  =====

    Base yaw about the vertical z0, shoulder and elbow pitch about horizontal axes; at q = 0 the upper
    arm and forearm point along x0 (Spong's zero pose). Links are uniform solid cylinders of m_i = 1 kg
    (the tutorial gives no masses) and radius ``radius`` = 0.05 m, gravity -g along z0.

    Inertia of each link about its centre (a solid cylinder of mass m, length L, radius r; e.g. Meriam &
    Kraige, Engineering Mechanics: Dynamics, Appendix D): m r^2 / 2 about its own axis and
    m (3 r^2 + L^2) / 12 about the two transverse axes. The radius is kinedyn's choice (the tutorial gives
    none): 5 cm, thin beside the 1-3 m links, so M(q) is within 0.1 % of the thin-rod textbook model, but
    not zero about the rods' own axes. With ``radius=0`` (thin rods, the textbook's m L^2 / 12) M(q) is
    singular wherever the upper arm and forearm both lie on the vertical z0 axis (q2 = +-90 deg, q3 = 0 or
    180 deg): turning about z0 then moves no mass. ``symbolic=True`` uses symbols L1, L2, L3, m1, m2, m3,
    g, radius for the parameters not given (a keyword given keeps its value; ``radius=0`` for the
    textbook's thin rods).
    """
    half_pi = sp.pi / 2 if symbolic else math.pi / 2
    axial = lambda m: m * radius**2 / 2  # noqa: E731
    transverse = lambda m, L: m * (3 * radius**2 + L**2) / 12  # noqa: E731
    # link 1 runs from the base up to frame 1 (along -y1 in frame 1 after Rx(+90 deg)): its own axis is y1
    link1 = Inertia(m1, (0, -L1 / 2, 0), ((transverse(m1, L1), 0, 0), (0, axial(m1), 0), (0, 0, transverse(m1, L1))))
    rows = [
        DHRow(d=L1, alpha=half_pi, inertia=link1),
        DHRow(a=L2, inertia=_rod_x(m2, L2, L2 / 2, transverse(m2, L2), axial(m2))),
        DHRow(a=L3, inertia=_rod_x(m3, L3, L3 / 2, transverse(m3, L3), axial(m3))),
    ]
    return Robot.from_dh(
        rows,
        gravity=(0, 0, -g),
        name="elbow_3r",
        source="METR4202 Tutorial 4 challenge; Spong et al., Robot Modeling and Control, Example 3.5 / Table 3.3",
    )


@_symbolic_defaults("m1 m2 g")
def cartesian_2p(m1=1.0, m2=1.0, g=9.81, symbolic=False) -> Robot:
    """Spong §9.4.1's two-link Cartesian manipulator: joint 1 slides vertically (along z0, against
    gravity), joint 2 slides horizontally (along y0) and is carried by link 1."""
    minus_half_pi = -sp.pi / 2 if symbolic else -math.pi / 2
    rows = [
        DHRow(alpha=minus_half_pi, kind="prismatic", inertia=Inertia(m1)),
        DHRow(kind="prismatic", inertia=Inertia(m2)),
    ]
    return Robot.from_dh(
        rows, gravity=(0, 0, -g), name="cartesian_2p", source="Spong et al., Robot Modeling and Control, §9.4.1"
    )
