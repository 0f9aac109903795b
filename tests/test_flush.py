"""history.csv, summary.json, thickness.csv and fields.pvd rewritten at most every
flush_every_s (as `axiform run` writes them): the first step at once, the rows of every
checkpoint before it, every step at the end, the same files as when written every step."""

import json
from pathlib import Path

import pytest

from axiform.case.schema import build, load
from axiform.io.results import ResultsWriter
from axiform.solve.solver import solve

PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"


def _run(out: Path, flush_every_s: float, seen: list) -> None:
    case = load(PLATE, ["solver.steps=6", "solver.target=1.5"])
    built = build(case, PLATE.parent)
    writer = ResultsWriter(
        out, built.model, built.monitors, case.title, plots=False, restart_every=4, flush_every_s=flush_every_s
    )

    def on_step(step):
        writer.step(step)
        rows = (out / "history.csv").read_text().splitlines()[1:]
        summary = json.loads((out / "summary.json").read_text())
        pvd = (out / "fields.pvd").read_text().count("<DataSet")
        seen.append((len(rows), summary["steps"], pvd))

    result = solve(built.model, built.control, built.options, on_step=on_step, keep=1)
    writer.finish(result.status, result.message)


def test_files_written_in_batches_hold_every_step_at_the_end(tmp_path):
    seen_each, seen_batch = [], []
    _run(tmp_path / "each", 0.0, seen_each)
    _run(tmp_path / "batch", 1e9, seen_batch)
    assert seen_each == [(k + 1, k, k) for k in range(1, 7)]  # history.csv: the t = 0 row and the steps
    # step 1 at once, steps 2-4 before the checkpoint of step 4, nothing more until finish
    assert seen_batch == [(2, 1, 1), (2, 1, 1), (2, 1, 1), (5, 4, 4), (5, 4, 4), (5, 4, 4)]
    for name in ("history.csv", "thickness.csv", "fields.pvd"):
        assert (tmp_path / "batch" / name).read_text() == (tmp_path / "each" / name).read_text(), name
    summaries = [json.loads((tmp_path / d / "summary.json").read_text()) for d in ("each", "batch")]
    for s in summaries:
        s.pop("wall_time_s")
    assert summaries[0] == summaries[1] and summaries[1]["steps"] == 6


def test_fields_pvd_lists_only_vtu_files_written(tmp_path):
    """The VTU files are written by a second thread: fields.pvd, whenever it is read, names
    files that are there and whole."""
    import meshio

    case = load(PLATE, ["solver.steps=5", "solver.target=1.5"])
    built = build(case, PLATE.parent)
    out = tmp_path / "out"
    writer = ResultsWriter(out, built.model, built.monitors, case.title, plots=False, flush_every_s=0.0)
    listed = []

    def on_step(step):
        writer.step(step)
        names = [
            line.split('file="')[1].split('"')[0]
            for line in (out / "fields.pvd").read_text().replace(">", ">\n").splitlines()
            if 'file="' in line
        ]
        for name in names:
            assert meshio.read(out / name).points.shape[0] == built.model.mesh.n_nodes
        listed.append(len(names))

    result = solve(built.model, built.control, built.options, on_step=on_step, keep=1)
    writer.finish(result.status, result.message)
    assert listed == [1, 2, 3, 4, 5]
    assert sorted(p.name for p in (out / "fields").glob("*.vtu")) == [f"step_{k:04d}.vtu" for k in range(1, 6)]


@pytest.mark.parametrize("bad", [3, 6])  # 6: the last step, found by `finish`
def test_a_vtu_file_that_cannot_be_written_fails_the_run_keeping_the_steps_before(tmp_path, monkeypatch, capsys, bad):
    """Found at a later step or by `finish` (the thread writes it while the run goes on):
    status "failed", exit 3, the message says why, fields.pvd lists the files written."""
    from axiform.cli import main
    from axiform.io import results

    write_vtu = results.write_vtu

    def full_disk(path, mesh, data):
        if path.name == f"step_{bad:04d}.vtu":
            raise OSError(28, "No space left on device")
        write_vtu(path, mesh, data)

    monkeypatch.setattr(results, "write_vtu", full_disk)
    out = tmp_path / "out"
    assert (
        main(
            [
                "run",
                str(PLATE),
                "--out",
                str(out),
                "-q",
                "--set",
                "output.plots=false",
                "--set",
                "solver.steps=6",
                "--set",
                "solver.target=1.5",
            ]
        )
        == 3
    )
    err = capsys.readouterr().out  # the status line (stdout) says why
    assert "No space left on device" in err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "No space left on device" in summary["message"]
    pvd = (out / "fields.pvd").read_text()
    assert "step_0002.vtu" in pvd and f"step_{bad:04d}.vtu" not in pvd
    assert not (out / "fields" / f"step_{bad:04d}.vtu").exists()
