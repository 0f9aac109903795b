import numpy as np
import pytest

from axiform import rectangle

# a bar of a Prony-series law (axisymmetric: r from the axis to 1), stretched by 0.3 in
# 1 ms and held to t = 1 s: the relaxation tests' case file (test_viscoelastic,
# test_process_time)
RELAXING_BAR = """
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "q4"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e4
viscoelastic = { g = [0.4, 0.3], tau = [0.05, 0.5] }
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { z = 1.0 }
dofs = ["uz"]
value = 0.3
curve = [[0.0, 0.0], [0.001, 1.0], [1.0, 1.0]]
[solver]
target = 1.0
steps = 10
"""


def distorted_rectangle(r, z, divisions, element, amount=0.25, seed=0):
    """A rectangle mesh whose interior corner nodes are moved at random by up to `amount`
    of the cell size (Q8 mid-side nodes are put back at the middle of their straight edges)."""
    mesh = rectangle(r, z, divisions, element)
    rng = np.random.default_rng(seed)
    h = np.array([(r[1] - r[0]) / divisions[0], (z[1] - z[0]) / divisions[1]])
    boundary = np.unique(mesh.boundary_edges)
    corners = np.setdiff1d(mesh.corner_nodes, boundary)
    mesh.points[corners] += amount * h * rng.uniform(-1, 1, size=(len(corners), 2))
    if element == "q8":
        ends = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
        for k, (a, b) in zip(range(4, 8), ends, strict=False):
            mids = mesh.cells[:, k]
            mesh.points[mids] = 0.5 * (mesh.points[mesh.cells[:, a]] + mesh.points[mesh.cells[:, b]])
    mesh.check()
    return mesh


@pytest.fixture(params=["q4", "q8", "sfr"])
def element(request):
    return request.param


def difference_tangent(model, u_f, lam, h, state=None):
    """Central differences of the residual of a finalized model from the committed history
    `state` (None: the initial one): dR/du (n, n) and dR/dlambda."""
    n = model.n_free
    num = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        num[:, j] = (
            model.evaluate(u_f + e, lam, state, tangent=False).r - model.evaluate(u_f - e, lam, state, tangent=False).r
        ) / (2 * h)
    dl = (
        model.evaluate(u_f, lam + h, state, tangent=False).r - model.evaluate(u_f, lam - h, state, tangent=False).r
    ) / (2 * h)
    return num, dl


@pytest.fixture(params=["mixed", "displacement"])
def formulation(request):
    return request.param


def clamped_plate(element, formulation="mixed", divisions=(20, 2), grading=1.0):
    """The paper's plate (section 4.1): R = 7.5, h = 0.5, C1 = 80, C2 = 20, kappa = 1e4, rim
    clamped, unit follower pressure on z = 0; a finalized model.  grading: the size of the
    element at the clamp over that at the centre (radially)."""
    from axiform import Model, MooneyRivlin, select_edges, select_nodes

    mesh = rectangle((0.0, 7.5), (0.0, 0.5), divisions, element, grading=(grading, 1.0))
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4), formulation=formulation)
    model.fix(select_nodes(mesh, {"r": 7.5}), ["ur", "uz", "rot"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 1.0)
    return model.finalize()
