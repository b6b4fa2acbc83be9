"""kinedyn's fuzz suite (issue 11, "Trust at the boundary"): Hypothesis strategies that mutate real
robot files (URDF, YAML, TOML) and generate hostile arrays for the numeric API, run in worker
subprocesses under time and memory limits, with every outcome classified.

- :mod:`fuzz.corpus`: the real texts mutated;
- :mod:`fuzz.strategies`: the mutations and the array calls (Hypothesis strategies);
- :mod:`fuzz.worker`: the subprocess that runs and classifies cases;
- :mod:`fuzz.runner`: generation from a fixed seed, the worker pool, the table of figures.

Used by tests/test_fuzz.py (a few hundred cases) and scripts/fuzz (thousands). See docs/testing.md.
"""
