"""The asserted part of a validation script: each comparison a named quantity against its
stated tolerance.  The table of every check goes into the script's results file; a script
with a failed check exits 1 after writing it, naming the checks that failed."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
WORK = HERE / "work"  # the peers' decks and outputs, written again by every run (not kept)


class Checks:
    """Comparisons against tolerances: `below(what, value, limit)` holds where
    |value| <= limit, `above(what, value, limit)` where value >= limit."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, float, str, bool]] = []

    def below(self, what: str, value: float, limit: float) -> None:
        self.rows.append((what, float(value), f"<= {limit:.3g}", bool(abs(value) <= limit)))

    def above(self, what: str, value: float, limit: float) -> None:
        self.rows.append((what, float(value), f">= {limit:.3g}", bool(value >= limit)))

    def failed(self) -> list[str]:
        return [what for what, _, _, ok in self.rows if not ok]

    def table(self) -> list[str]:
        """The markdown table of every check, its value, its tolerance and the verdict."""
        out = ["## Checks", "", "| check | value | tolerance | |", "|---|---:|---:|---|"]
        out += [
            f"| {what} | {value:.3g} | {limit} | {'ok' if ok else '**FAILED**'} |"
            for what, value, limit, ok in self.rows
        ]
        return out

    def finish(self) -> int:
        """Print the failures; the exit status of the script (0: every check holds)."""
        bad = self.failed()
        for what in bad:
            print(f"FAILED: {what}", file=sys.stderr)
        print(f"{len(self.rows) - len(bad)} of {len(self.rows)} checks hold")
        return 1 if bad else 0


def have_ccx(script: str) -> bool:
    """Whether CalculiX's `ccx` is on the PATH; if not, say that `script` is skipped."""
    if shutil.which("ccx") is not None:
        return True
    print(f"{script}: skipped, CalculiX not found (apt-get install calculix-ccx puts `ccx` on the PATH)")
    return False
