"""kinedyn: robot kinematics and dynamics, symbolic for people and numeric (Rust) for programs."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import robots
from ._core import (
    NonFiniteResultError,
    simd,  # (kind, states per block) of batches in SIMD lanes (docs/dynamics.md)
)
from .description import DHRow, Frame, Inertia, Joint, Link, Loop
from .description.inertia import PhysicalConsistencyWarning
from .robot import Robot

if TYPE_CHECKING:
    # what type checkers and IDEs see: kd.simulate is the function and still holds the package's
    # names (kd.simulate.PD); the lazily loaded submodules are the modules themselves
    from . import analysis, configuration, dynamics, ik, kinematics, symbolic, testing  # noqa: F401
    from ._typing import PathLike
    from .description.audit import audit
    from .scale import sweep
    from .simulate import Trajectory
    from .simulate._callable import simulate
    from .symbolic import LagrangianSystem
from ._version import __version__

_SUBMODULES = ("analysis", "configuration", "dynamics", "ik", "kinematics", "symbolic", "testing")


def __getattr__(name):
    """Submodules load on first use (kd.ik, kd.kinematics, kd.analysis, ...), and so do kd.simulate,
    kd.Trajectory, kd.sweep, kd.audit (the file readers) and kd.LagrangianSystem (SymPy), keeping
    import fast."""
    if name in _SUBMODULES:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    if name in ("simulate", "robot_files", "scale"):  # kd.simulate is callable (see kinedyn.simulate)
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    if name == "Trajectory":
        from .simulate import Trajectory

        return Trajectory
    if name == "sweep":  # configuration-space sweeps into Zarr on a dask scheduler (docs/scale.md)
        from .scale import sweep

        return sweep
    if name == "audit":  # what is wrong with a robot file (docs/audit.md): it reads the file formats
        from .description.audit import audit

        return audit
    if name == "LagrangianSystem":  # the symbolic engine (SymPy) loads on first use
        from .symbolic import LagrangianSystem

        return LagrangianSystem
    raise AttributeError(f"module 'kinedyn' has no attribute '{name}'")


def load(path: PathLike, **kwargs) -> Robot:
    """Load a robot from a URDF (.urdf), YAML (.yaml/.yml) or TOML (.toml) file, by extension.
    ``inertia="warn"|"repair"|"strict"``: the policy for an inertia no rigid body can have
    (docs/model-files.md); other keywords as :meth:`Robot.from_urdf` or the Robot constructor."""
    from .robot_files import load as load_file  # the file readers (XML, TOML) load when a file is read

    return load_file(path, **kwargs)


__all__ = [
    "Robot",
    "Inertia",
    "Joint",
    "Link",
    "Frame",
    "Loop",
    "DHRow",
    "load",
    "audit",
    "robots",
    "LagrangianSystem",
    "simulate",
    "Trajectory",
    "sweep",
    "PhysicalConsistencyWarning",
    "NonFiniteResultError",
    "simd",
    "__version__",
    *_SUBMODULES,
]
