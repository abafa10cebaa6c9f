"""Interop with other FMI tools: SSP and OSP files; runs in libcosim, ecos, fmpy, OMSimulator."""
