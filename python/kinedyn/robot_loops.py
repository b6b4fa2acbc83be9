"""The closed-loop half of the ``Robot`` facade: the loops a robot declares and the methods that
respect them (docs/architecture.md, the layers). ``Robot`` inherits :class:`ClosedLoops`; each method
here is a one-line forward to the capability that does the work, as in ``kinedyn.robot``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from . import closed_loops
from .description.loops import Loop

if TYPE_CHECKING:
    from .description.description import Description
    from .robot import Robot

__all__ = ["ClosedLoops"]


class ClosedLoops:
    """Closed kinematic loops of a robot (LaValle 13.4): constraints between two frames of its tree."""

    @property
    def loops(self) -> tuple:
        """The robot's closed loops (:class:`~kinedyn.description.loops.Loop`: name, the two frames,
        kind, ``rows``); empty for a tree."""
        return self.description.loops

    description: Description  # the Robot's own (kinedyn.robot)
    _model: Any  # the Robot's compiled native model (kinedyn.robot, a cached property there)

    def add_loop(self, frame_a: str, frame_b: str, kind: str = "point", name: str | None = None) -> Robot:
        """A new robot with a loop closing ``frame_a`` on ``frame_b``: ``kind="point"`` makes their
        origins coincide (3 rows), ``"weld"`` the frames whole (6 rows). ``name`` defaults to
        ``"loop<k>"``."""
        if name is None:
            taken = {loop.name for loop in self.loops}
            name = next(f"loop{k}" for k in range(len(taken) + 1) if f"loop{k}" not in taken)
        return self.replace(loops=self.loops + (Loop(name, frame_a, frame_b, kind),))  # type: ignore[attr-defined]

    # ---- the numbers (kinedyn.closed_loops; docs/closed-loops.md, "The numbers") ----
    def loop_residual(self, q):
        """The closure error r(q), (m,) or (N, m), m = sum of the loops' rows, base axes: per loop
        ``p_a - p_b`` and, for a weld, the rotation vector ``R_b log3(R_b^T R_a)``. Zero where closed."""
        return closed_loops.loop_residual(self.description, self._model, q)

    def loop_jacobian(self, q):
        """J(q), (m, nv) or (N, m, nv): ``J qd`` is frame a's velocity relative to frame b in base
        axes (linear, then angular for a weld); the derivative of :meth:`loop_residual` where closed."""
        return closed_loops.loop_jacobian(self.description, self._model, q)

    def loop_gamma(self, q, qd):
        """``gamma = dJ/dt qd``, (m,) or (N, m): a closed motion has ``J qdd + gamma = 0``."""
        return closed_loops.loop_gamma(self.description, self._model, q, qd)

    def constrained_forward_dynamics(self, q, qd, tau, f_ext=None):
        """``(qdd, lam)`` of ``M qdd + h = tau + J^T lam``, ``J qdd + gamma = 0`` (proximal KKT solve,
        Carpentier et al. RSS 2021), one state or a batch. ``lam`` (m,): the force (then moment, for
        a weld) the loop applies to frame a's link, base axes, about frame a's origin; frame b's link
        gets the opposite. ``f_ext`` as in :meth:`forward_dynamics`. ValueError where the loops
        cannot all hold (a singular configuration, a state far from closed)."""
        return closed_loops.constrained_forward_dynamics(self.description, self._model, q, qd, tau, f_ext)

    def constrained_inverse_dynamics(self, q, qd, qdd, actuated, f_ext=None):
        """Torques (nv,) or (N, nv), zero off the ``actuated`` joints (names), that produce the closed
        motion ``qdd``. ValueError when ``qdd`` does not keep a loop closed, when the actuators cannot
        produce the motion, or when they do not determine their torques."""
        return closed_loops.constrained_inverse_dynamics(self.description, self._model, q, qd, qdd, actuated, f_ext)

    def project_configuration(self, q, hold=None, tolerance=1e-12, max_iter=50):
        """A configuration near ``q`` that closes the loops (Gauss-Newton, least-norm steps), the
        ``hold`` joints (names) fixed: with ``hold`` = the actuated joints, the forward kinematics of
        a parallel robot. ValueError naming the loop left open."""
        return closed_loops.project_configuration(self.description, self._model, q, hold, tolerance, max_iter)

    def project_velocity(self, q, qd):
        """The velocity nearest ``qd`` (Euclidean) that keeps the loops closed: ``qd - J^+ J qd``."""
        return closed_loops.project_velocity(self.description, self._model, q, qd)

    def independent_joints(self, q) -> list:
        """Names of 1-DOF joints that are independent coordinates of the loops at the closed
        configuration ``q`` (nearest the base first: a parallel mechanism's motors): holding them
        (``project_configuration(q, hold=...)``) fixes the other 1-DOF joints. As many as the
        mechanism's degrees of freedom, fewer when some of its freedom is in multi-DOF joints."""
        return closed_loops.independent_joints(self.description, self._model, q)

    def reduced_dynamics(self, q, qd_independent, independent=None):
        """The equations of motion in independent coordinates at one closed state (coordinate
        partitioning): ``qd = G qd_i``, ``qdd = G qdd_i + a0`` and ``M_r qdd_i + bias + g_r = G^T tau``
        as a dict of ``G``, ``M``, ``bias``, ``g``, ``a0``, ``qd``, ``independent`` (velocity
        columns). ``independent``: joint names, or None to choose them from J by pivoted QR."""
        return closed_loops.reduced_dynamics(self.description, self._model, q, qd_independent, independent)
