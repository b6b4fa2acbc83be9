"""Type stubs of the native module built from crates/kinedyn-py (PyO3 + rust-numpy).

Every state argument (q, qd, qdd, tau) is a float64 array of shape (n,) or a batch (N, n); a batch
returns the stacked results, computed in one native call with the GIL released. Shapes and finiteness
are checked at the boundary and reported as ValueError naming the argument (complex numbers and text:
TypeError). Finite inputs with a non-finite result raise NonFiniteResultError naming the quantity (and
the state of a batch); a result that cannot be allocated raises MemoryError naming its bytes; a panic
of the native code (a bug) raises RuntimeError naming the binding, never pyo3's PanicException.
Batches run in a thread pool rebuilt in a forked child, so they work after ``fork``.
``reference``: "world" (LOCAL_WORLD_ALIGNED), "local" or "spatial" (WORLD).
"""

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]  # stub-only type aliases (not in the compiled module)
I64 = NDArray[np.int64]

class Model:
    def __init__(
        self,
        # one record per joint, parents before children, each a mapping taken whole (the core's
        # ModelBuilder expands a multi-DOF joint into one body per degree of freedom):
        #   name: str; kind: "revolute" | "continuous" | "prismatic" | "floating" | "spherical" | "planar";
        #   placement: (4, 4) parent link frame -> joint frame at q = 0;
        #   parent: int = -1 (an earlier joint's index, -1 = base);
        #   axis: (3,) unit axis (the planar joint's normal; not read for floating and spherical);
        #   inertia: (10,) = 0, [m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] of the link about its frame origin;
        #   offset, armature (r^2 J_m), viscous, coulomb: float = 0 (1-DOF joints only);
        #   coulomb_negative: float | None = None, the Coulomb level for qd < 0 when it differs;
        #   link_origin: (3,) | None = None, the link frame's origin in the joint frame (f_ext's moments about it)
        joints: Sequence[Mapping[str, object]],
        gravity: F64,  # (3,) in base coordinates
        frames: Sequence[tuple[int, F64]] = (),  # (joint index, -1 = base; (4, 4) link frame -> named frame)
    ) -> None: ...
    # the model with f_ext's moments taken about link-frame origins: (n, 3), each body's link-frame
    # origin in its body frame (zero: the body origin; the records' link_origin set them)
    def with_link_origins(self, origins: F64) -> Model: ...
    def with_loops(self, loops: list[tuple[int, int, str, str]]) -> Model: ...
    # closed loops (frame_a, frame_b, kind "point" | "weld", name), checked by the core
    @property
    def loop_rows(self) -> int: ...  # m: 3 per point loop, 6 per weld
    def loop_residual(self, q: F64) -> F64: ...  # (m,) | (N, m), base axes
    def loop_jacobian(self, q: F64) -> F64: ...  # (m, n) | (N, m, n)
    def loop_gamma(self, q: F64, qd: F64) -> F64: ...  # (m,) | (N, m), dJ/dt qd
    def constrained_forward_dynamics(
        self, q: F64, qd: F64, tau: F64, f_ext: F64 | None = None
    ) -> F64: ...  # [qdd; lambda] (n + m,) | (N, n + m)
    def constrained_inverse_dynamics(
        self, q: F64, qd: F64, qdd: F64, actuated: list[int], f_ext: F64 | None = None
    ) -> F64: ...  # tau (n,) | (N, n), zero off the actuated velocity columns
    def project_configuration(
        self, q: F64, hold: list[int], tolerance: float, max_iter: int
    ) -> F64: ...  # (nq,) | (N, nq)
    def project_velocity(self, q: F64, qd: F64) -> F64: ...  # (n,) | (N, n)
    @property
    def link_bodies(self) -> I64: ...  # (links,) the body that carries each link (a multi-DOF joint's last)
    @property
    def n(self) -> int: ...  # bodies = degrees of freedom (nv)
    @property
    def nq(self) -> int: ...  # length of a configuration q
    @property
    def n_frames(self) -> int: ...
    # ---- kinematics (issue 2) ----
    def frame_poses(self, q: F64, frames: I64) -> F64: ...  # (k, 4, 4) | (N, k, 4, 4)
    def frame_pose(self, q: F64, frame: int) -> F64: ...  # (4, 4) | (N, 4, 4)
    def jacobian(self, q: F64, frame: int, reference: str, point: F64 | None = None) -> F64: ...  # (6, n) | (N, 6, n)
    def jacobian_hessian(
        self, q: F64, frame: int, reference: str, point: F64 | None = None
    ) -> F64: ...  # (n, 6, n) | (N, n, 6, n), H[i, r, j] = dJ[r, j]/dq_i
    def frame_velocity(
        self, q: F64, qd: F64, frame: int, reference: str, point: F64 | None = None
    ) -> F64: ...  # (6,) | (N, 6)
    def jdot_qd(
        self, q: F64, qd: F64, frame: int, reference: str, point: F64 | None = None
    ) -> F64: ...  # (6,) | (N, 6)
    # ---- dynamics (issue 3) ----
    # f_ext: (links, 6) | (N, links, 6), one [force; moment] per link (the core places it on the body that
    # carries the link), base axes, moment about the link-frame origin; one (links, 6) set serves a whole batch.
    # A singular mass matrix (forward_dynamics, mass_matrix_inverse) raises RuntimeError naming the joint.
    def inverse_dynamics(
        self, q: F64, qd: F64, qdd: F64, f_ext: F64 | None = None, out: F64 | None = None
    ) -> F64: ...  # (n,) | (N, n)
    def mass_matrix(self, q: F64, out: F64 | None = None) -> F64: ...  # (n, n) | (N, n, n)
    def mass_matrix_inverse(self, q: F64, out: F64 | None = None) -> F64: ...  # (n, n) | (N, n, n)
    def forward_dynamics(
        self, q: F64, qd: F64, tau: F64, f_ext: F64 | None = None, out: F64 | None = None
    ) -> F64: ...  # (n,) | (N, n)
    def coriolis_matrix(self, q: F64, qd: F64, out: F64 | None = None) -> F64: ...  # (n, n) | (N, n, n)
    def christoffel(self, q: F64) -> F64: ...  # (n, n, n) | (N, n, n, n), c[i, j, k]
    def gravity_torque(self, q: F64, out: F64 | None = None) -> F64: ...  # (n,) | (N, n)
    def bias_torque(self, q: F64, qd: F64, out: F64 | None = None) -> F64: ...  # (n,) | (N, n), C qd + g
    def kinetic_energy(self, q: F64, qd: F64) -> float | F64: ...  # a float | (N,)
    def potential_energy(self, q: F64) -> float | F64: ...  # a float | (N,)
    def inverse_dynamics_derivatives(
        self, q: F64, qd: F64, qdd: F64, f_ext: F64 | None = None
    ) -> tuple[F64, F64, F64]: ...
    # (dtau/dq, dtau/dqd, M), each (n, n) | (N, n, n): analytical derivatives of the RNEA
    def forward_dynamics_derivatives(
        self, q: F64, qd: F64, tau: F64, f_ext: F64 | None = None
    ) -> tuple[F64, F64, F64]: ...
    # (dqdd/dq, dqdd/dqd, M^-1), each (n, n) | (N, n, n): derivatives of the ABA
    def regressor(self, q: F64, qd: F64, qdd: F64) -> F64: ...  # (n, 10 n) | (N, n, 10 n)
    def center_of_mass(self, q: F64) -> F64: ...  # (3,) | (N, 3)
    def momentum(self, q: F64, qd: F64) -> F64: ...  # (6,) | (N, 6), [p; L about the base origin]
    def centroidal_momentum_matrix(self, q: F64) -> F64: ...  # (6, n) | (N, 6, n), h_G = A_G qd

class SingularMassMatrixError(RuntimeError):
    """Forward dynamics or M^-1 undefined at a state: the pivot of degree of freedom ``joint`` failed."""

    joint: int  # the native body (degree of freedom) whose pivot failed
    overflow: bool  # numbers too large for float64 (finite inputs), not a physically singular M
    message: str  # the core's message, without the "singular mass matrix: " prefix

class NonFiniteResultError(FloatingPointError, ValueError):
    """Finite inputs gave a non-finite result (the numbers overflowed float64)."""

def planar_basis(
    normal: F64,
) -> tuple[tuple[float, float, float], tuple[float, float, float]]: ...  # (e1, e2), e1 x e2 = normal
def simd() -> tuple[str, int]: ...  # (kind, states per block) of batches: "avx512" | "avx2" | "portable" | "off"
def _debug_panic(message: str = ..., in_worker: bool = False) -> None:
    """TEST-ONLY: panics inside a guarded binding (on a batch worker thread if ``in_worker``), to
    check that a panic reaches Python as a RuntimeError."""

def _set_check_finite(on: bool) -> bool:
    """BENCHMARK-ONLY: turns the non-finite scan of batch results on or off; returns the previous
    setting (benches/bench_finite_check.py)."""

# ---- inverse kinematics (crates/kinedyn-py/src/ik.rs) ----
def solve_ik(
    model: Model,
    frame: int,
    targets: F64,  # (4, 4) pose or (3,) position, or a batch (N, 4, 4) | (N, 3)
    q0: F64,  # (nq,) | (N, nq): configurations (reduced ones with `reduction`), unit quaternions
    lower: F64,  # (nq,), infinite on a multi-DOF joint's entries
    upper: F64,  # (nq,)
    weights: F64,  # (6,) for [x, y, z, rx, ry, rz]
    max_iterations: int = 50,
    restarts: int = 50,
    position_tolerance: float = 1e-10,
    orientation_tolerance: float = 1e-10,
    lambda_min: float = 1e-06,
    max_step: float = 0.5,
    seed: int = 0,
    first_index: int = 0,  # index of targets[0] in the whole batch (each target's random restarts follow from seed and its index)
    # reduced mimic coordinates: (q_source (nq_full,), q_multiplier, q_offset, v_source (nv_full,), v_multiplier, q_keep (nq,), nv)
    reduction: tuple[list[int], list[float], list[float], list[int], list[float], list[int], int] | None = None,
) -> tuple[
    Any, Any, Any, Any, Any
]: ...  # (q, success, position_error, orientation_error, iterations), leading N for a batch

class AnalyticIk:
    """A closed-form solver detected from a model's geometry (None from ``detect`` when there is none)."""
    @staticmethod
    def detect(model: Model, frame: int, lower: F64, upper: F64) -> AnalyticIk | None: ...
    @property
    def structure(self) -> str: ...  # e.g. "spherical_wrist"
    @property
    def arm(self) -> str | None: ...  # the arm of a spherical-wrist chain
    @property
    def solves_position(self) -> bool: ...  # whether (3,) position targets have a closed form
    def solve(
        self, target: F64, reference: F64, respect_limits: bool = True, tolerance: float = 1e-09
    ) -> tuple[F64, F64, F64, int, bool]: ...
    # (solutions (m, n) nearest reference first, position errors (m,), orientation errors (m,), found before the limit filter, singular)
    def solve_nearest(
        self, targets: F64, references: F64, respect_limits: bool = True, tolerance: float = 1e-09
    ) -> tuple[F64, NDArray[np.bool_], F64, F64]: ...
    # (q (N, n), success (N,), position errors (N,), orientation errors (N,)); q is NaN where no solution exists
    @property
    def max_solutions(self) -> int: ...  # the most real solutions the structure has for one target
    def solve_stated(
        self, target: F64, reference: F64, respect_limits: bool = True, tolerance: float = 1e-09
    ) -> tuple[F64, F64, F64, int, bool, int, float, bool]: ...
    # solve's tuple, then max_solutions, worst residual, merged (the statement of completeness)
    def solve_all(
        self, targets: F64, references: F64, respect_limits: bool = True, tolerance: float = 1e-09
    ) -> tuple[F64, I64, F64, F64, I64, NDArray[np.bool_], I64, F64, NDArray[np.bool_]]: ...
    # every solution of each target: (q (N, B, n) NaN-padded, count (N,), position errors (N, B),
    # orientation errors (N, B), found (N,), singular (N,), max_solutions (N,), worst residual (N,), merged (N,))

class RedundantIk:
    """A seven-joint chain's closed forms: a held joint ("held") or an SRS arm's arm angle ("arm_angle")."""
    @staticmethod
    def detect(model: Model, frame: int, lower: F64, upper: F64) -> RedundantIk | None: ...
    @property
    def srs(self) -> bool: ...
    def held_structure(self, joint: int, value: float) -> str | None: ...
    def arm_angle(self, q: F64) -> float | None: ...
    def solve(
        self,
        target: F64,
        mode: str,
        joint: int,
        value: float,
        reference: F64,
        respect_limits: bool = True,
        tolerance: float = 1e-09,
    ) -> tuple[F64, F64, F64, int, bool, int, float, bool]: ...  # as AnalyticIk.solve_stated
    def solve_batch(
        self,
        targets: F64,
        mode: str,
        joint: int,
        values: F64,
        references: F64,
        respect_limits: bool = True,
        tolerance: float = 1e-09,
    ) -> tuple[F64, I64, F64, F64, I64, NDArray[np.bool_], I64, F64, NDArray[np.bool_]]: ...  # as AnalyticIk.solve_all
    def sweep(
        self, target: F64, mode: str, joint: int, values: F64, reference: F64, tolerance: float = 1e-09
    ) -> tuple[F64, NDArray[np.bool_]]: ...  # (q (M, B, 7) per branch slot, NaN where absent; singular (M,))
    def arm_angle_intervals(
        self, target: F64, lo: float, hi: float
    ) -> list[list[tuple[float, float]]] | None: ...  # per branch slot (8), the arm-angle intervals inside the limits

# ---- fixed-step integration (crates/kinedyn-py/src/simulate.rs) ----
# Both return (q, qd, qdd, tau, steps, failures): arrays (samples, n) | (N, samples, n), steps (N,) int64,
# failures a list with None or {"step", "t", "joint", "kind", "value", "message"} per trajectory.
def integrate_fixed(
    model: Model,
    method_name: str,  # "rk4" | "implicit" | "semi_implicit" | "euler"
    q0: F64,
    qd0: F64,
    t0: float,
    dt: float,
    steps: int,
    tau: F64 | None = None,  # None, (S, n) or (N, S, n)
    linear: bool = False,
    record_every: int = 1,
    max_speed: float = 1e6,
    lower: F64 | None = None,  # (n,) joint position limits: inelastic stops when given
    upper: F64 | None = None,
    f_ext: F64 | None = None,  # (links, 6) constant external wrenches per link (as Model.inverse_dynamics)
) -> tuple[F64, F64, F64, F64, I64, list[dict[str, Any] | None]]: ...
def integrate_callback(
    model: Model,
    method_name: str,
    q0: F64,
    qd0: F64,
    t0: float,
    dt: float,
    steps: int,
    callback: Callable[[int, float, F64, F64], Sequence[float]],  # (step, t, q, qd) -> tau
    hold: bool = False,
    record_every: int = 1,
    max_speed: float = 1e6,
    jacobian: Callable[[int, float, F64, F64], Any]
    | None = None,  # (step, t, q, qd) -> (dtau/dq, dtau/dqd) (n, n) each, or None
    lower: F64 | None = None,
    upper: F64 | None = None,
    # external wrenches per link: None, (links, 6) constant, or (t, q, qd) -> (links, 6) at every stage
    f_ext: F64 | Callable[[float, F64, F64], F64] | None = None,
) -> tuple[F64, F64, F64, F64, I64, list[dict[str, Any] | None]]: ...

# the core's Lie-group operations per joint block ("floating", "spherical", "planar", "" for 1-DOF):
def lie_integrate(names: Sequence[str], q: F64, v: F64) -> F64: ...  # q (..., nq), v (..., nv) -> q ⊕ v
def lie_difference(names: Sequence[str], q0: F64, q1: F64) -> F64: ...  # (..., nq) x2 -> v with q0 ⊕ v = q1

# their Jacobians, block diagonal (..., nv, nv) each: (d/dq, d/dv) of q ⊕ v dt; (d/dq0, d/dq1) of the difference
def lie_integrate_jacobians(names: Sequence[str], v: F64, dt: float) -> tuple[F64, F64]: ...
def lie_difference_jacobians(names: Sequence[str], q0: F64, q1: F64) -> tuple[F64, F64]: ...

# (Ad(Exp(tau)), Jl(tau), Jl(tau)^-1) of one joint kind's group at tangent vectors tau (..., nv)
def lie_group_jacobians(kind: str, tau: F64) -> tuple[F64, F64, F64]: ...

# SO(3) on unit quaternions (x, y, z, w): op "multiply", "rotate", "matrix", "exp", "log"
def lie_quaternion(op: str, a: F64, b: F64 | None = None) -> F64: ...

# a joint's motion joint_from_body (4, 4) at its q block (kind and axis as in a joint record)
def joint_transform(kind: str, axis: F64 | None, q: F64) -> F64: ...

# robot-specialised programs (kinedyn.codegen): the algorithms that can be recorded, the operation
# counts of one recorded for a model (recorded, optimized: dicts of add, mul, div, neg, sincos, select,
# add_mul), and the C or Rust source of kinedyn_<robot>_<algorithm> for each of algorithms
def trace_algorithms() -> list[str]: ...
def trace_counts(model: Model, algorithm: str) -> tuple[dict[str, int], dict[str, int]]: ...
def trace_source(model: Model, robot: str, algorithms: Sequence[str], language: str, version: str) -> str: ...
