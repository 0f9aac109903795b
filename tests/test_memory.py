"""Memory flat in the number of steps: a converged Step keeps u, u_f and the residual, never
the Evaluation and its tangent; with keep=1 (as `axiform run` solves) a 1,000-step run holds
what it held after 50 steps."""

import tracemalloc

import numpy as np
import pytest

from axiform import LoadControl, Model, MooneyRivlin, NewtonOptions, rectangle, solve
from axiform.fem.mesh import edges_on_nodes
from axiform.solve.solver import Step


def _ring(steps_target: float = 2.0):
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (3, 3), "q4")
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4), formulation="displacement")
    model.fix(mesh.node_sets["bottom"], ["uz"])
    model.pressure(edges_on_nodes(mesh, mesh.node_sets["left"]), steps_target)
    return model


def _array_bytes(snapshot: tracemalloc.Snapshot) -> int:
    """Bytes of NumPy array data alive in a snapshot (NumPy traces them in its own domain;
    Python's small objects, whose free lists fill and empty with the history of the process,
    are left out)."""
    arrays = snapshot.filter_traces([tracemalloc.DomainFilter(True, np.lib.tracemalloc_domain)])
    return sum(stat.size for stat in arrays.statistics("filename"))


def test_thousand_steps_memory_flat():
    tracemalloc.start()
    try:
        model = _ring()
        held = {}

        def on_step(step):
            if step.number in (50, 1000):
                held[step.number] = _array_bytes(tracemalloc.take_snapshot())

        result = solve(model, LoadControl(1.0, 1000), NewtonOptions(growth=1.0), on_step=on_step, keep=1)
    finally:
        tracemalloc.stop()
    assert result.status == "finished" and result.n_steps == 1000 and len(result.steps) == 1
    assert result.steps[0].number == 1000
    growth = (held[1000] - held[50]) / held[50]
    assert growth < 0.05, f"array memory grew by {100 * growth:.1f} % from step 50 to step 1000"


def test_steps_hold_results_not_the_tangent():
    model = _ring().finalize()
    result = solve(model, LoadControl(1.0, 4))
    assert result.n_steps == len(result.steps) == 4
    held = {f.name for f in Step.__dataclass_fields__.values()}
    # state: the committed history (per slave node and cavity), not the tangent
    assert held == {"number", "lam", "iterations", "residuals", "u_f", "u", "r_full", "checkpoint", "state", "fraction"}

    def arrays(value):  # the checkpoint (restart state) holds vectors and scalars, no matrix
        if isinstance(value, dict):
            return [a for v in value.values() for a in arrays(v)]
        if isinstance(value, (list, tuple)):
            return [a for v in value for a in arrays(v)]
        assert value is None or isinstance(value, (int, float, bool, np.ndarray)), type(value)
        return [value] if isinstance(value, np.ndarray) else []

    assert all(a.ndim <= 2 and a.size <= 2 * model.n_full for a in arrays(result.steps[-1].checkpoint))
    last = result.steps[-1]
    # what the step holds is the converged state: its residual vanishes off the supports, and
    # along z the supports' reactions (r_full at the bottom's uz) balance the pressure on the
    # bore, -p pi (a_top^2 - a_bottom^2) over the bore's straight edges (a its current radii:
    # the bore tilts as it opens), to 1e-7 of the largest reaction (3e-10 measured)
    assert last.lam == 1.0
    mesh = model.mesh
    x = mesh.points + last.u.reshape(-1, 2)
    bore = mesh.node_sets["left"][np.argsort(mesh.points[mesh.node_sets["left"], 1])]
    supports = model.dof(mesh.node_sets["bottom"], "uz")
    off = np.ones(model.n_full, bool)
    off[supports] = False
    reactions = last.r_full[supports]
    assert np.abs(last.r_full[off]).max() < 1e-8 * np.abs(reactions).max()
    a_bottom, a_top = x[bore[0], 0], x[bore[-1], 0]
    assert a_bottom - a_top > 1e-3
    pressure = 2.0 * last.lam
    assert reactions.sum() == pytest.approx(
        pressure * np.pi * (a_top**2 - a_bottom**2), abs=1e-7 * np.abs(reactions).max()
    )
