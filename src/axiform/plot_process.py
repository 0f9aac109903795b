"""The PNG plots of `axiform run` drawn by a second Python process, started before the model
is built when a core is idle (`idle_cores`): it imports matplotlib (0.3 to 0.5 s, half of what the plots cost) on the other core
while this one builds and solves, then waits for the results folder and draws its plots
(`plots.plot_jobs`, each picture in its own forked copy: `draw_in_parallel`) when the run
ends.  While it waits it draws a small figure to memory (fonts loaded, caches filled: the
plots then take 0.1 to 0.25 s less).

The second process ignores SIGINT (a Ctrl-C reaches the whole process group; the run winds
up and still asks for its plots) and leaves without drawing when its input closes unasked,
as it does when the run dies.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Self

# the folder containing the axiform package: the second process imports this same code
_ROOT = str(Path(__file__).resolve().parent.parent)


def idle_cores() -> float:
    """The cores this process may run on less the load average of the last minute (Linux,
    macOS; 0 elsewhere).  A second process pays only with a core idle: on a busy machine it
    adds its start (0.2 to 0.35 s of CPU: Python, NumPy, a figure) to the work
    (benchmarks/README.md § 3.5)."""
    try:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
        return cores - os.getloadavg()[0]
    except (OSError, AttributeError):
        return 0.0


class PlotProcess:
    """A plotting process for one run: `plot(folder)` once, or nothing (the `with` block's
    end ends it)."""

    def __init__(self):
        code = f"import sys; sys.path.insert(0, {_ROOT!r}); from axiform.plot_process import serve; serve()"
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def plot(self, folder: str | Path) -> list[Path]:
        """Draw the plots of `folder` there; returns the files written.  RuntimeError with
        the process's last line when it failed."""
        out, err = self.proc.communicate(f"{folder}\n")
        if self.proc.returncode != 0:
            last = err.strip().splitlines()[-1] if err.strip() else f"exit code {self.proc.returncode}"
            raise RuntimeError(f"plotting {folder} failed: {last}")
        return [Path(line) for line in out.splitlines()]

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        if self.proc.returncode is None:  # never asked (an invalid case, a failed start)
            self.proc.kill()
            self.proc.communicate()


def _warm_up() -> None:
    """Draw a small figure with the artists of the plots (lines, labels, a title, a colour
    bar, constrained layout) to memory: the first figure of a process loads the fonts."""
    import io

    from matplotlib.cm import ScalarMappable

    from .plots import _pyplot

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(3, 2), layout="constrained")
    ax.plot([0.0, 1.0], [0.0, 1.0], "o-")
    ax.set_xlabel("r (in)")
    ax.set_ylabel("λ")
    fig.suptitle("warm-up")
    fig.colorbar(ScalarMappable(cmap="viridis"), ax=ax, label="σ")
    fig.savefig(io.BytesIO(), format="png", dpi=110)
    plt.close(fig)


def serve() -> None:
    """The second process: import what the plots need, read one folder from stdin, plot it,
    print the files written; nothing when stdin closes empty."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import meshio  # noqa: F401 - read by plot_folder: imported while the run solves

    import numpy as np

    from .plots import plot_jobs

    _warm_up()
    folder = sys.stdin.readline().strip()
    if folder:
        with np.errstate(all="ignore"):  # as in `axiform run`
            jobs = plot_jobs(folder)
            # the run waits: its core and any other idle one draw
            made = draw_in_parallel(jobs) if idle_cores() >= 2.0 else [job() for job in jobs]
            for png in filter(None, made):
                print(png)


def draw_in_parallel(jobs: list) -> list[Path]:
    """Run the drawing functions `jobs` (plots.plot_jobs), all but the first in forked copies
    of this process (they share its imported matplotlib), the first here; the files drawn, in
    the jobs' order; without fork (Windows) one after the other.  RuntimeError with the
    failure of a child.  Worth it with two cores idle (idle_cores): the run waits for its
    plots, and the plate's three take 0.09, 0.18 and 0.11 s of CPU."""
    if not hasattr(os, "fork") or len(jobs) < 2:
        return [p for p in (job() for job in jobs) if p is not None]
    sys.stdout.flush()
    sys.stderr.flush()
    children = []
    for job in jobs[1:]:
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: draw, say the file (or the error), leave without cleanup
            os.close(read)
            try:
                made, code = str(job() or ""), 0
            except BaseException as exc:  # noqa: BLE001 - reported by the parent
                made, code = f"{type(exc).__name__}: {exc}", 1
            os.write(write, made.encode())
            os._exit(code)
        os.close(write)
        children.append((pid, read))
    made = [jobs[0]()]
    failures = []
    for pid, read in children:
        with os.fdopen(read, "rb") as fh:
            said = fh.read().decode()
        _, status = os.waitpid(pid, 0)
        if os.waitstatus_to_exitcode(status) == 0:
            made.append(Path(said) if said else None)
        else:
            failures.append(said or f"a drawing process ended with status {status}")
    if failures:
        raise RuntimeError(failures[0])
    return [p for p in made if p is not None]
