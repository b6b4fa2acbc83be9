"""Low helpers for what a person sees: JSON-ready values (:mod:`.json`) and inline SVG plots (:mod:`.svg`).
Nothing here imports a robot or a room above; the report, the CLI and the notebook displays share them."""
