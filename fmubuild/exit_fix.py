"""A fix for pythonfmu's Linux binaries: their static destructor frees the global
``shared_ptr<PyState>`` at exit, then ``onLibraryUnload`` assigns to the dead pointer (an
intermittent SIGABRT of every host). The destructor already shuts Python down, so
``onLibraryUnload`` becomes a plain return, in a binary the adapter knows by SHA-256."""
from __future__ import annotations

import hashlib
import importlib

from .project import ROUTES


def patch(binary: bytes, where: str, fmi: int = 2) -> bytes:
    """The binary, ``onLibraryUnload`` a no-op; RuntimeError naming ``where`` if unknown."""
    route, digest = ROUTES[fmi], hashlib.sha256(binary).hexdigest()
    fix = importlib.import_module(route.adapter).KNOWN_BINARIES.get(digest)
    if fix is None:
        raise RuntimeError(f"{where} is not the {route.pythonfmu} {route.known} {route.linux} "
                           f"binary whose exit-time heap corruption fmubuild.exit_fix knows how "
                           f"to fix (SHA-256 {digest}); check the new binary and extend "
                           f"{route.adapter}")
    end = fix.offset + len(fix.code)
    fixed = binary[:fix.offset] + fix.patched + binary[end:]
    if binary[fix.offset:end] != fix.code or hashlib.sha256(fixed).hexdigest() != fix.fixed_sha256:
        raise RuntimeError(f"{where}: the patched binary is not the one fmukit expects")
    return fixed

