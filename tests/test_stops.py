"""A stop names the cause a user can act on before the element that failed."""

from axiform.case.schema import build, parse
from axiform.solve.controls import LoadControl, NewtonOptions
from axiform.solve.paths import LoadPath
from axiform.solve.solver import solve


def ring_on_a_short_plate(plate_end: float) -> dict:
    """The square ring r 18..22, z 0..4 on a frictionless plate that ends at r = plate_end,
    pressed 0.2 by a plate from above."""
    return {
        "mesh": {"kind": "rectangle", "r": [18.0, 22.0], "z": [0.0, 4.0], "divisions": [4, 4], "element": "q4"},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 1000.0},
        "contact": [
            {"name": "plate", "surface": {"polyline": [[10.0, 0.0], [plate_end, 0.0]]}, "slaves": {"z": 0.0}},
            {
                "name": "press",
                "surface": {"polyline": [[30.0, 4.0], [10.0, 4.0]]},
                "slaves": {"z": 4.0},
                "motion": {"uz": -0.2},
            },
        ],
        "solver": {"control": "load", "steps": 2},
    }


def diagnosis_after_the_run(plate_end: float) -> str:
    built = build(parse(ring_on_a_short_plate(plate_end)))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    path = LoadPath(built.model, LoadControl(1.0, 2), NewtonOptions())
    path.u_f, path.lam, path.history = res.last.u_f, res.last.lam, res.last.state
    return path.diagnosis()


def test_a_body_at_the_open_end_of_its_mould_is_said_to_slide_off_it():
    """The outer corner of the ring rests on the plate's very end: the diagnosis of a stop there
    names the mould and the place; on a plate that reaches past the ring it says nothing."""
    said = diagnosis_after_the_run(22.0)
    assert said.startswith("the body reached the end of the mould plate at (r, z) = (22")
    assert "extend the mould" in said
    assert diagnosis_after_the_run(30.0) == ""


def test_an_end_of_a_mould_on_the_axis_is_no_end_to_slide_off():
    """A disc (r 0..4) pressed onto a plate whose outline ends on the axis: the centre node
    rests on that end, which the outline would continue mirrored; nothing to say."""
    case = ring_on_a_short_plate(30.0)
    case["mesh"]["r"] = [0.0, 4.0]
    case["contact"][0]["surface"]["polyline"] = [[0.0, 0.0], [10.0, 0.0]]
    case["contact"][1]["surface"]["polyline"] = [[10.0, 4.0], [0.0, 4.0]]
    case["fix"] = [{"at": {"r": 0.0}, "dofs": ["ur"]}]
    built = build(parse(case))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    assert (built.model.contacts[0].report(built.model.contact_states(res.last.state)[0])["status"] > 0).all()
    path = LoadPath(built.model, LoadControl(1.0, 2), NewtonOptions())
    path.u_f, path.lam, path.history = res.last.u_f, res.last.lam, res.last.state
    assert path.diagnosis() == ""


def test_the_cause_comes_before_the_failure(monkeypatch):
    from axiform.solve import solver

    monkeypatch.setattr(LoadPath, "diagnosis", lambda self: "the cause")
    built = build(parse(ring_on_a_short_plate(30.0) | {"solver": {"control": "load", "steps": 1, "max_iterations": 1}}))
    res = solver.solve(built.model, built.control, built.options)
    assert res.status == "stopped"
    assert res.message.startswith("step 1: the cause; no convergence")
