"""Interop with other FMI co-simulation tools: SSP packages (``ssp``), OSP's system
structure (``osp``), and runs in libcosim, ecos, fmpy's SSP runner (``engines``) and
OMSimulator (``omsimulator``)."""
