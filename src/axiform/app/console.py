"""What the commands print on the console.  Two streams: stdout carries what a command
produces (a run's progress lines and its final status line, check's verdict, the files
written); stderr the warnings (`warn`) and errors (`say`, `invalid`, `failed`); the traceback
of an unexpected error on request (`trace`); the progress line of a run or a sweep
(`ProgressLine`: a tqdm bar on a terminal, one line per update elsewhere, at most 80 columns).

A closed reader never stops a command (`guarded_streams`): `axiform run CASE | head -3` goes
on, writes every file and exits with the run's own code; what it would still print is dropped.
"""

from __future__ import annotations

import errno
import io
import os
import sys
import time
import traceback
from contextlib import contextmanager
from pathlib import Path
from typing import Any

# the widest progress line (a terminal's width when it is narrower)
COLUMNS = 80


def apart(value: float, previous: float | None, digits: int = 4) -> str:
    """value with `digits` significant digits, or as many more (up to 15) as tell it from
    `previous` (None: none before): two steps a cut apart (t 0.938574 and 0.938647) do not
    read as one time printed twice."""
    for n in range(digits, 16):
        text = f"{value:.{n}g}"
        if previous is None or value == previous or text != f"{previous:.{n}g}":
            return text
    return text


class Guarded:
    """A text stream that a closed reader cannot break: the first write or flush that finds
    the pipe closed (BrokenPipeError, EPIPE) points the stream's file descriptor at os.devnull
    (so that the interpreter's own flush at exit finds nothing to complain about, as Python's
    documentation on SIGPIPE suggests) and every later write is dropped.  A stream closed
    before the command started (None: Python's sys.stdout under `>&-`) drops every write from
    the start.  All else is the wrapped stream's."""

    def __init__(self, stream):
        self._stream = stream
        self.broken = stream is None

    def _drop(self) -> None:
        self.broken = True
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(devnull, self._stream.fileno())
            finally:
                os.close(devnull)
        except (OSError, ValueError, AttributeError, io.UnsupportedOperation):
            pass  # no descriptor (a StringIO, pytest's capture): dropping the writes is enough

    def _guard(self, name: str, *args):
        """The wrapped stream's method `name` called with args, unless the stream is broken."""
        if self.broken:
            return None
        try:
            return getattr(self._stream, name)(*args)
        except OSError as exc:  # BrokenPipeError, or EPIPE / EINVAL on a closed pipe elsewhere
            if not isinstance(exc, BrokenPipeError) and exc.errno not in (errno.EPIPE, errno.EINVAL):
                raise
            self._drop()
            return None
        except ValueError:  # "I/O operation on closed file": the stream itself was closed
            self.broken = True
            return None

    def write(self, text: str) -> int:
        self._guard("write", text)
        return len(text)

    def writelines(self, lines) -> None:
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        self._guard("flush")

    def isatty(self) -> bool:
        return not self.broken and bool(self._guard("isatty"))

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextmanager
def guarded_streams():
    """sys.stdout and sys.stderr Guarded while the block runs (a command); both flushed at
    its end, still guarded, then the originals put back."""
    old = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = Guarded(old[0]), Guarded(old[1])
    try:
        yield
    finally:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
        sys.stdout, sys.stderr = old


def say(*lines: str) -> None:
    """Print lines on stderr (the channel of errors and warnings)."""
    print(*lines, sep="\n", file=sys.stderr)


def warn(*lines: str) -> None:
    """Each line on stderr as `warning: <line>`."""
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)


def tell(*lines: str, stream=None) -> None:
    """Print lines on stdout (or stream), flushed: what the command produces (a status line)."""
    stream = stream or sys.stdout
    print(*lines, sep="\n", file=stream)
    stream.flush()


def trace(exc: BaseException) -> None:
    """The traceback of an unexpected error, only with AXIFORM_TRACEBACK=1 (for a bug report)."""
    if os.environ.get("AXIFORM_TRACEBACK") == "1":
        traceback.print_exception(exc)


def invalid(case_file: Path, exc: Exception) -> int:
    """Report an invalid case; returns its exit code, 2."""
    say(f"axiform: invalid case {case_file}:", str(exc))
    return 2


def failed(exc: Exception, what: str) -> int:
    """Report an unexpected error (a fault of axiform's, not of the input); returns exit code 3."""
    say(f"axiform: {what}: {type(exc).__name__}: {exc}")
    trace(exc)
    return 3


class ProgressLine:
    """Progress: on a terminal a tqdm bar of 16 characters rewritten in place, followed by a
    text, the whole within COLUMNS (or the terminal's width); elsewhere (a log, CI) one line
    per update; nothing when quiet.  `elapsed` counts from the creation."""

    def __init__(self, stream, total: float, quiet: bool = False):
        self.stream = stream
        self.total = total
        self.quiet = quiet
        self.tty = stream.isatty() and not quiet
        self.t0 = time.perf_counter()
        self._bar: Any = None  # a tqdm bar, made at the first update on a terminal

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def show(self, done: float, bar_text: str, log_line: str) -> None:
        """`done` of `total` on the bar with bar_text after it (terminal), or log_line."""
        if self.quiet:
            return
        if not self.tty:
            self.stream.write(log_line + "\n")
            self.stream.flush()
            return
        if self._bar is None:  # at the first update: messages before it stay above the bar
            from tqdm import tqdm

            try:  # a terminal that says no size (0 x 0, as a pseudo-terminal may): COLUMNS
                size = os.get_terminal_size(self.stream.fileno())
                width, height = min(size.columns or COLUMNS, COLUMNS), size.lines or 10**4
            except (OSError, ValueError, AttributeError):
                width, height = COLUMNS, None
            self._bar = tqdm(
                total=self.total,
                file=self.stream,
                bar_format="[{bar:16}] {desc}",
                ascii="-#",
                ncols=width,
                nrows=height,
                mininterval=0,
                leave=True,
            )
        self._bar.n = min(max(done, 0), self.total)
        self._bar.set_description_str(bar_text, refresh=False)
        self._bar.refresh()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
