"""One module per ``kinedyn`` command, each with ``add_arguments(parser)`` and ``run(args) -> int``
(named in :data:`kinedyn.cli.COMMANDS`, which imports a module only when its command runs).
:mod:`.formulas` is the ``--symbolic`` output that ``fk`` and ``jacobian`` share."""
