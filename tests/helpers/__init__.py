"""What the tests share, kept apart from the tests themselves (no test module imports another):

- ``scenes``: small scenes several test modules build;
- ``reference_edmd``: a slow, obvious event-driven MD in pure NumPy, the engine's reference;
- ``sde_reference``: a slow, obvious Langevin/UDSBM integrator drawing the engine's random
  numbers, the SDE engine's reference;
- ``margins``: the theories' own systematic accuracy, as tolerances;
- ``fuzz_cases``: the seeded fuzz inputs and the worker that runs them;
- ``ensemble_tasks``: picklable models for the ensemble tests (workers import them by name).

Imported as ``from helpers import ...``: pytest puts tests/ on sys.path (its default
"prepend" import mode, tests/ having no __init__.py), from the repository and from the copy
``make test-asan`` runs.
"""
