"""Archives from others (FMUs, SSP packages) unpacked only where they say and within a size:
a member with an absolute or '..' path, a link, or more bytes in all than ``LIMIT`` is
refused before anything is written, naming the file and the member."""
from __future__ import annotations

import shutil
import stat
import tempfile
import zipfile
from pathlib import Path, PurePosixPath

LIMIT = 4 << 30                    # bytes an archive may unpack to, in all (a zip bomb: more)


class UnsafeArchive(ValueError):
    """An archive that would write outside its folder, hold a link, or unpack past the limit."""


def check_archive(path: str | Path, limit: int = LIMIT) -> None:
    """UnsafeArchive naming ``path`` and the member, if any member would not stay inside the
    folder it is unpacked into (an absolute or '..' path, a link) or the sizes its members
    declare (which zipfile holds them to) add up to more than ``limit``."""
    with zipfile.ZipFile(path) as archive:
        members = archive.infolist()
    total = 0
    for member in members:
        name = member.filename
        parts = PurePosixPath(name.replace("\\", "/")).parts
        if name.startswith(("/", "\\")) or ":" in name or ".." in parts:
            raise UnsafeArchive(f"{path}: member {name!r} would be written outside the folder "
                                "it is unpacked into; refused")
        if stat.S_ISLNK(member.external_attr >> 16):
            raise UnsafeArchive(f"{path}: member {name!r} is a symbolic link; refused")
        total += member.file_size
        if total > limit:
            raise UnsafeArchive(f"{path}: unpacks to more than {limit / 2**30:g} GiB (at member "
                                f"{name!r}); refused as a zip bomb")


def unpack(path: str | Path, limit: int = LIMIT) -> Path:
    """A new temporary folder holding the checked archive ``path`` unpacked; if unpacking
    fails (a full disk), the folder is removed and the OSError says which archive."""
    check_archive(path, limit)
    folder = Path(tempfile.mkdtemp(prefix="cosim-unpacked-"))
    try:
        with zipfile.ZipFile(path) as archive:
            archive.extractall(folder)
    except BaseException as error:
        shutil.rmtree(folder, ignore_errors=True)
        if isinstance(error, OSError):
            raise OSError(error.errno, f"cannot unpack {path}: {error.strerror or error}") \
                from error
        raise
    return folder
