"""The seam between a robot description and the Rust core: the description compiled into
``_core.Model`` (:mod:`kinedyn.native.compile`), the core's structured errors turned into
the messages users read (:mod:`kinedyn.native.errors`), and the native model of a robot with mimic
joints in its reduced coordinates (:mod:`kinedyn.native.mimic`)."""

from .compile import compile_model, joint_record, locked_block, planar_basis
from .errors import SingularMassMatrixError, singular_mass_matrix_error
from .mimic import ReducedModel

__all__ = [
    "ReducedModel",
    "SingularMassMatrixError",
    "compile_model",
    "joint_record",
    "locked_block",
    "planar_basis",
    "singular_mass_matrix_error",
]
