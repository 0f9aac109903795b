"""The PNG plots of `axiform run` drawn by a second Python process, started first thing when
other processes leave about two cores idle (`cores_left_idle` over the run's first imports,
`PLOT_PROCESS_MIN_IDLE`): it imports matplotlib (0.3 to 0.5 s, half of what the plots cost)
on the other core while this one imports the case's modules, builds and solves, then waits
for the results folder and draws its plots (`plots.plot_jobs`) when the run ends, on as many
cores as other processes left idle while it waited (the run waits for its plots, its core is
free; `drawing_workers`, `draw_in_parallel`).  While it waits it draws a small figure to
memory (fonts loaded, caches filled: the plots then take 0.1 to 0.25 s less).

The second process ignores SIGINT (a Ctrl-C reaches the whole process group; the run winds
up and still asks for its plots) and leaves without drawing when its input closes unasked,
as it does when the run dies.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable, NamedTuple, Self

# the folder containing the axiform package: the second process imports this same code
_ROOT = str(Path(__file__).resolve().parents[2])


# a plot process is started when other processes leave this many cores idle: one for the
# run, most of one for the plot process's imports and warm-up (CpuSample's ticks are 10 ms)
PLOT_PROCESS_MIN_IDLE = 1.5


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


class CpuSample(NamedTuple):
    """CPU counters at one moment (Linux): the busy seconds of the cores this process may run
    on (/proc/stat), the CPU seconds of the run (this process, and process `also` if given:
    the run that a plot process serves), and the monotonic clock."""

    at: float
    busy_s: float
    ours_s: float
    also: int | None = None

    @classmethod
    def now(cls, also: int | None = None) -> "CpuSample | None":
        """The counters now; None without /proc (not Linux) or when it cannot be read."""
        try:
            cpus = {f"cpu{k}" for k in os.sched_getaffinity(0)}
            tick = os.sysconf("SC_CLK_TCK")
            with open("/proc/stat") as fh:
                rows = [line.split() for line in fh if line.split(maxsplit=1)[0] in cpus]
            # user nice system idle iowait irq softirq steal: all but idle and iowait
            busy = sum(sum(int(v) for v in r[1:4] + r[6:9]) for r in rows)
            own = os.times()
            ours = own.user + own.system
            if also is not None:
                with open(f"/proc/{also}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()  # utime, stime: fields 14 and 15
                ours += (int(fields[11]) + int(fields[12])) / tick
            return cls(time.monotonic(), busy / tick, ours, also)
        except (OSError, AttributeError, ValueError, IndexError):
            return None


def free_cores(cores: int, busy_s: float, ours_s: float, elapsed_s: float) -> float:
    """The cores that other processes left idle over `elapsed_s` seconds in which the cores
    were busy `busy_s` CPU seconds, `ours_s` of them this run's (its two processes)."""
    return cores - max(busy_s - ours_s, 0.0) / max(elapsed_s, 1e-9)


def drawing_workers(free: float, jobs: int) -> int:
    """How many processes draw `jobs` pictures with `free` cores idle: one for each core at
    least three quarters idle, at least one and at most one a picture."""
    return max(1, min(jobs, int(free + 0.25)))


def cores_left_idle(since: CpuSample | None, min_window_s: float = 0.2) -> float:
    """The cores other processes left idle since `since` (free_cores), the run's own
    processes not counted (a plot process: when the run asks for its plots it waits for
    them, its core is free).  Without CPU counters, or less than `min_window_s` since, the
    cores less the load average (idle_cores)."""
    now = CpuSample.now(since.also) if since is not None else None
    if now is None or now.at - since.at < min_window_s:
        return idle_cores()
    return free_cores(len(os.sched_getaffinity(0)), now.busy_s - since.busy_s, now.ours_s - since.ours_s,
                      now.at - since.at)


class PlotProcess:
    """A plotting process for one run: `plot(folder)` once, or nothing (the `with` block's
    end ends it)."""

    def __init__(self):
        code = f"import sys; sys.path.insert(0, {_ROOT!r}); from axiform.post.plot_process import serve; serve()"
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

    def close(self) -> None:
        """End the process if it was never asked (an invalid case, a failed start, a case
        without plots)."""
        if self.proc.returncode is None:
            self.proc.kill()
            self.proc.communicate()

    def __exit__(self, *exc) -> None:
        self.close()


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
    started = CpuSample.now(also=os.getppid())  # the run
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import meshio  # noqa: F401 - read by plot_folder: imported while the run solves

    import numpy as np

    from .plots import plot_jobs

    _warm_up()
    folder = sys.stdin.readline().strip()
    if folder:
        with np.errstate(all="ignore"):  # as in `axiform run`
            jobs = plot_jobs(folder)
            for png in draw_in_parallel(jobs, drawing_workers(cores_left_idle(started), len(jobs))):
                print(png)
        # the run waits for this process's end: the files are written and closed, and an
        # interpreter with matplotlib takes 0.1 to 0.15 s to tear down
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)


def draw_in_parallel(jobs: list[Callable[[], Path | None]], workers: int) -> list[Path]:
    """Run the drawing functions `jobs` (plots.plot_jobs) in `workers` processes, job k in
    process k mod workers: the first this one, the others forked copies of it (they share its
    imported matplotlib); the files drawn, in the jobs' order (without fork, as on Windows,
    all here).  RuntimeError with the failure of a child.  The run waits for its plots: the
    plate's three take 0.08, 0.14 and 0.09 s of CPU."""
    workers = min(workers, len(jobs)) if hasattr(os, "fork") else 1
    sys.stdout.flush()
    sys.stderr.flush()
    children = [_fork(jobs[k::workers]) for k in range(1, workers)]
    made = {0: [job() for job in jobs[::workers]]}
    failures = []
    for k, (pid, read) in enumerate(children, start=1):
        with os.fdopen(read, "rb") as fh:
            said = fh.read().decode()
        _, status = os.waitpid(pid, 0)
        if os.waitstatus_to_exitcode(status) == 0:
            made[k] = [Path(p) if p else None for p in said.split("\n")]
        else:
            failures.append(said or f"a drawing process ended with status {status}")
    if failures:
        raise RuntimeError(failures[0])
    in_order = [made[k % workers][k // workers] for k in range(len(jobs))]
    return [p for p in in_order if p is not None]


def _fork(jobs: list[Callable[[], Path | None]]) -> tuple[int, int]:
    """A forked copy of this process that runs `jobs` and writes their files (a line each,
    empty for none) or its error to a pipe, then leaves without cleanup; its pid and the
    pipe's end to read."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read)
        try:
            said, code = "\n".join(str(job() or "") for job in jobs), 0
        except BaseException as exc:  # noqa: BLE001 - reported by the parent
            said, code = f"{type(exc).__name__}: {exc}", 1
        os.write(write, said.encode())
        os._exit(code)
    os.close(write)
    return pid, read
