"""The command-line applications, built on the library's public API (``python -m granular``):

- ``demo``: a granular and a molecular gas against theory (the main job);
- ``reproduce``: the thesis' chapter 4, figure by figure (two experiments in
  ``reproduce_clustering`` and ``reproduce_visco``, the report's prose in ``reproduce_text``);
- ``speed_accuracy``: error against cost, and where each method fails (``bench --speed-accuracy``);
- ``bench`` and ``bench_langevin``: throughput of the two engines;
- ``output``: strict JSON for their results.

The library never imports from here; granular/__main__.py parses the command line, checks
the optional dependencies and dispatches.
"""
