"""Reading the text files a user names (case files, sweep files, CSV data, mould outlines) with
a bound on their size, so that /dev/zero, /dev/urandom or a multi-gigabyte file given by
mistake is refused at once instead of filling the memory or never ending; a UTF-8 byte order
mark (as spreadsheet programs write) is dropped."""

from __future__ import annotations

import os
import stat
from pathlib import Path

# a case file of a million-node gmsh mesh is a few kB; the largest sensible data file (a
# relaxation test logged at 1 kHz for a day, a mould outline of a million points) tens of MB
MAX_CASE_BYTES = 16 * 2**20
MAX_DATA_BYTES = 64 * 2**20


class FileTooLarge(OSError):
    """A file beyond the bound on what is read (or a device that never ends): the message says which."""


def _mib(n: int) -> str:
    return f"{n / 2**20:g} MiB"


def read_bytes(path: str | Path, limit: int = MAX_DATA_BYTES) -> bytes:
    """The bytes of a file, at most `limit` of them: FileTooLarge beyond that (a device such as
    /dev/zero included); OSError where the file cannot be opened."""
    with open(path, "rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:
        raise FileTooLarge(f"{path}: more than {_mib(limit)}: not a case or data file (a device or a huge file?)")
    return data


def read_text(path: str | Path, limit: int = MAX_DATA_BYTES) -> str:
    """The UTF-8 text of a file (a byte order mark dropped), at most `limit` bytes of it;
    FileTooLarge, OSError or UnicodeDecodeError otherwise."""
    return read_bytes(path, limit).decode("utf-8-sig")


def check_regular(path: str | Path, limit: int = MAX_DATA_BYTES) -> None:
    """FileTooLarge unless `path` is a regular file of at most `limit` bytes: for the files a
    library reads whole by itself (a gmsh mesh, a DXF drawing)."""
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise FileTooLarge(f"{path}: not a regular file (a device, a pipe or a socket)")
    if info.st_size > limit:
        raise FileTooLarge(f"{path}: {_mib(info.st_size)}, more than {_mib(limit)}")
