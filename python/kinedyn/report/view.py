"""The report's 3-D view moved to :mod:`kinedyn.visual.page` (the animation page uses it too, and
the visual room sits below the report); this path keeps importing it."""

from ..visual.page import animation_page, asset, json_script, script_json, view_model  # noqa: F401
