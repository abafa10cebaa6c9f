"""Output files written whole or not at all (under a temporary name, then renamed; a failure
names the file and what was kept), and output folders written by one process at a time."""
from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import shutil
import tempfile
from pathlib import Path
from typing import Callable, Iterator

try:
    import fcntl
except ImportError:                     # Windows: msvcrt's byte-range lock instead
    fcntl = None
    import msvcrt

TEMPORARY_PREFIX = ".partial-"              # hidden, never a final name
FILE_NAME = re.compile(r"\w(?:[\w .+-]{0,98}[\w+-])?")   # one plain file name (``--name``)


def plain_name(value: object, what: str) -> str:
    """``value`` if it is a plain file name (``FILE_NAME``); else ValueError naming ``what``."""
    if not isinstance(value, str) or not FILE_NAME.fullmatch(value):
        raise ValueError(f"{what} = {value!r}: a name in the output folder must be one plain "
                         "file name of 1-100 letters, digits, _ . + - and inner spaces (no / "
                         "or \\, not starting with a dot)")
    return value


class OutputError(OSError):
    """A file could not be written: names the file, the reason and what was kept."""

    def __init__(self, target: Path, error: OSError, kept: str = ""):
        reason = error.strerror or str(error)
        if error.errno == errno.EFBIG:
            reason += " (a limit on file size)"
        super().__init__(f"cannot write {target}: {reason}" + (f"; {kept}" if kept else ""))


def _writing(error: OSError, place: Path) -> bool:
    """Whether ``error`` is of writing ``place`` or into it, not of reading another file."""
    return not error.filename or Path(error.filename).resolve().is_relative_to(place.resolve())


def read_small_text(path: Path, limit: int) -> str:
    """The text of a regular UTF-8 file of at most ``limit`` bytes; ValueError saying why not."""
    if not path.is_file():
        raise ValueError("no such file" if not path.exists() else "not a regular file")
    if path.stat().st_size > limit:
        raise ValueError(f"more than {limit / 2**20:g} MiB")
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(str(error)) from None


@contextlib.contextmanager
def whole_file(target: Path) -> Iterator[Path]:
    """``tmp`` (of ``target``'s suffix) becomes ``target`` if the block succeeds, else goes."""
    target = Path(target)
    if target.exists() and not target.is_file():
        raise OutputError(target, OSError(errno.EEXIST, "it exists and is not a regular file "
                                          "(a folder or a device): give a file's name"))
    tmp = target.with_name(f"{TEMPORARY_PREFIX}{target.stem}.{secrets.token_hex(4)}"
                           f"{target.suffix}")
    try:
        yield tmp
        os.replace(tmp, target)
    except OSError as error:
        if not _writing(error, tmp):
            raise                   # reading another file failed: its own error
        kept = (f"{target.name} is as it was before" if target.exists()
                else f"no {target.name} was written")
        raise OutputError(target, error, kept) from error
    finally:
        tmp.unlink(missing_ok=True)


def write_atomically(target: Path, write: Callable[[Path], object]) -> Path:
    """``write(path)`` to a temporary path beside ``target``, renamed to ``target``."""
    with whole_file(target) as tmp:
        write(tmp)
    return Path(target)


@contextlib.contextmanager
def fresh_folder(target: Path) -> Iterator[Path]:
    """An empty folder that replaces ``target`` if the block succeeds, else goes."""
    target = Path(target)
    folder = Path(tempfile.mkdtemp(dir=target.parent, prefix=f"{TEMPORARY_PREFIX}{target.name}-"))
    try:
        yield folder
        old = Path(tempfile.mkdtemp(dir=target.parent, prefix=f"{TEMPORARY_PREFIX}old-"))
        if target.exists():
            os.replace(target, old / target.name)
        os.replace(folder, target)
        shutil.rmtree(old, ignore_errors=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


class Outputs(contextlib.AbstractContextManager):
    """The files of ``outputs.writing`` enter ``folder`` together, and the ``stale`` not
    rewritten go, if the block succeeds (none else); a killed process's stages go first."""

    def __init__(self, folder: Path, stale: list[Path] | tuple[Path, ...] = (),
                 label: str = "outputs"):
        self.folder, self.stale = Path(folder), set(map(Path, stale))
        for entry in self.folder.glob(f"{TEMPORARY_PREFIX}{label}-{'?' * 8}"):   # mkdtemp's
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry, ignore_errors=True)
        self.stage = Path(tempfile.mkdtemp(dir=self.folder, prefix=f"{TEMPORARY_PREFIX}{label}-"))

    def final(self, path: Path) -> Path:
        """The name in ``folder`` of a file written to the stage."""
        path = Path(path)
        return self.folder / path.relative_to(self.stage) if path.is_relative_to(self.stage) \
            else path

    def __exit__(self, kind, error, trace) -> None:
        try:
            if kind is None and self.stage.exists():     # not discarded
                self.commit()
        finally:
            self.discard()

    @contextlib.contextmanager
    def writing(self, name: str) -> Iterator[Path]:
        """``with outputs.writing("x.csv") as path``: an OSError names ``folder/x.csv``."""
        try:
            yield self.stage / name
        except OSError as error:
            if isinstance(error, OutputError) or not _writing(error, self.stage):
                raise
            raise OutputError(self.folder / name, error,
                              f"the earlier files in {self.folder} are kept") from error

    def commit(self) -> list[Path]:
        """Rename every staged file into place, each earlier one set aside until all are in;
        if one cannot go (a permission, an immutable file), every earlier file is put back
        (OutputError). Then remove the stale ones."""
        staged = sorted(self.stage.iterdir())
        aside = Path(tempfile.mkdtemp(dir=self.stage))
        done: list[tuple[Path, bool]] = []          # (target, an earlier file set aside)
        try:
            for path in staged:
                target = self.folder / path.name
                earlier = target.exists() or target.is_symlink()
                if earlier:
                    os.replace(target, aside / path.name)
                done.append((target, earlier))
                os.replace(path, target)
        except OSError as error:
            lost = False
            for placed, earlier in reversed(done):      # the new ones out, the earlier back
                try:
                    os.replace(aside / placed.name, placed) if earlier else \
                        placed.unlink(missing_ok=True)
                except OSError:
                    lost = True
            kept = f"the earlier files in {self.folder} are as they were"
            if lost:                                    # not deleted with the stage
                kept = "the earlier files it could not put back are in " + \
                    str(aside.rename(self.folder / f"earlier-{aside.name}"))
            raise OutputError(target, error, kept) from error
        for old in self.stale - {target for target, _ in done}:
            old.unlink(missing_ok=True)
        self.discard()
        return [target for target, _ in done]

    def discard(self) -> None:
        shutil.rmtree(self.stage, ignore_errors=True)


class FolderBusy(RuntimeError):
    """Another process is writing into this output folder."""


@contextlib.contextmanager
def FolderLock(folder: Path) -> Iterator[None]:
    """``with FolderLock(folder)``: this process alone writes into ``folder``, FolderBusy at
    once if another does; the kernel's lock on the folder (Windows: on ``.cosim-lock`` in it)."""
    windows = fcntl is None
    handle = os.open(Path(folder) / ".cosim-lock" if windows else folder,
                     os.O_RDWR | os.O_CREAT if windows else os.O_RDONLY)
    try:
        if windows:
            msvcrt.locking(handle, msvcrt.LK_NBLCK, 1)
        else:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as error:
        os.close(handle)
        if not (windows or isinstance(error, BlockingIOError)):
            raise
        raise FolderBusy(f"output folder {folder} is being written by another command; wait "
                         "for it to end, or give this one another --out") from None
    try:
        yield
    finally:
        os.close(handle)          # closing releases the lock
