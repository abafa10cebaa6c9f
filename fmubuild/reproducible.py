"""The same sources give the same FMU, byte for byte: entries in name order with one fixed time
and mode, no generation time, and (``derive_guid``) a GUID (FMI 3.0: instantiation token)
derived from the contents.
"""
from __future__ import annotations

import hashlib
import re
import uuid
import zipfile
from pathlib import Path

EPOCH = (1980, 1, 1, 0, 0, 0)
"""The time of every entry: the earliest a zip file can hold."""

_GUID = re.compile(rb'\s(guid|instantiationToken)="[^"]*"')
_GENERATED = re.compile(rb'\sgenerationDateAndTime="[^"]*"')


def write(fmu: Path, entries: dict[str, bytes], derive_guid: bool = False) -> None:
    """An archive of ``entries`` (name: bytes) at ``fmu``, in name order, fixed times and
    modes, compressed; written beside it, then renamed. ``derive_guid``: the model
    description without its generation time, and its GUID derived from the contents."""
    if derive_guid:
        blank = _GUID.sub(rb' \1=""', _GENERATED.sub(b"", entries["modelDescription.xml"]), 1)
        contents = hashlib.sha256()
        for name in sorted(entries):
            data = blank if name == "modelDescription.xml" else entries[name]
            contents.update(name.encode() + b"\0" + hashlib.sha256(data).digest())
        guid = uuid.uuid5(uuid.NAMESPACE_OID, contents.hexdigest())
        entries = {**entries, "modelDescription.xml": _GUID.sub(
            rb' \1="{%s}"' % str(guid).encode(), blank, 1)}
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
