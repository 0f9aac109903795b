"""The plots of `axiform run` drawn by a second process (plot_process.py): the same pictures as
in this process, its failure reported, and no process left behind."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from axiform.post import plot_process
from axiform.cli import run
from axiform.post.plot_process import (CpuSample, PlotProcess, cores_left_idle, draw_in_parallel, drawing_workers,
                                  free_cores, idle_cores)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SRC = Path(__file__).resolve().parents[1] / "src"
PNGS = ["load_curve.png", "thickness.png", "deformed.png"]


def test_a_run_plots_in_a_second_process(tmp_path):
    out = tmp_path / "plate"
    assert run(str(EXAMPLES / "hughes_carnoy_plate.toml"), str(out), quiet=True,
               overrides=["solver.steps=3", "solver.target=1.0"], plot_process=True) == 0
    for png in PNGS:
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the same folder plotted again: the second process returns the files it wrote
    for png in PNGS:
        (out / png).unlink()
    with PlotProcess() as plotter:
        assert sorted(p.name for p in plotter.plot(out)) == sorted(PNGS)
    assert all((out / png).exists() for png in PNGS)


def test_a_case_without_plots_ends_the_plot_process_started_for_it(tmp_path):
    out = tmp_path / "plate"
    assert run(str(EXAMPLES / "hughes_carnoy_plate.toml"), str(out), quiet=True,
               overrides=["solver.steps=2", "solver.target=0.5", "output.plots=false"], plot_process=True) == 0
    assert (out / "summary.json").exists() and not list(out.glob("*.png"))


def test_the_command_plots(tmp_path):
    """`axiform run` from a shell: the plots come from a second process when cores are idle
    (cores_left_idle), from this one otherwise: the same files, no process left behind, the
    exit code and the last line as from main()."""
    out = tmp_path / "plate"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    proc = subprocess.run([sys.executable, "-m", "axiform.cli", "run", str(EXAMPLES / "hughes_carnoy_plate.toml"),
                           "--out", str(out), "-q", "--set", "solver.steps=2", "--set", "solver.target=0.5"],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert all((out / png).exists() for png in PNGS)
    assert "axiform: finished after 2 steps" in proc.stderr  # flushed before the exit without teardown
    bad = subprocess.run([sys.executable, "-m", "axiform.cli", "run", str(EXAMPLES / "hughes_carnoy_plate.toml"),
                          "--out", str(tmp_path / "bad"), "-q", "--set", "solver.steps=-1"],
                         env=env, capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "solver.steps" in bad.stderr


def test_a_failed_plot_raises_with_its_reason(tmp_path):
    (tmp_path / "history.csv").write_text("step,load_factor,iterations\n1,not a number,3\n")
    with PlotProcess() as plotter, pytest.raises(RuntimeError, match="could not convert string to float"):
        plotter.plot(tmp_path)


def test_an_unused_plot_process_ends_with_its_block():
    with PlotProcess() as plotter:
        pass
    assert plotter.proc.returncode is not None
    with PlotProcess() as plotter:
        plotter.close()
        assert plotter.proc.returncode is not None
    with pytest.raises(subprocess.TimeoutExpired):  # nothing else: it waits for its folder
        with PlotProcess() as waiting:
            waiting.proc.wait(timeout=0.2)
    assert waiting.proc.returncode is not None


def test_idle_cores_read_the_load(monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.4, 0.0, 0.0))
    assert idle_cores() == pytest.approx(1.6)


def test_drawing_in_parallel_keeps_the_order_and_reports_a_failure(tmp_path):
    def draw(name):
        def job():
            (tmp_path / name).write_text(name)
            return tmp_path / name
        return job

    def nothing():
        return None

    def broken():
        raise ValueError("no such field")

    for workers in (1, 2, 3, 5):
        assert draw_in_parallel([draw("a"), nothing, draw("b"), draw("c")], workers) == [tmp_path / n for n in "abc"]
        assert (tmp_path / "c").read_text() == "c"
        (tmp_path / "c").unlink()
    with pytest.raises(RuntimeError, match="ValueError: no such field"):
        draw_in_parallel([draw("d"), broken], 2)


def test_the_cores_left_idle_do_not_count_the_run():
    """Over 1 s the two cores were busy 1.9 s: 1.8 s of them the run's (its solve and the
    plot process's warm-up), so the other processes left 1.9 cores idle; busy 2 s with 0.9 s
    the run's, one other process held a core throughout."""
    assert free_cores(2, busy_s=1.9, ours_s=1.8, elapsed_s=1.0) == pytest.approx(1.9)
    assert free_cores(2, busy_s=2.0, ours_s=0.9, elapsed_s=1.0) == pytest.approx(0.9)
    assert free_cores(2, busy_s=0.5, ours_s=0.6, elapsed_s=1.0) == 2.0  # clock ticks: never more than all
    assert free_cores(4, busy_s=6.0, ours_s=2.0, elapsed_s=2.0) == pytest.approx(2.0)


@pytest.mark.parametrize(("free", "jobs", "workers"), [
    (2.0, 3, 2), (1.8, 3, 2), (1.7, 3, 1), (0.9, 3, 1), (0.0, 3, 1), (-1.5, 3, 1),  # busy: no oversubscription
    (4.0, 3, 3), (2.0, 1, 1), (2.0, 0, 1)])
def test_the_pictures_are_drawn_on_the_cores_left_idle(free, jobs, workers):
    assert drawing_workers(free, jobs) == workers


@pytest.mark.skipif(not Path("/proc/stat").exists(), reason="CPU counters of Linux")
def test_the_counters_take_this_process_as_the_run(monkeypatch):
    started = CpuSample.now()
    end = time.monotonic() + 0.3
    while time.monotonic() < end:
        pass
    now = CpuSample.now()
    # this loop: ours, not load (in seconds, not clock ticks); at most its wall time, less on a
    # machine where other jobs take turns on this core
    assert 0.15 <= now.ours_s - started.ours_s <= 0.33
    assert now.busy_s - started.busy_s >= now.ours_s - started.ours_s - 0.05
    # over a window of the counters they decide; over a shorter one, the load average
    monkeypatch.setattr(plot_process, "idle_cores", lambda: -1.0)
    assert 0.0 <= cores_left_idle(started) <= len(os.sched_getaffinity(0))
    assert cores_left_idle(started, min_window_s=60.0) == -1.0
    assert cores_left_idle(None) == -1.0
