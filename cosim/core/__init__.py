"""The co-simulation core: components and their backends, systems, the master and its parts
(docs/architecture.md). It imports nothing of the project: where FMUs are built, the caller
says (``system.FmuFolders``).
"""
