"""Studies on the co-simulation core: ensembles, benchmarks, accuracy, the in-process reference.

- ``sweep``: Monte Carlo ensembles on Dask: ``sweep`` runs a spec (and documents its
  file), ``sweep_spec`` reads it and lists its runs, ``sweep_client`` drives them on
  the cluster, ``sweep_task`` is one run on a worker, ``bundle`` ships the FMUs by
  content, ``journal`` keeps each row as it completes, ``sweep_tables`` and
  ``sweep_figures`` present the rows; ``cluster`` makes or joins the Dask cluster;
- ``scorecard``: your autopilot beside the paper's PD and SMC and the PID;
- ``bench``: the benchmarks behind ``python -m cosim.bench``, ``bench_sweep`` the sweep's;
- ``integration_error``, ``monolithic``, ``accuracy``: the numerical error study behind
  ``python -m cosim.accuracy`` (RK4 against DOP853 open loop; the co-simulation against a
  monolithic model, the controller inside the solver); ``cpu_variants``: the same runs
  under other CPUs' numpy, OpenBLAS and libm; ``spread``: the digits a run's figures mean,
  from the run again with a last bit changed;
- ``direct``: the paper's diagram wired by hand from the plain modules, without FMI or
  master: the in-process limit the benchmark measures and a reference for the tests.
"""
