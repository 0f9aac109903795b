"""The public names of `axiform` resolve, and axiform.solve runs a model (it is the package
solve/ and the solver function at once)."""

import ast
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

import axiform
from axiform.solve.solver import solve as solve_function

REFERENCE = Path(__file__).resolve().parents[1] / "docs" / "reference.md"


def documented_calls() -> tuple[str, dict[str, ast.Call]]:
    """The Python API section of docs/reference.md and the calls it writes in backquotes,
    `name(params)`, parsed (name -> the call's syntax tree)."""
    text = REFERENCE.read_text()
    section = text[text.index("## Python API") :]
    calls = {}
    for name, params in re.findall(r"`(\w+)\(([^`]*)\)`", section):
        try:
            call = ast.parse(f"f({params})", mode="eval").body
        except SyntaxError:
            continue
        calls.setdefault(name, call)
    return section, calls


def test_every_public_name_is_documented_with_its_call():
    """Each name of axiform.__all__ resolves, is named in the Python API section of
    docs/reference.md, and where it is written there as a call, the call is its signature:
    the positional parameters in order, each keyword a parameter with the default written."""
    section, calls = documented_calls()
    for name in axiform.__all__:
        value = getattr(axiform, name)
        assert f"`{name}" in section or f", `{name}`" in section, f"{name} is not in the reference"
        if name in ("ELEMENTS", "Q4", "Q8", "SFR"):
            kinds = axiform.ELEMENTS.values()
            assert value in kinds if name != "ELEMENTS" else set(value) == {"q4", "q8", "sfr"}
            continue
        if name == "Sensitivity":  # the result of sensitivity(...), not built by hand
            assert inspect.signature(axiform.sensitivity).return_annotation in ("Sensitivity", value)
            continue
        assert name in calls, f"{name}: the reference writes no call of it"
        target = solve_function if name == "solve" else value
        parameters = inspect.signature(target).parameters
        names = list(parameters)
        call = calls[name]
        positional = [a.id for a in call.args]
        assert names[: len(positional)] == positional, (name, positional, names)
        for keyword in call.keywords:
            assert keyword.arg in parameters, (name, keyword.arg)
            try:
                written = ast.literal_eval(keyword.value)
            except ValueError:  # a placeholder, not a default
                continue
            default = parameters[keyword.arg].default
            assert default is not inspect.Parameter.empty and default == written, (name, keyword.arg, default)


@pytest.mark.parametrize(
    "law, mu0",
    [
        (axiform.NeoHooke(0.3, 100.0), 0.6),
        (axiform.MooneyRivlin(0.3, 0.1, 100.0), 0.8),
        (axiform.Yeoh(0.3, -0.01, 0.001, 100.0), 0.6),
        (axiform.Ogden([0.5, 0.1], [2.0, -1.5], 100.0), 0.6),
        (axiform.Gent(0.5, 20.0, 100.0), 0.5),
        (
            axiform.ArrudaBoyce(0.5, 3.0, 100.0),
            0.5 * (1 + 3 / 45 + 99 / (175 * 81) + 513 / (875 * 729) + 42039 / (67375 * 6561)),
        ),
    ],
)
def test_every_law_has_the_documented_initial_shear_modulus(law, mu0):
    """Each law of the table of docs/reference.md: no stress at F = I, and in a small simple
    shear gamma of the meridian plane P_rZ = mu0 gamma, mu0 the table's."""
    identity = np.array([1.0, 0.0, 0.0, 1.0, 1.0])
    P, _ = law.stress_tangent(identity[None])
    assert np.abs(P).max() < 1e-12
    gamma = 1e-5
    P, _ = law.stress_tangent(np.array([[1.0, gamma, 0.0, 1.0, 1.0]]))
    assert P[0, 1] / gamma == pytest.approx(mu0, rel=1e-6)


def test_a_ring_pressed_onto_a_polyline_and_the_surfaces_gaps():
    """ContactPair, Polyline and Circle in a short use: a ring held by contact alone on a flat
    mould, pressed by a pressure on its top face: the pair's force along z is the pressure on
    the deformed top face, p pi (b^2 - a^2), to 1e-9; a point at distance 1 outside a unit
    circle and one 0.5 above a polyline have those gaps."""
    mesh = axiform.rectangle((1.0, 2.0), (0.0, 1.0), (2, 2), "q4")
    model = axiform.Model(mesh, axiform.NeoHooke(0.5, 100.0))
    model.pressure(axiform.select_edges(mesh, {"z": 1.0}), 0.01)
    mould = axiform.Polyline(points=np.array([[0.0, 0.0], [3.0, 0.0]]))
    pair = axiform.ContactPair(mesh, mould, axiform.select_nodes(mesh, {"z": 0.0}), modulus=1.0)
    model.contact(pair)
    system = model.finalize()
    result = axiform.solve(system, axiform.LoadControl(1.0, 2))
    assert result.status == "finished", result.message
    top = axiform.select_nodes(mesh, {"z": 1.0})
    r = np.sort(mesh.points[top, 0] + result.last.u.reshape(-1, 2)[top, 0])
    force_z = pair.report(system.contact_states(result.last.state)[0])["force_z"]
    assert force_z == pytest.approx(0.01 * np.pi * (r[-1] ** 2 - r[0] ** 2), rel=1e-9)
    x = np.array([[2.0, 0.0], [1.0, 0.5]])
    assert axiform.Circle(center=(0.0, 0.0), radius=1.0).local(x[:1], x[:1], 1.0).g == pytest.approx(1.0)
    assert mould.local(x[1:], x[1:], 1.0).g == pytest.approx(0.5)


def test_solve_is_callable_and_a_package():
    mesh = axiform.rectangle((1.0, 2.0), (0.0, 1.0), (2, 2), "q4")
    model = axiform.Model(mesh, axiform.NeoHooke(0.5, 100.0))
    model.fix(axiform.select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.pressure(axiform.select_edges(mesh, {"r": 1.0}), 0.01)
    by_package = axiform.solve(model, axiform.LoadControl(1.0, 2))
    by_function = solve_function(model, axiform.LoadControl(1.0, 2))
    assert by_package.status == by_function.status == "finished"
    assert (by_package.last.u == by_function.last.u).all()
