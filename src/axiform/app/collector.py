"""Python's cyclic garbage collector around a run.

Reading, validating and building a case imports NumPy, SciPy, pydantic and axiform and builds
the case's schemas and the model: some 1e5 objects that live as long as the run, next to no
garbage among them (about 1,000 objects on the paper's plate).  Each full collection walks all
of them: during the set-up, during the solve, and once more when the interpreter ends, some
20 ms each on the plate (benchmarks/README.md § 7.1).  `SetUp` pauses the collector while the
run is set up, then freezes what exists out of its sight (gc.freeze) for the solve.
"""

from __future__ import annotations

import gc
import threading
from typing import Self


class SetUp:
    """A `with` block around a run, whose set-up ends with `done()`: the collector is paused
    until then, and what exists then is frozen out of its sight.  At the end of the block the
    frozen objects are handed back to it (gc.unfreeze), unless `last`: the process ends with
    the run (the command line), and its interpreter's final collection would walk them again.
    The collector is left enabled or disabled as it was found.  Only in the main thread: the
    collector is the process's, and runs in other threads (a Dask worker's) may overlap."""

    def __init__(self, last: bool = False):
        self.last = last
        self.active = threading.current_thread() is threading.main_thread()
        self.enabled = False
        self.frozen = False

    def __enter__(self) -> Self:
        if self.active:
            self.enabled = gc.isenabled()
            gc.disable()
        return self

    def done(self) -> None:
        """The set-up is over: what exists now is frozen, the collector resumed."""
        if not self.active:
            return
        if not self.frozen:
            gc.freeze()
            self.frozen = True
        if self.enabled:
            gc.enable()

    def __exit__(self, *exc) -> None:
        if self.frozen and not self.last:
            gc.unfreeze()
        if self.enabled:
            gc.enable()
