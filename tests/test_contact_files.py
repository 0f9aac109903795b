"""contact.csv and surfaces.csv: written with the other files of a flush (the first step at
once, then at most every flush_every_s, and whatever ends the run), the same bytes as a row
per node through csv.writer, and a run stopped midway keeps those of its last written step."""

import csv
import io
from pathlib import Path

import numpy as np
import pytest
from test_run_report import ring_case

from axiform.case.schema import build, parse
from axiform.contact.pair import STATUS
from axiform.io.files import contact_table
from axiform.io.results import NonFiniteResult, ResultsWriter
from axiform.solve.solver import solve

FILES = ("contact.csv", "surfaces.csv")


def _run(out: Path, flush_every_s: float, poison_at: int | None = None) -> list[dict[str, str]]:
    """The squeezed ring of test_run_report (4 steps); the contact files after each step.
    poison_at: the step whose displacements get an inf (refused by the writer: status stopped)."""
    built = build(parse(ring_case()), out)
    writer = ResultsWriter(out, built.model, title="ring", plots=False, flush_every_s=flush_every_s)
    seen = []

    def on_step(step):
        if step.number == poison_at:
            step.u[0] = np.inf
        writer.step(step)
        seen.append({name: (out / name).read_text() if (out / name).exists() else None for name in FILES})

    try:
        result = solve(built.model, built.control, built.options, on_step=on_step, keep=1)
        writer.finish(result.status, result.message)
    except NonFiniteResult as exc:
        writer.finish("stopped", str(exc))
    return seen


@pytest.fixture(scope="module")
def each_step(tmp_path_factory):
    out = tmp_path_factory.mktemp("each")
    return out, _run(out, 0.0)


def test_written_with_a_flush_and_at_the_end(each_step, tmp_path):
    each_dir, each = each_step
    batch = _run(tmp_path, 1e9)
    assert len(each) == len(batch) == 4
    assert len({s["contact.csv"] for s in each}) == 4  # the steps differ
    assert batch == [each[0]] * 4  # the first step at once, nothing more until finish
    for name in FILES:
        assert (tmp_path / name).read_bytes() == (each_dir / name).read_bytes()
        assert (each_dir / name).read_text() == each[-1][name]


def test_a_stopped_run_keeps_the_files_of_its_last_step(each_step, tmp_path):
    _, each = each_step
    seen = _run(tmp_path, 1e9, poison_at=3)
    assert len(seen) == 2  # step 3 refused before anything of it was written
    for name in FILES:
        assert (tmp_path / name).read_text() == each[1][name]


def _rows_by_csv_writer(reports: list[dict], x: np.ndarray) -> str:
    """contact.csv as a csv.writer row per node (the format's definition)."""
    text = io.StringIO()
    table = csv.writer(text, lineterminator="\n")
    table.writerow(["pair", "node", "r", "z", "gap", "pressure", "status", "first_contact"])
    for k, rep in enumerate(reports):
        for node, g, p, st, t in zip(
            rep["node"], rep["gap"], rep["pressure"], rep["status"], rep["first_contact"], strict=False
        ):
            r, z = x[node]
            table.writerow(
                [
                    k,
                    node,
                    f"{r:.10g}",
                    f"{z:.10g}",
                    "" if np.isnan(g) else f"{g:.6g}",
                    f"{p:.6g}",
                    STATUS[int(st)],
                    "" if np.isnan(t) else repr(float(t)),
                ]
            )
    return text.getvalue()


def test_the_table_is_the_rows_of_csv_writer():
    """Gaps and first contacts NaN or not, every status, negative zero, large and tiny numbers."""
    x = np.array([[0.0, 1.0], [-0.0, 1e-300], [123456789.123, -2.5e-7], [1.0 / 3.0, 1e20]])
    reports = [
        {
            "node": np.array([0, 1, 2]),
            "gap": np.array([np.nan, -0.0, 1.23456789e-5]),
            "pressure": np.array([0.0, 7.5e12, -1e-9]),
            "status": np.array([0, 1, 2]),
            "first_contact": np.array([np.nan, 0.1 + 0.2, 1.5]),
        },
        {
            "node": np.array([3, 0], dtype=np.int32),
            "gap": np.array([2.0, np.nan]),
            "pressure": np.array([np.pi, 0.0]),
            "status": np.array([3, 0]),
            "first_contact": np.array([1e-17, np.nan]),
        },
        {
            "node": np.array([], dtype=int),
            "gap": np.array([]),
            "pressure": np.array([]),
            "status": np.array([], int),
            "first_contact": np.array([]),
        },
    ]
    assert contact_table(reports, x, STATUS) == _rows_by_csv_writer(reports, x)


def test_a_failed_run_keeps_the_contact_table_of_its_last_step(tmp_path, monkeypatch):
    """`axiform run` failing midway (status failed, exit 3): contact.csv is that of the last
    converged step, its (r, z) the slave nodes moved by that step's displacements."""
    import json

    import meshio

    from axiform.cli import main
    from axiform.model import system as model_module

    calls = {"n": 0}
    evaluate = model_module.System.evaluate

    def crash_later(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > 20:
            raise RuntimeError("a fault in the law")
        return evaluate(self, *args, **kwargs)

    monkeypatch.setattr(model_module.System, "evaluate", crash_later)
    out = tmp_path / "out"
    toric = Path(__file__).resolve().parents[1] / "examples" / "toric_plate.toml"
    assert (
        main(["run", str(toric), "--out", str(out), "-q", "--set", "output.plots=false", "--set", "output.every=1"])
        == 3
    )
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert steps >= 2
    vtu = meshio.read(out / "fields" / f"step_{steps:04d}.vtu")
    x = vtu.points[:, :2] + vtu.point_data["displacement"][:, :2]
    rows = list(csv.DictReader((out / "contact.csv").read_text().splitlines()))
    assert rows
    for row in rows:
        node = int(row["node"])
        assert (row["r"], row["z"]) == (f"{x[node, 0]:.10g}", f"{x[node, 1]:.10g}")
