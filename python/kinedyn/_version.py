"""The package version, in a module of its own so that the rooms inside the package read it without
importing the package root (which imports every room)."""

__version__ = "0.1.0"
