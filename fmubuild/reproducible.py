"""The same sources give the same FMU, byte for byte: entries in name order with one fixed time
and mode, no generation time, and a GUID (FMI 3.0: instantiation token) derived from the
contents.
"""
from __future__ import annotations

import hashlib
import re
import uuid
import zipfile
from pathlib import Path
from typing import Callable

EPOCH = (1980, 1, 1, 0, 0, 0)
"""The time of every entry: the earliest a zip file can hold."""

_GUID = re.compile(rb'\s(guid|instantiationToken)="[^"]*"')
_GENERATED = re.compile(rb'\sgenerationDateAndTime="[^"]*"')


def rewrite(fmu: Path, transform: Callable[[dict[str, bytes]], dict[str, bytes]],
            to: Path) -> None:
    """Write ``fmu`` again reproducibly ``to`` another path (whole or not at all), its
    entries (name: bytes) passed through ``transform`` first."""
    with zipfile.ZipFile(fmu) as package:
        entries = transform({info.filename: package.read(info)
                             for info in package.infolist() if not info.is_dir()})
    description = _GENERATED.sub(b"", entries["modelDescription.xml"])
    found = _GUID.search(description)
    attribute = found.group(1) if found else b"guid"
    entries["modelDescription.xml"] = _GUID.sub(b' ' + attribute + b'=""', description, count=1)
    contents = hashlib.sha256()
    for name in sorted(entries):
        contents.update(name.encode() + b"\0" + hashlib.sha256(entries[name]).digest())
    guid = str(uuid.uuid5(uuid.NAMESPACE_OID, contents.hexdigest()))
    entries["modelDescription.xml"] = entries["modelDescription.xml"].replace(
        b' ' + attribute + b'=""', b' ' + attribute + f'="{{{guid}}}"'.encode(), 1)
    write(to, entries)


def write(fmu: Path, entries: dict[str, bytes]) -> None:
    """An archive of ``entries`` (name: bytes) at ``fmu``, in name order, fixed times and
    modes, compressed; written beside it, then renamed."""
    temporary = fmu.with_name(f".{fmu.name}.tmp")
    try:
        with zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as package:
            for name in sorted(entries):
                info = zipfile.ZipInfo(name, EPOCH)
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
                package.writestr(info, entries[name])
        temporary.replace(fmu)
    finally:
        temporary.unlink(missing_ok=True)
