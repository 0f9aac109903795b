"""What a run leaves for a person to look at: the VTU series, thickness.csv, GiD files, the
3D revolved copy, the PNG plots; and the thickness itself against exact answers."""

import csv
import json
from pathlib import Path

import meshio
import numpy as np
import pytest

from axiform import rectangle
from axiform.cli import main
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Line, Profile, ProfileError
from axiform.post.thickness import thickness_table

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_thickness_of_a_homogeneous_stretch_is_exact(element):
    """U = a R, W = d Z: the wall (along z) gets thicker by exactly 1 + d."""
    mesh = rectangle((0.0, 3.0), (0.0, 0.4), (6, 2), element)
    u = np.column_stack([0.2 * mesh.points[:, 0], -0.3 * mesh.points[:, 1]])
    t = thickness_table(mesh, u)
    assert np.allclose(t["initial_thickness"], 0.4) and np.allclose(t["ratio"], 0.7)
    assert np.allclose(t["s"], np.linspace(0, 3.0, 7))
    assert np.allclose(t["r"], 1.2 * t["s"])


def test_layered_profile_geometry():
    """A tube (line) then a hemispherical cap (arc): area of the section, named sets, fibres."""
    prof = Profile((1.0, 0.0), (Line((1.0, 2.0), 8), Arc((0.0, 2.0), (0.0, 3.0), 8, ccw=True)))
    mesh = layered(prof, 0.1, 2, "q8")
    mesh.check()
    assert prof.length() == pytest.approx(2.0 + np.pi / 2)
    # meridian area: wall 0.1 thick along the mid-surface
    from axiform.fem.elements import gauss_quad, jacobian

    xi, w = gauss_quad(3)
    _, _, detJ, _ = jacobian(mesh.element, mesh.points[mesh.cells], xi)
    assert (detJ * w).sum() == pytest.approx(0.1 * (2.0 + np.pi / 2), rel=1e-4)
    # travelling up the tube the left side is the axis side: top = inner
    assert np.array_equal(mesh.node_sets["inner"], mesh.node_sets["top"])
    assert np.allclose(mesh.points[mesh.node_sets["start"], 1], 0.0)
    assert np.allclose(mesh.points[mesh.node_sets["end"], 0], 0.0)
    assert mesh.fibres.shape == (17, 3)
    t = thickness_table(mesh, np.zeros((mesh.n_nodes, 2)))
    assert np.allclose(t["thickness"], 0.1, rtol=2e-2)


def test_a_profile_without_pieces_is_refused():
    with pytest.raises(ProfileError, match="at least one piece"):
        Profile((1.0, 0.0), ()).sample()


def test_graded_wall_from_a_table():
    prof = Profile((1.0, 0.0), (Line((1.0, 4.0), 8),))
    mesh = layered(prof, [[0.0, 0.2], [4.0, 0.1]], 1, "q4")
    t = thickness_table(mesh, np.zeros((mesh.n_nodes, 2)))
    assert np.allclose(t["thickness"], 0.2 - 0.025 * t["s"])


def test_balloon_case_writes_every_output(tmp_path):
    out = tmp_path / "balloon"
    assert main(["run", str(EXAMPLES / "balloon.toml"), "--out", str(out), "-q", "--set", "output.gid=true"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    rows = list(csv.DictReader(open(out / "history.csv")))
    assert summary["status"] == "finished" and summary["steps"] == len(rows) - 1 and rows[0]["step"] == "0"
    # the arc length passes the maximum: the load factor rises then falls
    lam = np.array([float(r["load_factor"]) for r in rows])
    assert lam.argmax() not in (0, len(lam) - 1)
    # thin incompressible sphere: thickness h0 / l^2 at stretch l
    data = np.genfromtxt(out / "thickness.csv", delimiter=",", names=True)
    l = np.hypot(data["r"], data["z"]) / 1.0
    assert np.allclose(data["thickness"], 0.01 / l**2, rtol=0.02)
    # ParaView series: a .pvd listing vtu files with the fields
    vtus = sorted((out / "fields").glob("*.vtu"))
    assert vtus and all(f"fields/{v.name}" in (out / "fields.pvd").read_text() for v in vtus)
    m = meshio.read(vtus[-1])
    for name in ("displacement", "J", "cauchy_stress", "von_mises", "principal_stretches"):
        assert name in m.point_data
    assert np.allclose(m.point_data["J"], 1.0, atol=0.02)
    # the hoop stretch equals r / R at every node
    R = m.points[:, 0]
    ok = R > 0.1
    hoop = m.point_data["principal_stretches"][ok, 2]
    assert np.allclose(hoop, (R[ok] + m.point_data["displacement"][ok, 0]) / R[ok], rtol=1e-2)
    # 3D copy for pictures
    rev = meshio.read(out / "revolved.vtu")
    assert rev.cells[0].type == "hexahedron" and len(rev.cells[0].data) == 36 * 16
    radius = np.linalg.norm(rev.points, axis=1)  # drawn in the deformed configuration
    assert np.allclose(radius, 5.0, rtol=0.01)  # the balloon is a sphere of radius ~5
    # GiD
    msh = (out / "axiform.post.msh").read_text()
    assert "ElemType Quadrilateral Nnode 8" in msh
    res = (out / "axiform.post.res").read_text()
    assert res.startswith("GiD Post Results File 1.0") and res.count('Result "von_mises"') == len(vtus)
    # pictures
    for png in ("load_curve.png", "thickness.png", "deformed.png"):
        assert (out / png).stat().st_size > 10_000


def test_plot_command(tmp_path, capsys):
    out = tmp_path / "plate"
    assert (
        main(
            [
                "run",
                str(EXAMPLES / "hughes_carnoy_plate.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "solver.target=2.0",
                "--set",
                "solver.steps=4",
                "--set",
                "output.plots=false",
            ]
        )
        == 0
    )
    assert not (out / "load_curve.png").exists()
    assert main(["plot", str(out), "--field", "J"]) == 0
    assert (out / "load_curve.png").exists() and (out / "deformed.png").exists()
    assert main(["plot", str(tmp_path)]) == 2


PNGS = ["load_curve.png", "thickness.png", "deformed.png"]


def test_a_run_draws_its_plots_and_a_case_without_plots_none(tmp_path):
    """The PNG plots of `axiform run` are drawn in its own process at the end of the run."""
    from axiform.app.run import run

    out = tmp_path / "plate"
    assert (
        run(
            str(EXAMPLES / "hughes_carnoy_plate.toml"),
            str(out),
            quiet=True,
            overrides=["solver.steps=3", "solver.target=1.0"],
        )
        == 0
    )
    for png in PNGS:
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    none = tmp_path / "none"
    assert (
        run(
            str(EXAMPLES / "hughes_carnoy_plate.toml"),
            str(none),
            quiet=True,
            overrides=["solver.steps=2", "solver.target=0.5", "output.plots=false"],
        )
        == 0
    )
    assert (none / "summary.json").exists() and not list(none.glob("*.png"))


def test_the_command_from_a_shell(tmp_path):
    """`axiform run` as a process: the plots, the exit code and the last line (the streams
    flushed by the interpreter's own teardown); an invalid case exits 2."""
    import os
    import subprocess
    import sys

    src = Path(__file__).resolve().parents[1] / "src"
    out = tmp_path / "plate"
    env = {**os.environ, "PYTHONPATH": str(src)}
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "axiform.cli",
            "run",
            str(EXAMPLES / "hughes_carnoy_plate.toml"),
            "--out",
            str(out),
            "-q",
            "--set",
            "solver.steps=2",
            "--set",
            "solver.target=0.5",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert all((out / png).exists() for png in PNGS)
    assert "axiform: finished after 2 steps" in proc.stdout
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "axiform.cli",
            "run",
            str(EXAMPLES / "hughes_carnoy_plate.toml"),
            "--out",
            str(tmp_path / "bad"),
            "-q",
            "--set",
            "solver.steps=-1",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert bad.returncode == 2 and "solver.steps" in bad.stderr


def test_a_run_says_why_a_picture_is_missing(tmp_path, capsys, monkeypatch):
    """Each picture not drawn is a `note:` line on stderr and in summary.json's `notes`; a mesh
    without through-thickness fibres (a gmsh mesh) has no thickness.png by design: no note."""
    out = tmp_path / "b"
    assert main(["run", str(EXAMPLES / "balloon.toml"), "--out", str(out), "-q", "--set", "output.vtu=false"]) == 0
    notes = json.loads((out / "summary.json").read_text())["notes"]
    assert notes == ["no deformed.png: no field output (output.vtu = false)"]
    assert "note: no deformed.png: no field output" in capsys.readouterr().err

    out = tmp_path / "d"
    assert main(["run", str(EXAMPLES / "balloon.toml"), "--out", str(out), "-q"]) == 0
    assert "notes" not in json.loads((out / "summary.json").read_text())
    assert "note:" not in capsys.readouterr().err

    import axiform.fem.mesh

    monkeypatch.setattr(axiform.fem.mesh, "_set_fibres", lambda *args: None)  # as a gmsh mesh
    out = tmp_path / "c"
    assert main(["run", str(EXAMPLES / "balloon.toml"), "--out", str(out), "-q", "--set", "output.vtu=false"]) == 0
    assert not (out / "thickness.png").exists() and (out / "load_curve.png").exists()
    assert json.loads((out / "summary.json").read_text())["notes"] == notes
    assert "thickness.png" not in capsys.readouterr().err
