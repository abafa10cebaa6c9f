"""The co-simulation core (docs/architecture.md): where FMUs are built, the caller says."""
