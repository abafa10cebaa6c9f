"""Interop with other FMI co-simulation tools: SSP and OSP files, runs in libcosim, ecos,
fmpy's SSP runner (``engines``) and OMSimulator (``omsimulator``)."""
