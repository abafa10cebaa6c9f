"""Studies built on the co-simulation core: ensembles, benchmarks, the in-process reference.

- ``sweep``: Monte Carlo ensembles on Dask (spec, task, journal, tables, comparison);
  ``sweep_figures`` draws their results; ``cluster`` makes or joins the Dask cluster;
- ``bench``: the benchmarks behind ``python -m cosim.bench``;
- ``direct``: the paper's diagram wired by hand from the plain modules, without FMI or
  master: the in-process limit the benchmark measures and a reference for the tests.
"""
