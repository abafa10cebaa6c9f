"""Studies on the co-simulation core: sweeps on Dask (``campaign`` runs one), the scorecard,
the benchmarks (``timing``, ``sweep_timing``, ``memory``), the accuracy study
(``integration_error``, ``coupling_error``), ``cpu_variants`` and ``spread``.
"""
