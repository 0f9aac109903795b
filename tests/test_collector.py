"""The garbage collector around a run (app.collector.SetUp): paused while the case is read and
built, what exists then frozen out of its sight for the solve, and handed back when the run
ends unless the process ends with it (the command line)."""

from __future__ import annotations

import gc
from pathlib import Path

import pytest

import axiform.solve.solver as solver
from axiform.app import run as app_run
from axiform.app.collector import SetUp

PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"
QUICK = ["solver.steps=2", "solver.target=0.5", "output.plots=false", "output.vtu=false"]


@pytest.fixture
def seen(monkeypatch):
    """What the collector is doing while the case is read and while the solve runs."""
    out = {}
    read, solve = app_run.Job.read.__func__, solver.solve

    def reading(cls, *args, **kwargs):
        out["reading"] = gc.isenabled()
        return read(cls, *args, **kwargs)

    def solving(*args, **kwargs):
        out["solving"] = gc.isenabled(), gc.get_freeze_count()
        return solve(*args, **kwargs)

    monkeypatch.setattr(app_run.Job, "read", classmethod(reading))
    monkeypatch.setattr(solver, "solve", solving)
    yield out
    gc.unfreeze()
    gc.enable()


def test_a_run_sets_up_without_collections_and_solves_with_the_set_up_frozen(tmp_path, seen):
    assert app_run.run(str(PLATE), str(tmp_path / "out"), quiet=True, overrides=QUICK) == 0
    enabled, frozen = seen["solving"]
    assert seen["reading"] is False and enabled is True
    assert frozen > 10_000  # the modules, the schemas, the model
    assert gc.isenabled() and gc.get_freeze_count() == 0  # a caller running more runs gets it all back


def test_the_command_line_keeps_the_set_up_frozen_to_the_end(tmp_path, seen):
    assert app_run.run(str(PLATE), str(tmp_path / "out"), quiet=True, overrides=QUICK, last=True) == 0
    assert gc.isenabled() and gc.get_freeze_count() > 10_000


def test_an_invalid_case_leaves_the_collector_as_it_was(tmp_path):
    gc.disable()
    try:
        assert app_run.run(str(PLATE), str(tmp_path / "out"), quiet=True, overrides=["solver.steps=0"]) == 2
        assert not gc.isenabled() and gc.get_freeze_count() == 0
    finally:
        gc.unfreeze()
        gc.enable()


def test_the_collector_is_resumed_even_where_the_set_up_fails():
    with pytest.raises(RuntimeError), SetUp() as setup:
        try:
            raise RuntimeError("while building")
        finally:
            setup.done()
    assert gc.isenabled() and gc.get_freeze_count() == 0


def test_check_reads_and_builds_with_the_collector_paused(monkeypatch):
    from axiform.app import check as app_check
    from axiform.case import preflight

    seen = []
    checks = preflight.preflight

    def checking(built):
        seen.append(gc.isenabled())
        return checks(built)

    monkeypatch.setattr(preflight, "preflight", checking)
    try:
        assert app_check.check(str(PLATE), QUICK) == 0
        assert seen == [False] and gc.isenabled() and gc.get_freeze_count() == 0
    finally:
        gc.unfreeze()
        gc.enable()


def test_a_run_in_another_thread_leaves_the_collector_alone():
    import threading

    seen = []

    def body():
        with SetUp() as setup:
            seen.append(gc.isenabled())
            setup.done()
            seen.append(gc.get_freeze_count())

    worker = threading.Thread(target=body)
    worker.start()
    worker.join()
    assert seen == [True, 0] and gc.isenabled()
