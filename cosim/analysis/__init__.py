"""What is computed and drawn from a recorded run: ``metrics`` and ``cost`` (eq 19),
``manoeuvres`` and ``criteria`` (MSC.137(76)), ``reports``, ``figures``, ``track``,
``plates``, ``animation``, ``describe`` (words from parameter values), ``kinds`` (which
report a scenario gets), ``seastate`` (WMO codes at model scale)."""
