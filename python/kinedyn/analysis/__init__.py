"""Analysis of a robot's equations of motion: the properties control design relies on, measured
with residuals (:func:`check_properties`), and identification of the base inertial parameters from
excitation data (:func:`identify`). See docs/analysis.md."""

from .excitation import excitation_condition, optimize_excitation, write_trajectory_csv
from .friction import FrictionModel
from .identification import (
    Identification,
    Measurements,
    RotorEstimate,
    Validation,
    base_parameters_with_rotors,
    excitation,
    geared_joints,
    identify,
    pseudo_inertia,
    simulate_measurements,
    with_inertial_parameters,
)
from .loaders import LoaderDiff, compare_loaders
from .logs import Log, LogError, load_log
from .properties import (
    Check,
    InertiaBounds,
    PropertiesReport,
    check_properties,
    global_inertia_bounds,
    prove_properties,
)
from .system_properties import check_system_properties

__all__ = [
    "compare_loaders",
    "LoaderDiff",
    "check_properties",
    "check_system_properties",
    "prove_properties",
    "global_inertia_bounds",
    "InertiaBounds",
    "PropertiesReport",
    "Check",
    "excitation",
    "simulate_measurements",
    "identify",
    "Identification",
    "Measurements",
    "with_inertial_parameters",
    "load_log",
    "Log",
    "LogError",
    "Validation",
    "RotorEstimate",
    "base_parameters_with_rotors",
    "geared_joints",
    "FrictionModel",
    "pseudo_inertia",
    "optimize_excitation",
    "excitation_condition",
    "write_trajectory_csv",
]
