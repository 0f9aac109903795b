"""The public names of `axiform` resolve, and axiform.solve runs a model (it is the package
solve/ and the solver function at once)."""

import axiform


def test_every_public_name_resolves():
    for name in axiform.__all__:
        assert getattr(axiform, name) is not None, name


def test_solve_is_callable_and_a_package():
    from axiform.solve.solver import solve as solve_function

    mesh = axiform.rectangle((1.0, 2.0), (0.0, 1.0), (2, 2), "q4")
    model = axiform.Model(mesh, axiform.NeoHooke(0.5, 100.0))
    model.fix(axiform.select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.pressure(axiform.select_edges(mesh, {"r": 1.0}), 0.01)
    by_package = axiform.solve(model, axiform.LoadControl(1.0, 2))
    by_function = solve_function(model, axiform.LoadControl(1.0, 2))
    assert by_package.status == by_function.status == "finished"
    assert (by_package.last.u == by_function.last.u).all()
