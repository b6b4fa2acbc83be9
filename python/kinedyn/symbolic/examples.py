"""The seed's example mechanisms as Lagrangian systems (each derived here from its geometry; the
seed's printed formulas are not copied, several carry misprints — see docs/symbolic.md).

- :func:`remotely_driven_arm`: Spong §9.4, planar elbow with the second joint driven from the base
  through a belt: coordinates p1, p2 are the absolute link angles, not joint angles (bodies written
  here); :func:`remotely_driven_arm_from_robot`: the same from the planar-elbow Robot and its drive
  map q = A p (:func:`kinedyn.symbolic.mechanisms.change_coordinates`).
- :func:`five_bar`: Spong §9.4, the parallelogram five-bar linkage; D is diagonal and constant exactly
  when m3 l2 lc3 = m4 l1 lc4 (bodies written here); :func:`five_bar_chains` /
  :func:`five_bar_from_chains`: the same assembled from two serial Robots and the loop closure
  (:func:`kinedyn.symbolic.mechanisms.closed_chain`).
- :func:`four_bar_linkage`: SymPy mechanics' four-bar (3 relative joint angles, 2 loop-closure
  constraints), solved numerically per evaluation by :meth:`LagrangianSystem.numeric`.
- :func:`sphere_particle`: LaValle Example 13.14, a particle on the unit sphere (holonomic constraint).
- :func:`falling_particle`: LaValle Example 13.11.
- :func:`simple_variational`: LaValle Example 13.10, L = x^3 + xd^2.
- :func:`geared_link`: Spong Example 9.1, one link through an r:1 gear train with rotor inertia J_m,
  and motor damping B_m reflected to the link (r^2 J_m, r^2 B_m); also :func:`geared_link_robot`.
"""

from __future__ import annotations

import sympy as sp

from .derive.system import LagrangianSystem, coordinates

__all__ = [
    "remotely_driven_arm",
    "remotely_driven_arm_from_robot",
    "five_bar",
    "five_bar_chains",
    "five_bar_from_chains",
    "four_bar_linkage",
    "sphere_particle",
    "falling_particle",
    "simple_variational",
    "geared_link",
    "geared_link_robot",
]


def _u(angle):
    return sp.Matrix([sp.cos(angle), sp.sin(angle)])


def remotely_driven_arm() -> LagrangianSystem:
    """Two links in a vertical plane; p1 = angle of link 1, p2 = angle of link 2, both from the x axis
    (the belt from the base motor sets link 2's absolute angle). Centres of mass at lc1 along link 1
    and l1 along link 1 + lc2 along link 2; angular velocities pd1, pd2; gravity -g along y."""
    l1, lc1, lc2, m1, m2, I1, I2, g = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2 g", positive=True)
    (p1, p2), (pd1, pd2) = coordinates("p1 p2")
    bodies = [
        dict(mass=m1, position=lc1 * _u(p1), inertia=I1, angular_velocity=pd1),
        dict(mass=m2, position=l1 * _u(p1) + lc2 * _u(p2), inertia=I2, angular_velocity=pd2),
    ]
    return LagrangianSystem.from_bodies(
        [p1, p2], bodies, gravity=(0, -g), qd=[pd1, pd2], name="remotely driven two-link arm"
    )


def remotely_driven_arm_from_robot():
    """The remotely driven arm from the planar elbow Robot (``planar_2r(symbolic=True)``, joint
    angles q1, q2) and its drive map: the belt sets link 2's absolute angle p2 = q1 + q2, so
    q = A p with A = [[1, 0], [-1, 1]] (p1 = q1). Returns EquationsOfMotion in p1, p2 (D_p = A^T D_q A;
    the same symbols as :func:`remotely_driven_arm`)."""
    from ..robots import planar_2r
    from .derive.mechanisms import change_coordinates

    eom = planar_2r(symbolic=True).equations_of_motion(steps=False)
    return change_coordinates(
        eom, [[1, 0], [-1, 1]], coordinates="p1 p2", name="remotely driven two-link arm (from planar_2r)"
    )


def five_bar_chains():
    """The five-bar of :func:`five_bar` cut open at its far vertex into two serial planar arms (DH
    Robots, joints about z, gravity -g along y), each ending at that vertex:

    - chain a: link 1 (joint q1 at the base, length l1, centre of mass lc1 along it) and link 4
      (joint phi4 at the tip of link 1, relative angle; it reaches the far vertex l2 along it, its
      centre of mass lc4 from the hinge on the other side);
    - chain b: link 2 (joint q2 at the base, length l2, centre of mass lc2) and link 3 (joint phi3
      at the tip of link 2; it reaches the far vertex l1 along it, centre of mass lc3 from the hinge).
    """
    from ..description.dh import DHRow
    from ..description.inertia import Inertia
    from ..robot import Robot

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
    from .derive.mechanisms import closed_chain, loop_closure

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


def five_bar() -> LagrangianSystem:
    """Parallelogram linkage with vertices O, A = l1 u(q1), B = l2 u(q2), A + l2 u(q2) (u(a) = (cos a, sin a)).
    Link 1 (O to A) turns with q1, link 2 (O to B) with q2; link 3 joins B to the far vertex, parallel
    to link 1 (length l1), centre of mass lc3 from B; link 4 is hinged at A, parallel to link 2, and
    carries the far vertex at l2 from A; its centre of mass is lc4 from A on the other side of the
    hinge (a counterweight). Links 1 and 3 turn with q1, links 2 and 4 with q2. Gravity -g along y."""
    l1, l2, lc1, lc2, lc3, lc4, g = sp.symbols("l1 l2 lc1 lc2 lc3 lc4 g", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)
    (q1, q2), (qd1, qd2) = coordinates("q1 q2")
    positions = [lc1 * _u(q1), lc2 * _u(q2), l2 * _u(q2) + lc3 * _u(q1), l1 * _u(q1) - lc4 * _u(q2)]
    omegas = [qd1, qd2, qd1, qd2]
    bodies = [dict(mass=m[i], position=positions[i], inertia=I[i], angular_velocity=omegas[i]) for i in range(4)]
    return LagrangianSystem.from_bodies([q1, q2], bodies, gravity=(0, -g), qd=[qd1, qd2], name="five-bar linkage")


def four_bar_linkage() -> LagrangianSystem:
    """The four-bar of SymPy mechanics' ``test_four_bar_linkage_with_manual_constraints``: uniform
    links of lengths l1..l4 and density rho (mass rho l, inertia rho l^3 / 12 about the centre), link
    1 fixed along x with its centre at the origin, relative joint angles q1, q2, q3 (absolute angles
    q1, q1 + q2, q1 + q2 + q3), no gravity; the loop closes when link 4's far end reaches link 1's
    other end: l1 + sum_k l_k cos(a_k) = 0, sum_k l_k sin(a_k) = 0 (k = 2, 3, 4)."""
    (q1, q2, q3), (qd1, qd2, qd3) = coordinates("q1 q2 q3")
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho", positive=True)
    absolute = [q1, q1 + q2, q1 + q2 + q3]
    rates = [qd1, qd1 + qd2, qd1 + qd2 + qd3]
    joint = sp.Matrix([l1 / 2, 0])
    bodies = []
    for length, angle, rate in zip((l2, l3, l4), absolute, rates):
        bodies.append(
            dict(
                mass=rho * length,
                position=joint + length / 2 * _u(angle),
                inertia=rho * length**3 / 12,
                angular_velocity=rate,
            )
        )
        joint = joint + length * _u(angle)
    closure = joint - sp.Matrix([-l1 / 2, 0])
    return LagrangianSystem.from_bodies(
        [q1, q2, q3], bodies, qd=[qd1, qd2, qd3], holonomic=list(closure), forces=[0, 0, 0], name="four-bar linkage"
    )


def sphere_particle(m=2) -> LagrangianSystem:
    """A particle of mass m on the unit sphere, no gravity: L = m |qd|^2 / 2, g_c = |q|^2 - 1 = 0."""
    q, qd = coordinates("q1 q2 q3")
    K = sp.Rational(1, 2) * m * sum(v**2 for v in qd) if not isinstance(m, float) else 0.5 * m * sum(v**2 for v in qd)
    return LagrangianSystem(
        q, K=K, P=0, qd=qd, holonomic=[sum(x**2 for x in q) - 1], forces=[0, 0, 0], name="particle on a sphere"
    )


def falling_particle() -> LagrangianSystem:
    """A particle of mass m in R^3 with gravity -g along q3: K = m |qd|^2 / 2, P = m g q3."""
    m, g = sp.symbols("m g", positive=True)
    q, qd = coordinates("q1 q2 q3")
    return LagrangianSystem(
        q, K=m * sum(v**2 for v in qd) / 2, P=m * g * q[2], qd=qd, forces=[0, 0, 0], name="falling particle"
    )


def simple_variational() -> LagrangianSystem:
    """L(x, xd) = x^3 + xd^2: the Euler-Lagrange equation is 2 xdd - 3 x^2 = 0."""
    (x,), (xd,) = coordinates("x")
    return LagrangianSystem([x], L=x**3 + xd**2, qd=[xd], forces=[0], name="simple variational problem")


def geared_link() -> LagrangianSystem:
    """One link (inertia J_l about its joint, mass M, centre of mass ell from the joint) driven
    through an r:1 gear (theta_m = r theta) by a motor of rotor inertia J_m, motor torque tau_m and
    motor viscous damping B_m. Coordinate: the link angle theta (theta = 0 hanging down).
    K = J_m (r thetad)^2 / 2 + J_l thetad^2 / 2; P = M g ell (1 - cos theta); the motor's torque
    and damping reach the link through the gear by virtual work: u = r tau_m, B = r^2 B_m thetad."""
    J_l, J_m, M, g, ell, r, B_m, tau_m = sp.symbols("J_l J_m M g ell r B_m tau_m", positive=True)
    (th,), (thd,) = coordinates("theta")
    K = J_m * (r * thd) ** 2 / 2 + J_l * thd**2 / 2
    P = M * g * ell * (1 - sp.cos(th))
    return LagrangianSystem(
        [th], K=K, P=P, qd=[thd], forces=[r * tau_m], B=[r**2 * B_m * thd], name="geared single link"
    )


def geared_link_robot(J_l=None, J_m=None, M=None, g=None, ell=None, r=None, B_m=None):
    """The same single link as a :class:`kinedyn.Robot` (a revolute joint about z with gear_ratio r,
    rotor_inertia J_m, viscous friction r^2 B_m at the joint); symbols by default. The link's frame
    has x along the link; gravity -g along y, so theta = 0 points along +x (P = M g ell sin theta)."""
    from ..description.inertia import Inertia
    from ..description.joint import Joint
    from ..description.link import Link
    from ..robot import Robot

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
