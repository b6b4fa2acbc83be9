"""kinedyn: robot kinematics and dynamics, symbolic for people and numeric (Rust) for programs."""

from .description import DHRow, Frame, Inertia, Joint, Link
from .robot import Robot
from . import robots
from . import simulate  # callable: kd.simulate(system, t_span, x0, ...) (see kinedyn.simulate)
from .simulate import Trajectory
from .symbolic import LagrangianSystem

__version__ = "0.1.0"


def load(path, **kwargs) -> Robot:
    """Load a robot from a URDF (.urdf), YAML (.yaml/.yml) or TOML (.toml) file, by extension."""
    from .description.files import load as _load

    return _load(path, **kwargs)


__all__ = ["Robot", "Inertia", "Joint", "Link", "Frame", "DHRow", "load", "robots", "LagrangianSystem", "simulate", "Trajectory", "__version__"]
