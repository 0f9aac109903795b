"""What the commands print on the console: messages on stderr (`say`, `invalid`, `failed`),
the traceback of an unexpected error on request (`trace`), and the progress line of a run or
a sweep (`ProgressLine`: a tqdm bar on a terminal, one line per update elsewhere)."""

from __future__ import annotations

import os
import sys
import time
import traceback
from pathlib import Path


def say(*lines: str) -> None:
    """Print lines on stderr (the channel of every message of the commands)."""
    print(*lines, sep="\n", file=sys.stderr)


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
    """Progress: on a terminal a tqdm bar of 30 characters rewritten in place, followed by a
    text; elsewhere (a log, CI) one line per update; nothing when quiet.  `elapsed` counts
    from the creation."""

    def __init__(self, stream, total: float, quiet: bool = False):
        self.stream = stream
        self.total = total
        self.quiet = quiet
        self.tty = stream.isatty() and not quiet
        self.t0 = time.perf_counter()
        self._bar = None

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

            try:  # a terminal that says no size (0 x 0, as a pseudo-terminal may): the whole line
                size = os.get_terminal_size(self.stream.fileno())
                width, height = size.columns or 10**4, size.lines or 10**4
            except (OSError, ValueError, AttributeError):
                width = height = None
            self._bar = tqdm(total=self.total, file=self.stream, bar_format="[{bar:30}] {desc}", ascii="-#",
                             ncols=width, nrows=height, mininterval=0, leave=True)
        self._bar.n = min(max(done, 0), self.total)
        self._bar.set_description_str(bar_text, refresh=False)
        self._bar.refresh()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
