"""``kinedyn.Robot``: one robot description read by both engines.

The description (links, joints, frames, inertias, gravity) is frozen and may hold SymPy symbols.
The numeric engine compiles it once into a native ``_core.Model`` (Rust, f64) on first use; every
numeric method takes ``q`` of shape (n,) or a batch (N, n) and calls the core once.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Mapping, Sequence
from functools import cached_property
from typing import TYPE_CHECKING, Union

import numpy as np

from . import configuration, display, dynamics
from ._arrays import point_in_frame
from ._dask import batched, dask_targets, is_dask_array, lazy_inverse_kinematics
from ._math import by_name, to_float_array
from ._ui.names import did_you_mean
from .description.description import Description
from .description.dh import DHRow, description_from_dh
from .description.edit import lock_joints, substitute
from .description.geometry import Visual
from .description.link import Frame, Link
from .description.loops import Loop
from .ik.closed_chain import closed_chain_inverse_kinematics
from .ik.dispatch import inverse_kinematics as solve_ik
from .native.compile import compile_model, locked_block
from .native.errors import robot_error
from .robot_loops import ClosedLoops

if TYPE_CHECKING:
    from ._typing import ArrayLike, FloatOrArray, PathLike, SeedLike
    from .description.audit import Audit
    from .dynamics import BaseParameters
    from .symbolic.eom import EquationsOfMotion

__all__ = ["Robot"]

_DASK_ARRAY = "dask.array"  # batch IK goes lazy only once dask.array was imported (kinedyn/_dask.py)


def _described(name: str) -> property:
    """A read-only property of the Robot that is the description's own (with its docstring)."""
    return property(lambda self: getattr(self.description, name), doc=getattr(Description, name).__doc__)


class Robot(ClosedLoops):
    """A kinematic tree of links connected by revolute, prismatic and fixed joints.

    Build one with :meth:`from_dh`, :meth:`from_urdf`, :func:`kinedyn.load`, the built-in catalogue
    ``kinedyn.robots``, or directly from :class:`Link` and :class:`Frame` objects.
    """

    description: Description  # set once in __init__; the Robot is immutable (see __setattr__)

    def __init__(
        self,
        links: Sequence[Link] | Description,
        frames: Sequence[Frame] = (),
        *,
        gravity=(0.0, 0.0, -9.81),
        base: str = "base",
        tool: str | None = None,
        name: str = "robot",
        dh: Sequence[DHRow] | None = None,
        dh_convention: str | None = None,
        source: str = "",
        inertia: str = "warn",
        visuals: Sequence[Visual] = (),
        collisions: Sequence[Visual] = (),
        mimic: str = "reduce",
        loops: Sequence[Loop] = (),
    ):
        """``Robot(description)`` (what the readers return), or ``Robot(links, frames, ...)`` with the
        fields of :class:`~kinedyn.description.description.Description` as keywords. ``inertia``: the
        policy for tensors no rigid body can have (docs/model-files.md); ``mimic``: "reduce" removes
        the followers' coordinates, "independent" keeps them (:mod:`kinedyn.description.mimic`);
        ``visuals``/``collisions``: what :mod:`kinedyn.visual` draws, by frame name; ``loops``: closed
        loops between frames (:class:`~kinedyn.description.loops.Loop`, :meth:`add_loop`)."""
        if isinstance(links, Description):
            description = links
        else:
            description = Description(
                tuple(links),
                tuple(frames),
                gravity=gravity,
                base=base,
                tool=tool,
                name=name,
                dh=None if dh is None else tuple(dh),
                dh_convention=dh_convention,
                source=source,
                inertia=inertia,
                visuals=tuple(visuals),
                collisions=tuple(collisions),
                mimic=mimic,
                loops=tuple(loops),
            )
        object.__setattr__(self, "description", description)

    def __setattr__(self, name: str, value) -> None:
        # frozen: the native model and the caches are built from the description once, so a changed
        # field would leave them stale; a changed robot is a new one (replace, subs, lock_joints)
        raise AttributeError(f"a Robot is immutable: robot.replace({name}=...) builds a changed copy")

    def __delattr__(self, name: str) -> None:
        raise AttributeError("a Robot is immutable")

    @classmethod
    def from_description(cls, description: Description) -> Robot:
        """The robot of a :class:`~kinedyn.description.description.Description` (= ``Robot(description)``)."""
        return cls(description)

    # the description's fields, read through the robot
    name = property(lambda self: self.description.name)
    links = property(lambda self: self.description.links)
    frames = property(lambda self: self.description.frames)
    base = property(lambda self: self.description.base)
    gravity = property(lambda self: self.description.gravity)
    tool = property(lambda self: self.description.tool)
    dh = property(lambda self: self.description.dh)
    dh_convention = property(lambda self: self.description.dh_convention)
    source = property(lambda self: self.description.source)
    visuals = property(lambda self: self.description.visuals)
    collisions = property(lambda self: self.description.collisions)
    tree = property(lambda self: self.description.tree)
    nonphysical = property(lambda self: self.description.nonphysical)
    inertia_policy = property(lambda self: self.description.inertia)
    mimic_mode = property(lambda self: self.description.mimic)
    reference_configuration = property(lambda self: self.description.reference_configuration)  # loops' assembly mode
    _mimic = property(lambda self: self.description.mimic_map)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dh(
        cls,
        rows,
        convention: str = "standard",
        *,
        gravity=(0.0, 0.0, -9.81),
        base_pose=None,
        tool=None,
        name: str = "dh_robot",
        source: str = "",
        inertia: str = "warn",
    ) -> Robot:
        """A serial arm from a DH table (see :mod:`kinedyn.description.dh` for the conventions).

        ``rows``: DHRow objects, mappings with keys theta/d/a/alpha/kind/inertia/limits..., or tuples
        ``(theta, d, a, alpha[, kind])``. ``base_pose``: the 4x4 pose of DH frame 0 in the world.
        ``tool``: the 4x4 pose of the tool in the last link frame (a frame named "tool" is always
        added; identity if not given). ``inertia``: the inertia policy (as :meth:`from_urdf`).
        """
        return cls(
            description_from_dh(
                rows,
                convention,
                gravity=gravity,
                base_pose=base_pose,
                tool=tool,
                name=name,
                source=source,
                inertia=inertia,
            )
        )

    @classmethod
    def from_urdf(
        cls,
        path_or_string: Union[PathLike, bytes],
        *,
        gravity: ArrayLike = (0.0, 0.0, -9.81),
        tool: str | None = None,
        inertia: str = "warn",
        floating_base: bool = False,
        xacro_args: Mapping[str, object] | None = None,
        trust_xacro: bool = False,
        package_dirs: Sequence[PathLike] = (),
        mimic: str = "reduce",
    ) -> Robot:
        """A robot from a URDF file path or an XML string (see :mod:`kinedyn.description.urdf`).
        ``inertia``: what to do with an inertia no rigid body can have: ``"warn"`` (load it, with a
        ``PhysicalConsistencyWarning``), ``"repair"`` (project it onto the nearest consistent one)
        or ``"strict"`` (ValueError); see docs/model-files.md. ``floating_base=True``: the root link
        moves on a free-flyer joint ``root_joint`` (Pinocchio's ``JointModelFreeFlyer``; nq = nv + 1).
        ``mimic``: ``"reduce"`` (default) removes the coordinates of ``<mimic>`` joints (q_follower =
        multiplier * q_leader + offset), or ``"independent"`` keeps each one a coordinate of its own
        (docs/model-files.md, "Mimic joints").

        A path ending in ``.xacro`` is expanded by the ``xacro`` package first, with ``xacro_args``
        (its ``<xacro:arg>`` values) and ``package_dirs`` (where ``$(find PKG)`` looks); xacro runs
        Python expressions from the file, so it needs ``trust_xacro=True``
        (:mod:`kinedyn.description.xacro`)."""
        from .description.urdf import description_from_urdf  # file formats load on use

        return cls(
            description_from_urdf(
                path_or_string,
                gravity=gravity,
                tool=tool,
                inertia=inertia,
                floating_base=floating_base,
                mimic=mimic,
                xacro_args=xacro_args,
                trust_xacro=trust_xacro,
                package_dirs=package_dirs,
            )
        )

    @classmethod
    def from_mjcf(
        cls,
        path_or_string: Union[PathLike, bytes],
        *,
        gravity: ArrayLike | None = None,
        tool: str | None = None,
        inertia: str = "warn",
    ) -> Robot:
        """A robot from a MuJoCo MJCF file path or XML string (see :mod:`kinedyn.description.mjcf`
        and docs/model-files.md). ``gravity``: overrides the model's ``<option gravity>``;
        ``tool`` and ``inertia`` as :meth:`from_urdf`."""
        from .description.mjcf import description_from_mjcf  # file formats load on use

        return cls(description_from_mjcf(path_or_string, gravity=gravity, tool=tool, inertia=inertia))

    def replace(self, **changes) -> Robot:
        """A copy with some constructor arguments changed (links, frames, gravity, tool, name...)."""
        return Robot(dataclasses.replace(self.description, **changes))

    def lock_joints(self, joints, at=None) -> Robot:
        """A new robot with some joints fixed (e.g. a gripper's fingers).

        ``joints``: a mapping ``{joint: value}``, or a sequence (list, tuple, set, array) of joints
        locked at their value in ``at`` (a configuration (nq,); default: :meth:`neutral`). A joint is
        named by its name (``robot.joint_names``) or its index in that list (= its index in ``q`` when
        every joint has one coordinate). A multi-DOF joint's value is its block of q (a free-flyer's
        position and unit quaternion: locking it gives the fixed-base robot at that base pose).
        """
        if at is None and not isinstance(joints, (Mapping, str, bytes)):
            at = self.neutral()
        return Robot(lock_joints(self.description, joints, at, locked_block))

    # ------------------------------------------------------------------ pickling
    # The native model (and what holds it: the IK solvers of each frame) is dropped when a Robot is
    # pickled or copied, and built again on first use on the other side (docs/architecture.md: "a Robot
    # pickles"). Everything else is the frozen description: numbers, NumPy arrays, SymPy objects.
    _NATIVE_STATE = ("_model", "_ik_chains", "_independent_robot")

    def __getstate__(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k not in self._NATIVE_STATE}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    # ------------------------------------------------------------------ description queries
    @property
    def n(self) -> int:
        """Number of degrees of freedom: the length of ``qd``, ``qdd`` and ``tau`` (= :attr:`nv`). For a
        robot of 1-DOF joints it is also the length of ``q``; with floating, spherical or planar joints
        ``q`` has :attr:`nq` entries (docs/conventions.md)."""
        return self.nv

    nq = _described("nq")
    nv = _described("nv")

    has_multi_dof_joints = _described("has_multi_dof_joints")
    joints = _described("joints")
    joint_names = _described("joint_names")
    mimic_joints = _described("mimic_joints")
    body_names = _described("body_names")
    frame_names = _described("frame_names")
    parents = _described("parents")

    def require_one_dof_joints(self, feature: str) -> None:
        """Raise a ValueError naming the joint when ``feature`` does not handle multi-DOF joints yet."""
        self.description.require_one_dof_joints(feature)

    def require_no_mimic_joints(self, feature: str) -> None:
        """Raise a ValueError naming a follower when ``feature`` does not handle reduced mimic joints."""
        self.description.require_no_mimic_joints(feature)

    lower_limits = _described("lower_limits")
    upper_limits = _described("upper_limits")
    velocity_limits = _described("velocity_limits")
    effort_limits = _described("effort_limits")
    armature = _described("armature")
    viscous = _described("viscous")
    coulomb = _described("coulomb")
    coulomb_negative = _described("coulomb_negative")

    @batched("qd")
    def friction_torque(self, qd: ArrayLike) -> np.ndarray:
        """viscous * qd + Coulomb friction (:func:`kinedyn.dynamics.friction_torque`), (n,) or (N, n)."""
        return dynamics.friction_torque(self, qd)

    is_symbolic = _described("is_symbolic")
    symbols = _described("symbols")

    def subs(self, mapping: Mapping) -> Robot:
        """A copy with SymPy symbols (or their names) replaced, by numbers for the numeric engine."""
        return Robot(substitute(self.description, by_name(mapping, self.symbols)))

    def save(self, path: PathLike) -> None:
        """Write the robot to a YAML or TOML robot file (by extension); see docs/model-files.md."""
        from .description.files import save as save_robot_file  # file formats load on use

        save_robot_file(self, path)

    def to_urdf(
        self, path: PathLike | None = None, *, geometry: bool = True, floating_base_as_root: bool = True
    ) -> str:
        """The robot as URDF text, written to ``path`` when given (:func:`kinedyn.description.export.to_urdf`,
        docs/model-files.md, "Converting robots")."""
        from .description import export  # file formats load on use

        return export.to_urdf(self, path, geometry=geometry, floating_base_as_root=floating_base_as_root)

    def audit(self, *, geometry: bool = True) -> Audit:
        """What is wrong with the robot's file (its description where it has none): docs/audit.md."""
        from .description.audit import audit  # the file formats load on use

        return audit(self.description, geometry=geometry)

    def to_mjcf(self, path: PathLike | None = None, *, geometry: bool = True, default_inertia: bool = True) -> str:
        """The robot as MuJoCo XML (MJCF), written to ``path`` when given (:func:`kinedyn.description.export.to_mjcf`)."""
        from .description import export  # file formats load on use

        return export.to_mjcf(self, path, geometry=geometry, default_inertia=default_inertia)

    def inertial_parameters(self) -> np.ndarray:
        """The 10 standard parameters of every body, stacked (10 n,): about each body-frame origin
        (the joint frame), order [m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]."""
        # a robot without moving joints (a drone's body on a fixed base) has no parameters: shape (0,)
        return np.concatenate(
            [np.zeros(0)]
            + [to_float_array(b.inertia.parameters(), what=f"inertia of '{b.name}'") for b in self.tree.bodies]
        )

    @cached_property
    def _frame_ids(self) -> dict:
        return {f.name: i for i, f in enumerate(self.tree.frames)}

    def frame_index(self, frame: str) -> int:
        try:
            return self._frame_ids[frame]
        except KeyError:
            raise ValueError(
                f"unknown frame '{frame}'{did_you_mean(frame, self.frame_names)} (frames of robot '{self.name}': {self.frame_names})"
            ) from None

    def show(self, q: ArrayLike | None = None, *, block: bool | None = None, **kwargs):
        """Open a live 3-D view of the robot at ``q`` in the browser (a viser server on localhost; its
        URL is printed): meshes, frames, a slider per joint. Returns the :class:`kinedyn.visual.viewer.Viewer`;
        ``block``: wait until Ctrl-C (default: from a script yes, in Jupyter no). ``kwargs``: host,
        port, geometry ("visual" or "collision"). See docs/visualisation.md."""
        from .visual.viewer import show  # viser (optional, heavy) loads with the viewer

        return show(self, q, block=block, **kwargs)

    def __repr__(self) -> str:
        return f"Robot(name={self.name!r}, n={self.n}, joints={self.joint_names}, tool={self.tool!r})"

    # notebooks (kinedyn.display): joint table, mass, gravity, tool and a small stick figure
    def _repr_html_(self) -> str:
        return display.robot_html(self)

    def _repr_markdown_(self) -> str:
        return display.robot_markdown(self)

    # ------------------------------------------------------------------ numeric engine
    @cached_property
    def _model(self):
        """The compiled native model (built once; numeric descriptions only): :func:`kinedyn.native.compile_model`."""
        return compile_model(self.description)

    @cached_property
    def _link_frame_ids(self) -> np.ndarray:
        return np.array([self.frame_index(name) for name in self.body_names], dtype=np.int64)

    # kinematics ---------------------------------------------------------------------------
    @batched("q")
    def forward_kinematics(self, q: ArrayLike) -> np.ndarray:
        """Poses of the moving links' frames in the base: (n, 4, 4), or (N, n, 4, 4) for a batch."""
        return self._model.frame_poses(q, self._link_frame_ids)

    @batched("q")
    def frame_poses(self, q: ArrayLike, frames: Sequence[str] | None = None) -> np.ndarray:
        """Poses of the named frames (all frames if None): (k, 4, 4) or (N, k, 4, 4)."""
        names = self.frame_names if frames is None else list(frames)
        ids = np.array([self.frame_index(f) for f in names], dtype=np.int64)
        return self._model.frame_poses(q, ids)

    @batched("q")
    def pose(self, q: ArrayLike, frame: str | None = None) -> np.ndarray:
        """Pose of one frame (default: the tool) in the base: (4, 4) or (N, 4, 4)."""
        # the native model converts and checks q (shape, dtype, finite) with the messages of
        # kinedyn._arrays.real_array; here only the frame's index, the tool's looked up once
        fid = self._tool_frame_id if frame is None else self._frame_ids.get(frame)
        if fid is None:  # the checked path, with its error message
            fid = self.frame_index(frame or self.tool)
        return self._model.frame_pose(q, fid)

    @cached_property
    def _tool_frame_id(self) -> int | None:
        """The tool frame's index (None: no tool, frame_index names the problem)."""
        return self._frame_ids.get(self.tool)

    @batched("q")
    def jacobian(
        self, q: ArrayLike, frame: str | None = None, reference: str = "world", point: ArrayLike | None = None
    ) -> np.ndarray:
        """Geometric Jacobian (6, n), rows [linear; angular] (see docs/conventions.md).

        ``reference="world"``: velocity of the frame origin (or of ``point``, given in the frame's
        axes) and angular velocity, in base axes; ``"local"``: both in the frame's axes;
        ``"spatial"``: the spatial Jacobian (velocity of the body point at the base origin).
        """
        fid = self._tool_frame_id if frame is None else self._frame_ids.get(frame)
        if fid is None or point is not None:  # the checked path, with its error messages
            fid, point = self.frame_index(frame or self.tool), point_in_frame(point)
        return self._model.jacobian(q, fid, reference, point)

    @batched("q")
    def jacobian_hessian(
        self, q: ArrayLike, frame: str | None = None, reference: str = "world", point: ArrayLike | None = None
    ) -> np.ndarray:
        """Kinematic Hessian ``dJ/dq`` of :meth:`jacobian` (same frame, reference and point):
        (n, 6, n), or (N, n, 6, n) for a batch, with ``H[i, :, j] = dJ[:, j]/dq_i`` (Robotics
        Toolbox's layout: ``H[i]`` is the derivative of the whole Jacobian along joint i).

        ``reference="world"`` is RTB's ``hessian0``; ``sum_ij H[i, :, j] qd_i qd_j`` equals
        :meth:`jacobian_dot_qd` in every reference. RTB's ``hessiane`` is ``hessian0`` with its rows
        turned into the frame's axes (not the derivative of the ``"local"`` Jacobian):
        :func:`kinedyn.kinematics.hessian_in_frame_axes`. Computed in the native core from the
        Jacobian's columns (Haviland & Corke 2022, Part I; derivation in crates/kinedyn-core/src/algorithms/jacobian.rs).
        """
        fid = self.frame_index(frame or self.tool)
        return self._model.jacobian_hessian(q, fid, reference, point_in_frame(point))

    @batched("q", "qd")
    def frame_velocity(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        frame: str | None = None,
        reference: str = "world",
        point: ArrayLike | None = None,
    ) -> np.ndarray:
        """Twist [v; w] of a frame, = J(q) qd, computed by the recursive velocity pass."""
        return self._model.frame_velocity(
            q,
            qd,
            self.frame_index(frame or self.tool),
            reference,
            point_in_frame(point),
        )

    @batched("q", "qd")
    def jacobian_dot_qd(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        frame: str | None = None,
        reference: str = "world",
        point: ArrayLike | None = None,
    ) -> np.ndarray:
        """The acceleration drift dJ/dt qd: the frame's (classical) acceleration when qdd = 0."""
        return self._model.jdot_qd(
            q,
            qd,
            self.frame_index(frame or self.tool),
            reference,
            point_in_frame(point),
        )

    def inverse_kinematics(
        self,
        target: ArrayLike,
        q0: ArrayLike | None = None,
        mask: ArrayLike | None = None,
        method: str = "auto",
        respect_limits: bool = True,
        **kwargs,
    ):  # IKResult, or IKBatchResult for a batch of targets
        """Joint vectors putting ``frame`` (default: the tool) at ``target`` (4x4 pose or 3-vector
        position, or a batch): closed form where the geometry has one, else numeric. Returns an
        ``IKResult`` (solutions nearest q0 first); see :func:`kinedyn.ik.inverse_kinematics`. A robot
        with closed loops solves the pose and the closure together (:mod:`kinedyn.ik.closed_chain`)."""
        if self.loops:  # the tree's solvers would leave the loops open
            return closed_chain_inverse_kinematics(self, target, q0, mask, method, respect_limits, **kwargs)
        if _DASK_ARRAY in sys.modules and (is_dask_array(target) or is_dask_array(q0)):
            return lazy_inverse_kinematics(
                self,
                target if is_dask_array(target) else dask_targets(target, q0),
                q0,
                mask,
                method,
                respect_limits,
                kwargs,
            )
        return solve_ik(self, target, q0, mask, method, respect_limits, **kwargs)

    # dynamics -----------------------------------------------------------------------------
    # Equations of motion (docs/architecture.md): M(q) qdd + C(q, qd) qd + g(q) + friction(qd) = tau + sum_i J_i^T f_ext_i,
    # friction = viscous qd + coulomb sign(qd) (direction-dependent levels: friction_torque), M including
    # the reflected rotor inertia r^2 J_m.
    @batched("q", "qd", "qdd", "f_ext", native=True)
    def inverse_dynamics(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, f_ext: ArrayLike | None = None, out: np.ndarray | None = None
    ) -> np.ndarray:
        """tau = M qdd + C qd + g + friction - sum_i J_i^T f_ext_i (recursive Newton-Euler).

        ``f_ext``: (links, 6) (or (N, links, 6); links = ``len(robot.body_names)``, = n without
        multi-DOF joints), one wrench ``[force; moment]`` per moving link, acting on the link, in base axes, the moment taken about the origin of
        the link's frame (``robot.forward_kinematics(q)[i]``), so that it maps to joint torques by
        ``J_i^T`` with ``J_i = robot.jacobian(q, frame=body_names[i], reference="world")``; or None."""
        return self._model.inverse_dynamics(q, qd, qdd, f_ext, out)

    @batched("q", native=True)
    def mass_matrix(self, q: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """M(q) (composite-rigid-body algorithm), reflected rotor inertia included; exactly symmetric.
        ``out``: a float64 array of the result's shape to write into instead of allocating one (as
        NumPy's ``out=``; also on the other per-step methods, for control loops)."""
        return self._model.mass_matrix(q, out)

    @batched("q", native=True, errors=robot_error)
    def mass_matrix_inverse(self, q: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """M(q)^-1 (sparse L^T D L factorisation of M); RuntimeError if M is singular."""
        try:
            return self._model.mass_matrix_inverse(q, out)
        except RuntimeError as e:
            raise robot_error(self, e) from None

    @batched("q", "qd", "tau", "f_ext", native=True, errors=robot_error)
    def forward_dynamics(
        self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, f_ext: ArrayLike | None = None, out: np.ndarray | None = None
    ) -> np.ndarray:
        """qdd solving M qdd = tau - C qd - g - friction + sum_i J_i^T f_ext_i (articulated-body
        algorithm); ``f_ext`` as in :meth:`inverse_dynamics`. RuntimeError naming the joint if the
        mass matrix is singular (e.g. a massless subtree without rotor inertia)."""
        try:
            return self._model.forward_dynamics(q, qd, tau, f_ext, out)
        except RuntimeError as e:
            raise robot_error(self, e) from None

    @batched("q", "qd", "qdd", "f_ext", native=True)
    def inverse_dynamics_derivatives(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, f_ext: ArrayLike | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(dtau/dq, dtau/dqd, dtau/dqdd = M)`` of :meth:`inverse_dynamics`, each (n, n) (or
        (N, n, n)), entry ``[i, j] = d tau_i / d x_j``: analytical and exact, O(n^2), from one pass
        in world coordinates (Pinocchio's ``computeRNEADerivatives``; the derivation is in the
        core's ``derivatives.rs``). ``f_ext`` is held fixed in base axes and applied at the
        link-frame origins, which move with q. Coulomb friction contributes its derivative, zero
        (qd != 0)."""
        return self._model.inverse_dynamics_derivatives(q, qd, qdd, f_ext)

    @batched("q", "qd", "tau", "f_ext", native=True, errors=robot_error)
    def forward_dynamics_derivatives(
        self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, f_ext: ArrayLike | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(dqdd/dq, dqdd/dqd, dqdd/dtau = M^-1)`` of :meth:`forward_dynamics`, each (n, n) (or
        (N, n, n)): ``-M^-1`` times the inverse-dynamics derivatives at the forward-dynamics qdd
        (Carpentier & Mansard, RSS 2018). ``f_ext`` as in :meth:`inverse_dynamics_derivatives`."""
        try:
            return self._model.forward_dynamics_derivatives(q, qd, tau, f_ext)
        except RuntimeError as e:
            raise robot_error(self, e) from None

    @batched("q", "qd", native=True)
    def coriolis_matrix(self, q: ArrayLike, qd: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """C(q, qd) built from Christoffel symbols, so that dM/dt - 2C is skew-symmetric."""
        return self._model.coriolis_matrix(q, qd, out)

    @batched("q", native=True)
    def christoffel(self, q: ArrayLike) -> np.ndarray:
        """c[i, j, k] = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k) (Spong eq. 9.58), (n, n, n);
        ``C[k, j] = sum_i c[i, j, k] qd[i]``."""
        return self._model.christoffel(q)

    @batched("q", native=True)
    def gravity_torque(self, q: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """g(q) = dP/dq."""
        return self._model.gravity_torque(q, out)

    @batched("q", "qd", native=True)
    def bias_torque(self, q: ArrayLike, qd: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """C(q, qd) qd + g(q) (without friction)."""
        return self._model.bias_torque(q, qd, out)

    @batched("q", "qd", native=True)
    def kinetic_energy(self, q: ArrayLike, qd: ArrayLike) -> FloatOrArray:
        """K = 1/2 qd . M(q) qd (rotor inertia included): a float, or (N,) for a batch."""
        return self._model.kinetic_energy(q, qd)  # the native model gives a float for one state

    @batched("q", native=True)
    def potential_energy(self, q: ArrayLike) -> FloatOrArray:
        """P = -sum_i m_i g . c_i (zero with all masses at the base origin): a float, or (N,)."""
        return self._model.potential_energy(q)

    @batched("q", native=True)
    def center_of_mass(self, q: ArrayLike) -> np.ndarray:
        """Centre of mass of the moving links in base coordinates, (3,) or (N, 3)."""
        return self._model.center_of_mass(q)

    @batched("q", "qd", native=True)
    def momentum(self, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
        """Spatial momentum of the robot, (6,) or (N, 6): [linear momentum; angular momentum about
        the base origin], base axes (Pinocchio's WORLD-frame momentum)."""
        return self._model.momentum(q, qd)

    @batched("q", native=True)
    def centroidal_momentum_matrix(self, q: ArrayLike) -> np.ndarray:
        """A_G(q), (6, n) or (N, 6, n): the momentum about the centre of mass, h_G = A_G qd =
        [m c_dot; L_G] in base axes (Orin, Goswami & Lee 2013; Pinocchio's ``ccrba`` ``Ag``)."""
        return self._model.centroidal_momentum_matrix(q)

    @batched("q")
    def center_of_mass_jacobian(self, q: ArrayLike) -> np.ndarray:
        """J_c(q), (3, n) or (N, 3, n): the centre of mass's velocity c_dot = J_c qd in base axes
        (the linear rows of the centroidal momentum matrix over the total mass)."""
        A = self._model.centroidal_momentum_matrix(q)
        return A[..., :3, :] / self._total_mass

    @cached_property
    def _total_mass(self) -> float:
        return float(sum(float(b.inertia.mass) for b in self.tree.bodies))

    @batched("q", "qd", "qdd")
    def regressor(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Y(q, qd, qdd), (n, 10 n_links), with Y @ robot.inertial_parameters() == tau (no friction/rotor)."""
        y = self._model.regressor(q, qd, qdd)
        if self.has_multi_dof_joints:
            # the native model's extra bodies of a multi-DOF joint are massless: keep the columns of
            # the bodies that carry the links (the core's layout, Model.link_bodies)
            columns = (10 * self._model.link_bodies[:, None] + np.arange(10)).ravel()
            y = np.ascontiguousarray(y[..., columns])
        return y

    def base_parameters(self, samples: int = 200, rng: SeedLike = 0, tol: float = 1e-9) -> BaseParameters:
        """A minimal identifiable parameter set (:class:`kinedyn.dynamics.BaseParameters`): column
        indices of the regressor kept, the grouping matrix with ``pi_base = grouping @ pi``, and
        ``pi_base`` of this robot, so that ``Y[:, indices] @ pi_base == Y @ pi``. Found by QR with
        column pivoting on regressors stacked at ``samples`` random states."""
        return dynamics.base_parameters(self, samples=samples, rng=rng, tol=tol)

    # symbolic engine ----------------------------------------------------------------------
    def equations_of_motion(self, method: str = "lagrange", simplify: bool = True, **kwargs) -> EquationsOfMotion:
        """Symbolic equations of motion (SymPy): see :func:`kinedyn.symbolic.equations_of_motion`."""
        from . import symbolic  # SymPy's engine loads only for symbolic work (kinedyn._lazy)

        return symbolic.equations_of_motion(self, method=method, simplify=simplify, **kwargs)

    # configurations (kinedyn.configuration: Pinocchio's conventions, docs/conventions.md) ---------
    def neutral(self) -> np.ndarray:
        """The neutral configuration (nq,): zeros, identity quaternions (0, 0, 0, 1), planar (0, 0, 1, 0)."""
        return configuration.neutral(self)

    def random_configuration(self, rng: SeedLike = None, size: int | None = None) -> np.ndarray:
        """Uniform within finite joint limits, in [-pi, pi] (revolute) or [-1, 1] (prismatic) else;
        uniformly distributed rotations for quaternions (see :func:`kinedyn.configuration.random_configuration`)."""
        return configuration.random_configuration(self, rng, size)

    def integrate(self, q: ArrayLike, v: ArrayLike, dt: ArrayLike = 1.0) -> np.ndarray:
        """q ⊕ v dt (nq,) or (N, nq): q + v dt for 1-DOF joints, M(q) Exp(v dt) for floating, spherical and
        planar joints (v in the child's frame): see :mod:`kinedyn.configuration`."""
        return configuration.integrate(self, q, v, dt)

    def difference(self, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
        """v (nv,) or (N, nv) with integrate(q0, v) == q1: Log(M(q0)^-1 M(q1)), rotations the short way."""
        return configuration.difference(self, q0, q1)

    def interpolate(self, q0: ArrayLike, q1: ArrayLike, t: ArrayLike) -> np.ndarray:
        """integrate(q0, t * difference(q0, q1)): the geodesic from q0 (t = 0) to q1 (t = 1)."""
        return configuration.interpolate(self, q0, q1, t)

    def normalize(self, q: ArrayLike) -> np.ndarray:
        """``q`` with each quaternion and planar (cos, sin) pair divided by its norm."""
        return configuration.normalize(self, q)
