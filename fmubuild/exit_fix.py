"""A fix for pythonfmu's Linux binaries, which corrupt their host's heap at process exit.

Both pythonfmu 0.7.0's linux64 binary and pythonfmu3 0.3.4's x86_64-linux one keep
their Python state in a global ``std::shared_ptr<PyState>``. At exit, the C++ static
destructors destroy it first (freeing its control block); only afterwards, from
``.fini_array``, its ``__attribute__((destructor))`` ``onLibraryUnload`` assigns
``pyState = nullptr`` to the dead pointer, which decrements a counter inside the
freed block, by then often one of malloc's free-list pointers. A later malloc or free
at exit (numpy's libgfortran, the OpenBLAS thread) then aborts with "corrupted
double-linked list". The library is never really unloaded before exit (its
STB_GNU_UNIQUE symbols make it NODELETE), so every host process that loaded an FMU is
exposed, Python or not: seen as an intermittent SIGABRT of ``fmpy simulate`` and of
pytest at exit (pythonfmu3's: 20 aborts in 20 runs of a C host).

The static destructor already shuts the Python state down, so the fix turns
``onLibraryUnload`` into a plain return. It is applied to a built FMU's Linux binary
only when that binary is the exact build its adapter knows (by SHA-256: the
``KNOWN_BINARIES`` of ``fmukit.pythonfmu07.binary`` and ``fmukit.pythonfmu3_03.binary``)
and the expected instructions are where the symbol table puts them; any other binary
fails the build, so that a pythonfmu upgrade is looked at again. The upstream fix:
drop ``onLibraryUnload``, or never destroy ``pyState``.
"""
from __future__ import annotations

import hashlib
import importlib
from pathlib import Path

from .routes import ROUTES


def patch(binary: bytes, where: str, fmi: int = 2) -> bytes:
    """The binary with ``onLibraryUnload`` made a no-op; RuntimeError naming ``where`` if
    it is not the binary of FMI ``fmi``'s pythonfmu that fmukit knows."""
    route = ROUTES[fmi]
    known_binaries = importlib.import_module(f"{route.adapter}.binary").KNOWN_BINARIES
    digest = hashlib.sha256(binary).hexdigest()
    fix = known_binaries.get(digest)
    if fix is None:
        platform = route.linux_binaries.split("/")[1]
        raise RuntimeError(f"{where} is not the {route.pythonfmu} {route.known} {platform} "
                           f"binary whose exit-time heap corruption fmubuild.exit_fix knows how "
                           f"to fix (SHA-256 {digest}); check the new binary and extend "
                           f"{route.adapter}.binary")
    offset, code = fix.offset, fix.code
    if binary[offset:offset + len(code)] != code:
        raise RuntimeError(f"{where}: unexpected code at onLibraryUnload")
    fixed = binary[:offset] + fix.patched + binary[offset + len(code):]
    if hashlib.sha256(fixed).hexdigest() != fix.fixed_sha256:
        raise RuntimeError(f"{where}: the patched binary is not the one fmukit expects")
    return fixed


def patch_binaries(entries: dict[str, bytes], fmu: Path, fmi: int = 2) -> dict[str, bytes]:
    """An FMU's entries (name: bytes) with ``patch`` applied to every Linux binary of FMI
    ``fmi``'s layout."""
    folder = ROUTES[fmi].linux_binaries
    return {name: patch(data, f"{fmu}:{name}", fmi) if name.startswith(folder) else data
            for name, data in entries.items()}
