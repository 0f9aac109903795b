"""history.csv, summary.json, thickness.csv and fields.pvd rewritten at most every
flush_every_s (as `axiform run` writes them): the first step at once, the rows of every
checkpoint before it, every step at the end, the same files as when written every step."""

import json
from pathlib import Path

from axiform.case import build, load
from axiform.results import ResultsWriter
from axiform.solver import solve

PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"


def _run(out: Path, flush_every_s: float, seen: list) -> None:
    case = load(PLATE, ["solver.steps=6", "solver.target=1.5"])
    built = build(case, PLATE.parent)
    writer = ResultsWriter(out, built.model, built.monitors, case.title, plots=False, restart_every=4,
                           flush_every_s=flush_every_s)

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
    assert seen_each == [(k, k, k) for k in range(1, 7)]
    # step 1 at once, steps 2-4 before the checkpoint of step 4, nothing more until finish
    assert seen_batch == [(1, 1, 1), (1, 1, 1), (1, 1, 1), (4, 4, 4), (4, 4, 4), (4, 4, 4)]
    for name in ("history.csv", "thickness.csv", "fields.pvd"):
        assert (tmp_path / "batch" / name).read_text() == (tmp_path / "each" / name).read_text(), name
    summaries = [json.loads((tmp_path / d / "summary.json").read_text()) for d in ("each", "batch")]
    for s in summaries:
        s.pop("wall_time_s")
    assert summaries[0] == summaries[1] and summaries[1]["steps"] == 6
