"""Code from equations of motion: one program (:mod:`.program`: the state as array reads, CSE applied)
printed as C or NumPy (:mod:`.c_numpy`), JAX (:mod:`.jax`) or CasADi (:mod:`.casadi`)."""
