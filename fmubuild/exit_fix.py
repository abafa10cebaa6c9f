"""A fix for pythonfmu 0.7.0's linux64 binary, which corrupts its host's heap at process exit.

The binary keeps its Python state in a global ``std::shared_ptr<PyState>``. At
exit, the C++ static destructors destroy it first (freeing its control block);
only afterwards, from ``.fini_array``, its ``__attribute__((destructor))``
``onLibraryUnload`` assigns ``pyState = nullptr`` to the dead pointer, which
decrements a counter inside the freed block, by then often one of malloc's
free-list pointers. A later malloc or free at exit (numpy's libgfortran, the
OpenBLAS thread) then aborts with "corrupted double-linked list". The library
is never really unloaded before exit (its STB_GNU_UNIQUE symbols make it
NODELETE), so every host process that loaded an FMU is exposed, Python or not:
seen as an intermittent SIGABRT of ``fmpy simulate`` and of pytest at exit.

The static destructor already shuts the Python state down, so the fix turns
``onLibraryUnload`` into a plain return. It is applied to a built FMU's linux64
binary only when that binary is the exact pythonfmu 0.7.0 build (by SHA-256) and
the expected instructions are where the symbol table puts them; any other binary
fails the build, so that a pythonfmu upgrade is looked at again. The upstream
fix: drop ``onLibraryUnload``, or never destroy ``pyState``.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

from fmukit.pythonfmu07.binary import KNOWN_BINARIES


def patch(binary: bytes, where: str) -> bytes:
    """The binary with ``onLibraryUnload`` made a no-op; RuntimeError naming ``where`` if unknown."""
    digest = hashlib.sha256(binary).hexdigest()
    fix = KNOWN_BINARIES.get(digest)
    if fix is None:
        raise RuntimeError(f"{where} is not the pythonfmu 0.7.0 linux64 binary whose exit-time "
                           f"heap corruption fmubuild.exit_fix knows how to fix (SHA-256 "
                           f"{digest}); check the new binary and extend fmukit.pythonfmu07.binary")
    offset, code = fix.offset, fix.code
    if binary[offset:offset + len(code)] != code:
        raise RuntimeError(f"{where}: unexpected code at onLibraryUnload")
    fixed = binary[:offset] + fix.patched + binary[offset + len(code):]
    if hashlib.sha256(fixed).hexdigest() != fix.fixed_sha256:
        raise RuntimeError(f"{where}: the patched binary is not the one fmukit expects")
    return fixed


def patch_binaries(entries: dict[str, bytes], fmu: Path) -> dict[str, bytes]:
    """An FMU's entries (name: bytes) with ``patch`` applied to every linux64 binary."""
    return {name: patch(data, f"{fmu}:{name}") if name.startswith("binaries/linux64/") else data
            for name, data in entries.items()}
