"""Analysis of a robot's equations of motion: the properties control design relies on, measured
with residuals (:func:`check_properties`), and identification of the base inertial parameters from
excitation data (:func:`identify`). See docs/analysis.md."""

from .identification import Identification, Measurements, excitation, identify, simulate_measurements, with_inertial_parameters
from .properties import Check, InertiaBounds, PropertiesReport, check_properties, global_inertia_bounds, prove_properties
from .system_properties import check_system_properties

__all__ = [
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
]
