"""What becomes an :class:`~kinedyn.symbolic.EquationsOfMotion`: a robot (:mod:`.robot_eom`, from the
derivations in :mod:`kinedyn.symbolic.derive`), a Lagrangian system (:mod:`.system`, with the checks of
its properties in :mod:`.system_properties`), closed chains and changes of coordinates
(:mod:`.mechanisms`). These build the equations object; the derivations below it never import it."""
