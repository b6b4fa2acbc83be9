"""The seed tutorial, worked: it lives in :mod:`kinedyn.tutorial`; this name stays importable
(``from kinedyn.report import tutorial``, ``kinedyn.report.tutorial.elbow_ik``)."""

from ..tutorial import *  # noqa: F403
from ..tutorial import __all__  # noqa: F401
