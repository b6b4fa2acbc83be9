"""The seam between a robot description and the Rust core: the core's structured errors turned into
the messages users read (:mod:`kinedyn.native.errors`)."""

from .errors import SingularMassMatrixError, singular_mass_matrix_error

__all__ = ["SingularMassMatrixError", "singular_mass_matrix_error"]
