"""What a command imports, read from sys.modules of a fresh Python: the command line alone
loads no library; a run loads the drawing library only to draw, the VTU writer only to write
VTU files, the fitting and dense linear algebra of SciPy, DXF, Dask and the XML writer only
where a case needs them, and the schemas and model code of contact, cavities, heat and
gravity only where the case has them.  A structural guard of a run's fixed cost
(benchmarks/fixed_cost.py measures it)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLATE = ROOT / "examples" / "hughes_carnoy_plate.toml"
DRAWING = ("matplotlib", "PIL")
HEAVY = ("meshio", "scipy.optimize", "scipy.linalg", "scipy.spatial", "ezdxf", "dask", "xml.etree")
# the case tables and model code of physics the plate lacks (moulds, gas cavities, heat,
# temperature, weight), and the lists of keys for messages of the command line
NOT_IN_THE_PLATE = (
    "axiform.case.contact",
    "axiform.case.cavity",
    "axiform.case.temperature",
    "axiform.case.thermal",
    "axiform.case.gravity",
    "axiform.contact",
    "axiform.fem.heat",
    "axiform.model.gravity",
)


def modules_after(code: str) -> set[str]:
    """The modules loaded by `code` run in a fresh Python (axiform from this checkout)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", probe], env=env, cwd=ROOT, capture_output=True, text=True, check=True)
    return set(json.loads(done.stdout.strip().splitlines()[-1]))


def loaded(modules: set[str], names: tuple[str, ...]) -> list[str]:
    return [n for n in names if n in modules]


def run_code(out: Path, *sets: str) -> str:
    argv = [
        "run",
        str(PLATE),
        "--out",
        str(out),
        "-q",
        "--set",
        "solver.steps=4",
        *(a for s in sets for a in ("--set", s)),
    ]
    return f"import axiform.cli\nassert axiform.cli.main({argv!r}) == 0"


def test_the_command_line_alone_imports_no_library():
    modules = modules_after("import axiform.cli")
    assert loaded(modules, ("numpy", "scipy", "pydantic", *DRAWING, *HEAVY)) == []


def test_a_run_without_pictures_and_vtu_files_imports_neither(tmp_path):
    modules = modules_after(run_code(tmp_path / "off", "output.plots=false", "output.vtu=false"))
    assert "axiform.solve.solver" in modules and "scipy.sparse" in modules
    assert loaded(modules, (*DRAWING, *HEAVY)) == []


def test_a_plain_run_imports_no_table_or_model_of_physics_the_case_lacks(tmp_path):
    modules = modules_after(run_code(tmp_path / "off", "output.plots=false", "output.vtu=false"))
    assert "axiform.case.material" in modules and "axiform.case.monitor" in modules
    assert [m for m in modules if m.startswith(NOT_IN_THE_PLATE)] == []


def test_a_mould_brings_its_table_and_the_contact_code():
    case = ROOT / "examples" / "die_drawing.toml"
    modules = modules_after(
        f"from axiform.case.schema import build, load\nbuild(load({str(case)!r}), {str(case.parent)!r})"
    )
    assert "axiform.case.contact" in modules and "axiform.contact.pair" in modules
    assert (
        loaded(modules, ("axiform.case.cavity", "axiform.case.gravity", "axiform.case.thermal", "axiform.fem.heat"))
        == []
    )


def test_vtu_files_bring_their_writer_and_no_drawing(tmp_path):
    modules = modules_after(run_code(tmp_path / "vtu", "output.plots=false"))
    assert "meshio" in modules
    assert loaded(modules, DRAWING) == []
