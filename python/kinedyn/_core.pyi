"""Type stubs of the native module built from crates/kinedyn-py (PyO3 + rust-numpy).

Every state argument (q, qd, qdd, tau) is a float64 array of shape (n,) or a batch (N, n); a batch
returns the stacked results, computed in one native call with the GIL released. Shapes and finiteness
are checked at the boundary and reported as ValueError naming the argument (complex numbers and text:
TypeError). Finite inputs with a non-finite result raise NonFiniteResultError naming the quantity (and
the state of a batch); a result that cannot be allocated raises MemoryError naming its bytes; a panic
of the native code (a bug) raises RuntimeError naming the binding, never pyo3's PanicException.
Batches run in a thread pool rebuilt in a forked child, so they work after ``fork``.
``reference``: 0 = "world" (LOCAL_WORLD_ALIGNED), 1 = "local", 2 = "spatial" (WORLD).
"""

from typing import Optional

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

class Model:
    def __init__(
        self,
        parent: I64,  # (n,) parent body index, -1 = base, parent[i] < i
        kind: I64,  # (n,) 0 = revolute, 1 = prismatic
        axis: F64,  # (n, 3) unit joint axis in the joint frame
        offset: F64,  # (n,) joint offset added to q
        placement: F64,  # (n, 4, 4) parent body frame -> joint frame at q = 0
        inertia: F64,  # (n, 10) [m, mc, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the body-frame origin
        armature: F64,  # (n,) reflected rotor inertia r^2 J_m
        viscous: F64,  # (n,)
        coulomb: F64,  # (n,)
        gravity: F64,  # (3,) in base coordinates
        frame_body: I64,  # (nf,) body of each named frame, -1 = base
        frame_placement: F64,  # (nf, 4, 4) body frame -> named frame
    ) -> None: ...
    @property
    def n(self) -> int: ...
    @property
    def n_frames(self) -> int: ...
    # ---- kinematics (issue 2) ----
    def frame_poses(self, q: F64, frames: I64) -> F64: ...  # (k, 4, 4) | (N, k, 4, 4)
    def jacobian(self, q: F64, frame: int, reference: int, point: Optional[F64] = None) -> F64: ...  # (6, n) | (N, 6, n)
    def frame_velocity(self, q: F64, qd: F64, frame: int, reference: int, point: Optional[F64] = None) -> F64: ...  # (6,) | (N, 6)
    def jdot_qd(self, q: F64, qd: F64, frame: int, reference: int, point: Optional[F64] = None) -> F64: ...  # (6,) | (N, 6)
    # ---- dynamics (issue 3) ----
    # f_ext: (n, 6) | (N, n, 6), per body [force; moment] in base axes, moment about the body origin.
    # A singular mass matrix (forward_dynamics, mass_matrix_inverse) raises RuntimeError naming the joint.
    def inverse_dynamics(self, q: F64, qd: F64, qdd: F64, f_ext: Optional[F64] = None) -> F64: ...  # (n,) | (N, n)
    def mass_matrix(self, q: F64) -> F64: ...  # (n, n) | (N, n, n)
    def mass_matrix_inverse(self, q: F64) -> F64: ...  # (n, n) | (N, n, n)
    def forward_dynamics(self, q: F64, qd: F64, tau: F64, f_ext: Optional[F64] = None) -> F64: ...  # (n,) | (N, n)
    def coriolis_matrix(self, q: F64, qd: F64) -> F64: ...  # (n, n) | (N, n, n)
    def christoffel(self, q: F64) -> F64: ...  # (n, n, n) | (N, n, n, n), c[i, j, k]
    def gravity_torque(self, q: F64) -> F64: ...  # (n,) | (N, n)
    def bias_torque(self, q: F64, qd: F64) -> F64: ...  # (n,) | (N, n), C qd + g
    def kinetic_energy(self, q: F64, qd: F64) -> F64: ...  # () | (N,)
    def potential_energy(self, q: F64) -> F64: ...  # () | (N,)
    def regressor(self, q: F64, qd: F64, qdd: F64) -> F64: ...  # (n, 10 n) | (N, n, 10 n)
    def center_of_mass(self, q: F64) -> F64: ...  # (3,) | (N, 3)
    def momentum(self, q: F64, qd: F64) -> F64: ...  # (6,) | (N, 6), [p; L about the base origin]

class NonFiniteResultError(FloatingPointError, ValueError):
    """Finite inputs gave a non-finite result (the numbers overflowed float64)."""

def _debug_panic(message: str = ..., in_worker: bool = False) -> None:
    """TEST-ONLY: panics inside a guarded binding (on a batch worker thread if ``in_worker``), to
    check that a panic reaches Python as a RuntimeError."""

def _set_check_finite(on: bool) -> bool:
    """BENCHMARK-ONLY: turns the non-finite scan of batch results on or off; returns the previous
    setting (benches/bench_finite_check.py)."""
