"""The seam between a robot description and the Rust core: the core's structured errors turned into
the messages users read (:mod:`kinedyn.native.errors`), and the native model of a robot with mimic
joints in its reduced coordinates (:mod:`kinedyn.native.mimic`)."""

from .errors import SingularMassMatrixError, singular_mass_matrix_error
from .mimic import ReducedModel

__all__ = ["ReducedModel", "SingularMassMatrixError", "singular_mass_matrix_error"]
