"""model.system.System.evaluate: a deferred tangent is the one an eager evaluation makes, and
an evaluation without a tangent has the residual of one with it."""

import numpy as np
import pytest

from axiform import Model, MooneyRivlin, NeoHooke, rectangle, select_nodes
from axiform.fem.mesh import edges_on_nodes
from axiform.materials.viscoelastic import Prony, Viscoelastic


def plate(element: str = "q8", formulation: str = "displacement", material=None, moving: bool = False):
    """A clamped plate under a follower pressure on its lower face (or, moving, with its top
    pulled by a prescribed displacement), finalized, and a state u_f near its first step."""
    mesh = rectangle((0.0, 2.0), (0.0, 0.2), (8, 2), element)
    model = Model(mesh, material or MooneyRivlin(80.0, 20.0, 1e4), formulation=formulation)
    model.fix(select_nodes(mesh, {"r": 2.0}), ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(edges_on_nodes(mesh, select_nodes(mesh, {"z": 0.0})), 5.0)
    if moving:
        model.prescribe(select_nodes(mesh, {"r": 0.0, "z": 0.2}), ["uz"], 0.1)
    system = model.finalize()
    u_f = 1e-3 * np.random.default_rng(0).standard_normal(system.n_free)
    return system, u_f


@pytest.mark.parametrize(
    "element, formulation, material",
    [
        ("q8", "displacement", None),
        ("q4", "mixed", None),
        ("q8", "mixed", None),
        ("sfr", "displacement", None),
        ("q8", "mixed", Viscoelastic(NeoHooke(0.5, 1e3), Prony((0.4, 0.3), (0.05, 0.5)))),
    ],
)
def test_deferred_tangent_is_the_eager_one(element, formulation, material):
    """deferred=True: the residual is the eager evaluation's, number for number, and K, made
    when first read (after the caller moved its u_f), the eager K."""
    system, u_f = plate(element, formulation, material)
    state = system.initial_state()
    eager = system.evaluate(u_f, 0.5, state)
    late = system.evaluate(u_f, 0.5, state, deferred=True)
    assert late.deferred and not eager.deferred
    for name in ("r", "dr_dlam", "r_full", "f_ext_full"):
        assert np.array_equal(getattr(late, name), getattr(eager, name)), name
    assert late.force_scale == eager.force_scale
    u_f += 1.0  # moved by its caller: the deferred tangent is still that of the evaluated state
    K = late.K
    assert not late.deferred
    assert np.array_equal(K.indptr, eager.K.indptr) and np.array_equal(K.indices, eager.K.indices)
    assert np.array_equal(K.data, eager.K.data)
    assert late.K is K  # made once
    assert late.noise == eager.noise


def test_tangent_not_deferred_where_a_prescribed_dof_moves():
    """A prescribed motion puts K_fp in dR/dt: the tangent is made at once."""
    system, u_f = plate(moving=True)
    ev = system.evaluate(u_f, 0.5, deferred=True)
    assert not ev.deferred and ev.K is not None
    assert np.array_equal(ev.dr_dlam, system.evaluate(u_f, 0.5).dr_dlam)


def test_newton_defers_the_tangent_of_its_last_check(monkeypatch):
    """Newton under displacement control evaluates an iteration expected to converge without
    its tangent: tangents never made, and the same steps, iterations and numbers as with every
    tangent made."""
    from axiform import DisplacementControl, solve
    from axiform.model.system import System
    from axiform.solve import newton

    system, _ = plate()
    centre = system.dof(select_nodes(system.mesh, {"r": 0.0, "z": 0.2}), "uz")[0]
    path = DisplacementControl(int(centre), 0.3, 4)
    made = []
    original = System.evaluate

    def counted(self, *args, **kw):
        ev = original(self, *args, **kw)
        made.append(ev)
        return ev

    monkeypatch.setattr(System, "evaluate", counted)
    lazy = solve(system, path)
    skipped = sum(ev.deferred for ev in made)  # tangents deferred and never read
    monkeypatch.setattr(newton, "hopeful", lambda *args: False)
    made.clear()
    eager = solve(system, path)
    assert skipped > 0 and not any(ev.deferred for ev in made)
    assert lazy.n_steps == eager.n_steps == 4
    for a, b in zip(lazy.steps, eager.steps, strict=True):
        assert a.iterations == b.iterations and a.residuals == b.residuals and a.lam == b.lam
        assert np.array_equal(a.u_f, b.u_f) and np.array_equal(a.r_full, b.r_full)


def test_a_small_term_accumulates_as_a_whole_array_would():
    """SparsePattern.accumulate sums a term of few entries (the pressure) over its own
    positions: the data array is the one a bincount over the whole pattern gives, number for
    number, over the distinct positions found when the positions were (SparsePattern.positions)."""
    system, u_f = plate()
    pattern = system.pattern
    (solid,), (pressure,) = system.positions
    assert 4 * pressure.size < len(pattern.keys) <= 4 * solid.size
    rng = np.random.default_rng(2)
    a, b = rng.standard_normal(solid.size), rng.standard_normal(pressure.size)
    data = pattern.accumulate(solid, a)
    expected = data + np.bincount(pressure, weights=b, minlength=len(pattern.keys))
    assert np.array_equal(pattern.accumulate(pressure, b, data), expected)
    held, distinct, _ = pattern._few[id(pressure)]
    assert held is pressure and np.array_equal(distinct, np.unique(pressure))
    assert id(solid) not in pattern._few  # the solid's are summed over the whole pattern
