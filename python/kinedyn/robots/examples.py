"""The seed's example mechanisms built from :class:`kinedyn.Robot`s (the Lagrangian-system ones, written
from their bodies, are in :mod:`kinedyn.symbolic.examples`; docs/symbolic.md, "The seed's mechanisms").

- :func:`remotely_driven_arm_from_robot`: Spong §9.4's remotely driven arm from the planar-elbow Robot
  and its drive map q = A p (:func:`kinedyn.symbolic.mechanisms.change_coordinates`).
- :func:`five_bar_chains` / :func:`five_bar_from_chains`: the five-bar assembled from two serial DH
  Robots and the loop closure (:func:`kinedyn.symbolic.mechanisms.closed_chain`).
- :func:`geared_link_robot`: Spong Example 9.1's geared link as a Robot.
- :func:`five_bar_robot`, :func:`four_bar_robot`: the five-bar and SymPy mechanics' four-bar as one
  Robot each, a tree of Links closed by a point loop (``robot.equations_of_motion()`` gives their
  multiplier and reduced forms; docs/closed-loops.md, "The equations").
"""

from __future__ import annotations

import sympy as sp

from ..description.dh import DHRow
from ..description.inertia import Inertia
from ..description.joint import Joint
from ..description.link import Frame, Link
from ..description.loops import Loop
from ..robot import Robot
from ..symbolic.systems.mechanisms import change_coordinates, closed_chain, loop_closure
from .basic import planar_2r

__all__ = [
    "remotely_driven_arm_from_robot",
    "five_bar_chains",
    "five_bar_from_chains",
    "geared_link_robot",
    "five_bar_robot",
    "four_bar_robot",
]


def remotely_driven_arm_from_robot():
    """The remotely driven arm from the planar elbow Robot (``planar_2r(symbolic=True)``, joint
    angles q1, q2) and its drive map: the belt sets link 2's absolute angle p2 = q1 + q2, so
    q = A p with A = [[1, 0], [-1, 1]] (p1 = q1). Returns EquationsOfMotion in p1, p2 (D_p = A^T D_q A;
    the same symbols as :func:`kinedyn.symbolic.examples.remotely_driven_arm`)."""
    eom = planar_2r(symbolic=True).equations_of_motion(steps=False)
    return change_coordinates(
        eom, [[1, 0], [-1, 1]], coordinates="p1 p2", name="remotely driven two-link arm (from planar_2r)"
    )


def five_bar_chains():
    """The five-bar of :func:`kinedyn.symbolic.examples.five_bar` cut open at its far vertex into two serial planar arms (DH
    Robots, joints about z, gravity -g along y), each ending at that vertex:

    - chain a: link 1 (joint q1 at the base, length l1, centre of mass lc1 along it) and link 4
      (joint phi4 at the tip of link 1, relative angle; it reaches the far vertex l2 along it, its
      centre of mass lc4 from the hinge on the other side);
    - chain b: link 2 (joint q2 at the base, length l2, centre of mass lc2) and link 3 (joint phi3
      at the tip of link 2; it reaches the far vertex l1 along it, centre of mass lc3 from the hinge).
    """
    l1, l2, lc1, lc2, lc3, lc4, g = sp.symbols("l1 l2 lc1 lc2 lc3 lc4 g", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)

    def link(mass, x_com, inertia):  # centre of mass on the DH x axis (frame i at link i's far end)
        return Inertia(mass, (x_com, 0, 0), ((0, 0, 0), (0, inertia, 0), (0, 0, inertia)))

    chain_a = Robot.from_dh(
        [
            DHRow(a=l1, name="q1", inertia=link(m[0], lc1 - l1, I[0])),
            DHRow(a=l2, name="phi4", inertia=link(m[3], -l2 - lc4, I[3])),
        ],
        gravity=(0, -g, 0),
        name="five-bar chain a (links 1, 4)",
    )
    chain_b = Robot.from_dh(
        [
            DHRow(a=l2, name="q2", inertia=link(m[1], lc2 - l2, I[1])),
            DHRow(a=l1, name="phi3", inertia=link(m[2], lc3 - l1, I[2])),
        ],
        gravity=(0, -g, 0),
        name="five-bar chain b (links 2, 3)",
    )
    return chain_a, chain_b


def five_bar_from_chains():
    """The five-bar's reduced equations in q1, q2 from :func:`five_bar_chains` and the loop closure
    (their tool points coincide), on the parallelogram branch phi4 = q2 - q1, phi3 = q1 - q2 (links
    4 and 3 parallel to links 2 and 1)."""
    chain_a, chain_b = five_bar_chains()
    closure = loop_closure(chain_a, chain_b)
    q1, phi4, q2, phi3 = sp.symbols("q1 phi4 q2 phi3", real=True)
    return closed_chain(
        [chain_a, chain_b],
        closure,
        independent=[q1, q2],
        solution={phi4: q2 - q1, phi3: q1 - q2},
        name="five-bar linkage (from two chains)",
    )


def geared_link_robot(J_l=None, J_m=None, M=None, g=None, ell=None, r=None, B_m=None):
    """The same single link as a :class:`kinedyn.Robot` (a revolute joint about z with gear_ratio r,
    rotor_inertia J_m, viscous friction r^2 B_m at the joint); symbols by default. The link's frame
    has x along the link; gravity -g along y, so theta = 0 points along +x (P = M g ell sin theta)."""
    names = "J_l J_m M g ell r B_m"
    syms = dict(zip(names.split(), sp.symbols(names, positive=True)))
    vals = dict(J_l=J_l, J_m=J_m, M=M, g=g, ell=ell, r=r, B_m=B_m)
    v = {k: (syms[k] if vals[k] is None else vals[k]) for k in syms}
    # inertia about the centre of mass: J_l - M ell^2 about z (parallel-axis theorem)
    Izz = v["J_l"] - v["M"] * v["ell"] ** 2
    link = Link(
        "link",
        None,
        Joint(
            "theta", "revolute", (0, 0, 1), gear_ratio=v["r"], rotor_inertia=v["J_m"], viscous=v["r"] ** 2 * v["B_m"]
        ),
        inertia=Inertia(v["M"], (v["ell"], 0, 0), ((0, 0, 0), (0, Izz, 0), (0, 0, Izz))),
    )
    return Robot([link], gravity=(0, -v["g"], 0), name="geared_link")


def _along_x(x) -> sp.Matrix:
    """The homogeneous translation by x along the x axis."""
    T = sp.eye(4)
    T[0, 3] = x
    return T


def _rod(mass, x_com, inertia):
    """A planar link's mass properties: centre of mass on its x axis, ``inertia`` about the centre
    for turns about y and z (a thin rod along x)."""
    return Inertia(mass, (x_com, 0, 0), ((0, 0, 0), (0, inertia, 0), (0, 0, inertia)))


def five_bar_robot() -> Robot:
    """The five-bar of :func:`kinedyn.symbolic.examples.five_bar` as one Robot: a tree of two planar
    arms from the base (joints about z, gravity -g along y) closed by a point loop at the far vertex.

    - link1 (joint q1 at the base, length l1, centre of mass lc1 along it), then link4 (joint phi4 at
      link 1's tip, relative angle; the far vertex is l2 along it, frame ``vertex_a``; its centre of
      mass lc4 from the hinge on the other side, a counterweight);
    - link2 (joint q2 at the base, length l2, centre of mass lc2), then link3 (joint phi3 at link 2's
      tip; the far vertex l1 along it, frame ``vertex_b``; centre of mass lc3 from the hinge);
    - the loop ``far_vertex`` makes ``vertex_a`` and ``vertex_b`` coincide.

    Coordinates (q1, phi4, q2, phi3); on the parallelogram branch phi4 = q2 - q1, phi3 = q1 - q2."""
    l1, l2, lc1, lc2, lc3, lc4, g = sp.symbols("l1 l2 lc1 lc2 lc3 lc4 g", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)
    z = (0, 0, 1)
    links = [
        Link("link1", None, Joint("q1", "revolute", z), inertia=_rod(m[0], lc1, I[0])),
        Link("link4", "link1", Joint("phi4", "revolute", z), placement=_along_x(l1), inertia=_rod(m[3], -lc4, I[3])),
        Link("link2", None, Joint("q2", "revolute", z), inertia=_rod(m[1], lc2, I[1])),
        Link("link3", "link2", Joint("phi3", "revolute", z), placement=_along_x(l2), inertia=_rod(m[2], lc3, I[2])),
    ]
    frames = [Frame("vertex_a", "link4", _along_x(l2)), Frame("vertex_b", "link3", _along_x(l1))]
    return Robot(
        links,
        frames,
        gravity=(0, -g, 0),
        tool="vertex_a",
        name="five-bar linkage",
        loops=[Loop("far_vertex", "vertex_a", "vertex_b", "point")],
    )


def four_bar_robot(gravity: bool = False) -> Robot:
    """SymPy mechanics' four-bar (:func:`kinedyn.symbolic.examples.four_bar_linkage`) as one Robot:
    the ground link (length l1) is the base, centred on its origin along x; link2, link3, link4
    (lengths l2, l3, l4, uniform, density rho: mass rho l, inertia rho l^3 / 12 about the centre)
    hang in a chain from its right end (l1/2, 0, 0) on joints q1, q2, q3 about z (relative angles).
    The loop ``closure`` pins link 4's far end (frame ``tip``) to the ground link's left end (frame
    ``anchor`` on the base, at (-l1/2, 0, 0)). ``gravity=True``: gravity -g along y (SymPy's test
    has none)."""
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho", positive=True)
    z = (0, 0, 1)

    def bar(length):
        return _rod(rho * length, length / 2, rho * length**3 / 12)

    links = [
        Link("link2", None, Joint("q1", "revolute", z), placement=_along_x(l1 / 2), inertia=bar(l2)),
        Link("link3", "link2", Joint("q2", "revolute", z), placement=_along_x(l2), inertia=bar(l3)),
        Link("link4", "link3", Joint("q3", "revolute", z), placement=_along_x(l3), inertia=bar(l4)),
    ]
    frames = [Frame("tip", "link4", _along_x(l4)), Frame("anchor", None, _along_x(-l1 / 2))]
    g = sp.Symbol("g", positive=True) if gravity else 0
    return Robot(
        links,
        frames,
        gravity=(0, -g, 0),
        tool="tip",
        name="four-bar linkage",
        loops=[Loop("closure", "tip", "anchor", "point")],
    )
