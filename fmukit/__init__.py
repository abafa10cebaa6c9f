"""The runtime an FMU built with fmukit carries, importing nothing of this project; the
adapters ``pythonfmu07`` (FMI 2.0) and ``pythonfmu3_03`` (FMI 3.0) alone import pythonfmu."""
