"""The co-simulation core (docs/architecture.md); it imports nothing of the project: where
FMUs are built, the caller says (``system.FmuFolders``)."""
