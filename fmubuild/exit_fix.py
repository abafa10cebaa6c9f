"""A fix for pythonfmu's Linux binaries, which corrupt their host's heap at process exit:
pythonfmu 0.7.0's and pythonfmu3 0.3.4's keep their Python state in a global
``std::shared_ptr<PyState>``, which its static destructor frees at exit, after which
``onLibraryUnload`` (``.fini_array``) assigns to the dead pointer, corrupting malloc's free
lists (an intermittent SIGABRT of every host that loaded an FMU). The destructor already
shuts Python down, so ``onLibraryUnload`` becomes a plain return, in a binary the adapter
knows by SHA-256 (``KNOWN_BINARIES`` of its ``binary``); any other fails the build.
"""
from __future__ import annotations

import hashlib
import importlib

from .routes import ROUTES


def patch(binary: bytes, where: str, fmi: int = 2) -> bytes:
    """The binary with ``onLibraryUnload`` made a no-op; RuntimeError naming ``where`` if
    it is not the binary of FMI ``fmi``'s pythonfmu that fmukit knows."""
    route, digest = ROUTES[fmi], hashlib.sha256(binary).hexdigest()
    fix = importlib.import_module(f"{route.adapter}.binary").KNOWN_BINARIES.get(digest)
    if fix is None:
        raise RuntimeError(f"{where} is not the {route.pythonfmu} {route.known} {route.linux} "
                           f"binary whose exit-time heap corruption fmubuild.exit_fix knows how "
                           f"to fix (SHA-256 {digest}); check the new binary and extend "
                           f"{route.adapter}.binary")
    end = fix.offset + len(fix.code)
    fixed = binary[:fix.offset] + fix.patched + binary[end:]
    if binary[fix.offset:end] != fix.code or hashlib.sha256(fixed).hexdigest() != fix.fixed_sha256:
        raise RuntimeError(f"{where}: the patched binary is not the one fmukit expects")
    return fixed

