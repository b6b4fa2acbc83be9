"""The whitelisting expression parser of robot files lives in :mod:`kinedyn.expressions` (below every
room that reads text); this path keeps importing it."""

from ..expressions import *  # noqa: F403
from ..expressions import __all__  # noqa: F401
