"""The lock of a results folder while a run writes it: a second run on the same folder is
refused (it would rewrite the files under the first) and told which run holds it.

The lock is an advisory `fcntl.flock` on DIR/.axiform.lock, whose text says who holds it
(pid, host, start time).  The operating system drops the lock when its process ends, however
it ends (kill -9 included), so a lock file left behind by a run that is gone is taken over
without a question; a run that ends normally (or by an error, SIGINT or SIGTERM) also
removes the file.
"""

from __future__ import annotations

import fcntl
import json
import os
import socket
import time
from pathlib import Path
from typing import Self

LOCK_FILE = ".axiform.lock"


class FolderLocked(Exception):
    """The folder is being written by another run; the message names it (pid, start)."""


def holder_text(path: Path) -> str:
    """Who holds a lock, from its file: 'pid N on HOST, started T', or what is known."""
    try:
        who = json.loads(path.read_text())
        return f"pid {int(who['pid'])} on {who['host']}, started {who['start']}"
    except (OSError, ValueError, KeyError, TypeError):
        return "a run whose lock file says no more"


class FolderLock:
    """`with FolderLock(folder):` holds the folder's lock for the block (FolderLocked when
    another process holds it), then removes the lock file."""

    def __init__(self, folder: str | Path):
        self.path = Path(folder) / LOCK_FILE
        self.fd: int | None = None

    def acquire(self) -> None:
        """Take the lock or raise FolderLocked.  A lock file whose process is gone holds no
        lock: it is taken over.  After taking it, the file must still be the one at the path
        (not removed by the run that just ended): else the lock is taken again."""
        for _ in range(100):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise FolderLocked(
                    f"{self.path.parent} is being written by another run ({holder_text(self.path)}); "
                    "wait for it to end, or give another --out"
                ) from None
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.path))
            except FileNotFoundError:
                same = False
            if same:
                self.fd = fd
                who = {
                    "pid": os.getpid(),
                    "host": socket.gethostname(),
                    "start": time.strftime("%Y-%m-%d %H:%M:%S %z"),
                }
                os.ftruncate(fd, 0)
                os.write(fd, (json.dumps(who) + "\n").encode())
                return
            os.close(fd)
        raise FolderLocked(f"{self.path.parent}: its lock file keeps changing under this run")

    def release(self) -> None:
        """Remove the lock file and drop the lock (once)."""
        if self.fd is None:
            return
        try:
            self.path.unlink(missing_ok=True)
        except OSError:
            pass  # a folder that turned read-only: the lock goes with the process all the same
        os.close(self.fd)  # closing drops the flock
        self.fd = None

    def __enter__(self) -> Self:
        self.acquire()
        return self

    def __exit__(self, *exc) -> None:
        self.release()
