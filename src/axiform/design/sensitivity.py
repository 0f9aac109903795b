"""Sensitivities of every converged state to design variables s, by direct differentiation
along the load path (load control).

At each converged step n the residual R_n(u_n; s, h_{n-1}) = 0 holds, h_{n-1} the history
committed at the step before (contact stick points, sticky nodes and where they froze,
positions for the crossing test; the law's state per quadrature point (materials.protocol:
a Prony series' h_i and the isochoric stress they were updated with, a network's Cv^-1, a
frozen network's H); the nodes' temperature where
heat conduction advances it after each step, System.settle), and h_n = H(u_n; s, h_{n-1}).
Differentiating,

    K_n du_n/ds = -( dR_n/ds |_u  +  dR_n/dh dh_{n-1}/ds )

with K_n = dR/du the (bordered) tangent at the converged state, evaluated with the history
h_{n-1} it converged with.  Cavities under volume or gas control are part of it: their
pressures are unknowns of u and their constraints rows of R.

The right-hand side is semi-analytic: central differences of the residual with respect to
each s_k at fixed u, two residual assemblies per variable and step (the well-known
semi-analytic method of shape sensitivity).  The model is rebuilt for s +- h e_k by a
user-supplied function (`build`), so every way the reference geometry enters the residual
counts: G and dV, pressure and cavity edges, V0 of a cavity under volume control, contact
ring areas, default penalties and reference positions.  The history is carried the same way:
each of these "shadow" models commits its history at the perturbed state u_n +- h du_n/ds_k,
so that its history is h_n(s +- h e_k) to first order and the difference of the shadows'
residuals at the next step holds dR/dh dh/ds.  The linear solves reuse one factorization of
K_n per step for all variables.

Cost per converged step: one tangent evaluation and one factorization of K_n, 2 m residual
evaluations for m variables (4 m with a history, has_history: the shadows' own, and a
conduction step each with heat conduction), one back-substitution with m right-hand sides.
Forward differences (`differences="forward"`: the shadow at s + h e_k against the base model
itself) halve the evaluations; their error is O(h) (they differ from the central ones by
6.4e-5 of the largest derivative of a sticky tube's wall), which a Gauss-Newton method does not
notice: `axiform optimize` uses them.

The steps are differentiated as they converge (`sensitivity`) or after the solve, from its
kept steps (`differentiate`), to the same numbers: a caller that learns only after a solve
whether it wants the derivatives (an optimizer that rejects the design) pays for them only
when it does.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..fem.constraints import DofMap
from ..model.model import Model
from ..model.system import System
from ..post.thickness import thickness_table
from ..solve.linsolve import LinearSolver, factorize
from ..solve.solver import LoadControl, NewtonOptions, SolveResult, Step, solve

RELATIVE_STEP = 1e-6  # the difference step of the semi-analytic residual, relative to |s_k|


class DesignError(ValueError):
    """The models built for perturbed designs cannot be compared with the base model (other
    supports, dofs or contact nodes: a selector that matches other nodes)."""


@dataclass
class Sensitivity:
    """A forward solve with the derivatives of its converged states.

    solve: the forward solve (status, steps, ...); model: the base model at its last state.
    design: the design s (m,); dx_ds: the derivative of the reference node positions
    (n_nodes, 2, m).  du_ds: per converged step, dU/ds of the full nodal dofs (n_full, m),
    node by node as model.dofmap numbers them (every step, or only the last with
    keep_steps=False); dp_ds: per step, the derivative of the unknown cavity pressures
    (cavities under volume or gas control, in model order) (c, m).  thickness: the
    thickness table of the last step (thickness.thickness_table, layered and rectangle
    meshes; None otherwise) and dthickness_ds its derivative (stations, m)."""

    solve: SolveResult
    model: System
    design: np.ndarray
    dx_ds: np.ndarray
    du_ds: list[np.ndarray] = field(default_factory=list)
    dp_ds: list[np.ndarray] = field(default_factory=list)
    thickness: dict[str, np.ndarray] | None = None
    dthickness_ds: np.ndarray | None = None

    @property
    def status(self) -> str:
        return self.solve.status

    def du_final_ds(self) -> np.ndarray:
        """Derivative of the node displacements u at the last step (n_nodes, 2, m)."""
        return self.du_ds[-1].reshape(self.model.mesh.n_nodes, self.model.dpn, -1)[:, :2]


def _same_numbering(base: System, other: System, k: int) -> None:
    if (
        other.mesh.n_nodes != base.mesh.n_nodes
        or other.n_free != base.n_free
        or not np.array_equal(_dofmap(other).eq, _dofmap(base).eq)
        or len(other.contacts) != len(base.contacts)
        or any(not np.array_equal(a.nodes, b.nodes) for a, b in zip(base.contacts, other.contacts, strict=False))
        or len(other.cavities) != len(base.cavities)
    ):
        raise DesignError(
            f"the model built for a perturbed design variable {k} has other dofs, supports or "
            "contact nodes than the base model: select nodes by named sets (start, end, inner, "
            "outer, ...) or by coordinates that do not move with the design"
        )


def _dofmap(model: System) -> DofMap:
    """The dof numbering of a finalized model."""
    if model.dofmap is None:
        raise ValueError("the model is not finalized: it has no dof numbering")
    return model.dofmap


def has_history(model: System) -> bool:
    """Whether the residual of a step depends on the history committed before it: contact
    pairs, a law with state (materials.protocol), or a temperature that heat conduction
    advances step by step (System.settle)."""
    return bool(model.contacts) or bool(model.solid_state(model.initial_state())) or model.conduction is not None


def sensitivity(
    build: Callable[[np.ndarray], Model | System],
    design: np.ndarray,
    control: LoadControl,
    options: NewtonOptions | None = None,
    keep_steps: bool = True,
    on_step: Callable[[Step, np.ndarray], None] | None = None,
    relative_step: float = RELATIVE_STEP,
    differences: str = "central",
) -> Sensitivity:
    """Solve the model build(design) under load control and differentiate every converged
    state with respect to the design variables (module docstring); `differences` "central"
    (O(h^2)) or "forward" (O(h), half the evaluations: module docstring).

    build: design s (m,) -> an unsolved Model, or its System (Model.finalize), with the same mesh topology,
    supports and loads for every s, only the reference geometry (or constants) changed.
    on_step(step, du_ds): called after each converged step with dU/ds (n_full, m).
    Returns a Sensitivity; its dthickness_ds is d(final thickness)/ds (stations, m)."""
    if not isinstance(control, LoadControl):
        raise ValueError("sensitivities follow the load path under load control (LoadControl)")
    s = np.asarray(design, float).ravel()
    derivatives = Derivatives(build, build(s).finalize(), s, relative_step, differences, keep_steps, on_step)
    derivatives.out.solve = solve(derivatives.model, control, options, on_step=derivatives.step)
    derivatives.finish()
    return derivatives.out


def differentiate(
    build: Callable[[np.ndarray], Model | System],
    design: np.ndarray,
    model: System,
    result: SolveResult,
    keep_steps: bool = True,
    relative_step: float = RELATIVE_STEP,
    differences: str = "central",
) -> Sensitivity:
    """The sensitivities of a solve already done: `result` is the solve of `model` =
    build(design) under load control with every converged step kept (solve's keep=None).
    The same derivatives as `sensitivity` (the steps differentiated in their order, after
    the solve instead of during it), for a caller that learns only after a solve whether it
    wants them (the optimizer's rejected trials and its last iterate do not)."""
    if len(result.steps) != result.n_steps:
        raise ValueError(f"the solve kept {len(result.steps)} of its {result.n_steps} steps: all are needed")
    s = np.asarray(design, float).ravel()
    derivatives = Derivatives(build, model, s, relative_step, differences, keep_steps)
    derivatives.out.solve = result
    for step in result.steps:
        derivatives.step(step)
    derivatives.finish()
    return derivatives.out


class Derivatives:
    """The derivatives of the converged steps of one solve of `model` = build(s), one step
    at a time and in order (`step`, the solve's on_step, or called afterwards over its kept
    steps), into `out` (a Sensitivity; `finish` adds the final wall's derivative).  The
    shadows (the models at s + h e_k, and s - h e_k for central differences) carry their own
    history along the steps (module docstring)."""

    def __init__(
        self,
        build: Callable[[np.ndarray], Model | System],
        model: System,
        s: np.ndarray,
        relative_step: float = RELATIVE_STEP,
        differences: str = "central",
        keep_steps: bool = True,
        on_step: Callable[[Step, np.ndarray], None] | None = None,
    ):
        if differences not in ("central", "forward"):
            raise ValueError(f'differences must be "central" or "forward", not {differences!r}')

        def built(x):
            return build(x).finalize()  # a Model finalized, a System as it is

        self.model, self.keep_steps, self.on_step = model, keep_steps, on_step
        self.central = central = differences == "central"
        self.h = h = relative_step * np.where(s != 0, np.abs(s), 1.0)
        self.shadows = shadows = _shadow_models(built, model, s, h, central)
        self.span = 2.0 * h if central else h  # the design step between the two residuals differenced
        dx_ds = np.stack(
            [
                (p[0].mesh.points - (p[1] if central else model).mesh.points) / d
                for p, d in zip(shadows, self.span, strict=True)
            ],
            axis=-1,
        )
        self.history = has_history(model)
        self.out = Sensitivity(SolveResult("running"), model, s, dx_ds)
        self.linear = LinearSolver()  # the analysis of the tangent's pattern, kept from step to step
        self.lag_state = model.initial_state()  # the history h_{n-1}: the tangent K_n is taken with it
        self.shadow_states = [[shadow.initial_state() for shadow in pair] for pair in shadows]

    def step(self, step: Step) -> None:
        """Differentiate the converged step `step` (the one after the last differentiated)."""
        model, out, central, span = self.model, self.out, self.central, self.span
        m = span.size
        u_f, lam = step.u_f, step.lam
        if step.state is None:
            raise ValueError(f"step {step.number} holds no committed history: it cannot be differentiated")
        ev = model.evaluate(u_f, lam, model.begin_step(self.lag_state, step.fraction))
        self.lag_state = step.state  # committed by the solver: h_n, the history of the next step's K
        dR = np.empty((model.n_free, m))
        _begin_shadow_steps(self.shadows, self.shadow_states, step.fraction)
        for k, (pair, states) in enumerate(zip(self.shadows, self.shadow_states, strict=True)):
            r = [shadow.evaluate(u_f, lam, held, tangent=False).r for shadow, held in zip(pair, states, strict=True)]
            dR[:, k] = (r[0] - (r[1] if central else ev.r)) / span[k]
        du_f = -np.asarray(factorize(ev.K, self.linear)(dR)).reshape(model.n_free, m)
        if self.history:
            self._settle_shadows(u_f, lam, du_f)
        dm = _dofmap(model)
        du = np.concatenate([du_f[: dm.nf], np.zeros((dm.np, m))])[dm.eq]  # (n_full, m)
        if not self.keep_steps:
            out.du_ds.clear()
            out.dp_ds.clear()
        out.du_ds.append(du)
        out.dp_ds.append(du_f[dm.nf :])
        if self.on_step is not None:
            self.on_step(step, du)

    def _settle_shadows(self, u_f: np.ndarray, lam: float, du_f: np.ndarray) -> None:
        """Each shadow commits its history at the perturbed state u_f +- h_k du_f[:, k] (n_free, m)."""
        for k, (pair, states) in enumerate(zip(self.shadows, self.shadow_states, strict=False)):
            for j, (shadow, sign) in enumerate(zip(pair, (1.0, -1.0), strict=False)):
                moved = u_f + sign * self.h[k] * du_f[:, k]
                trial = shadow.evaluate(moved, lam, states[j], tangent=False).trial
                assert trial is not None, "System.evaluate returns the trial state"
                states[j] = shadow.settle(states[j], trial, shadow.expand(moved, lam))

    def finish(self) -> None:
        """The final wall and its derivative (out.thickness, out.dthickness_ds) from the last step."""
        out, model = self.out, self.model
        last = out.solve.last
        if last is not None:
            u2 = last.u.reshape(-1, model.dpn)[:, :2]
            held = () if last.state is None else model.contact_states(last.state)
            out.thickness = thickness_table(model.mesh, u2, held)
            if out.thickness is not None:
                out.dthickness_ds = thickness_derivative(model, u2, out.dx_ds, out.du_final_ds())


def _shadow_models(
    built: Callable[[np.ndarray], System], model: System, s: np.ndarray, h: np.ndarray, central: bool
) -> list[tuple[System, ...]]:
    """Per design variable k: the models at s + h_k e_k and, for central differences, at
    s - h_k e_k, each checked to number its dofs as the base model does."""
    shadows: list[tuple[System, ...]] = []
    for k in range(s.size):
        e = np.zeros(s.size)
        e[k] = h[k]
        pair = (built(s + e), built(s - e)) if central else (built(s + e),)
        for shadow in pair:
            _same_numbering(model, shadow, k)
        shadows.append(pair)
    return shadows


def _begin_shadow_steps(shadows: list, shadow_states: list, fraction: float) -> None:
    """Each shadow's committed state as the step of `fraction` of the nominal one starts from
    it (System.begin_step), in place: the shadows start their steps as the solver did."""
    for pair, states in zip(shadows, shadow_states, strict=True):
        states[:] = [shadow.begin_step(held, fraction) for shadow, held in zip(pair, states, strict=True)]


def thickness_derivative(model: System, u: np.ndarray, dX: np.ndarray, du: np.ndarray) -> np.ndarray:
    """d thickness / ds (stations, m) of the wall at the nodal displacements u (n_nodes, 2),
    the reference node positions moving by dX (n_nodes, 2, m) and the displacements by du
    (n_nodes, 2, m) per unit of each design variable: central differences of the measured
    thickness of the perturbed reference mesh and displacements (the thickness is a smooth
    function of both; a held station, whose du is exactly zero or one translation, stays held
    and gives the derivative of its reference thickness), moving no node by more than 1e-6 of
    the smallest element edge."""
    mesh = model.mesh
    m = dX.shape[-1]
    out = np.empty((len(_wall(mesh, mesh.points, u)), m))
    for k in range(m):
        v, w = dX[..., k], du[..., k]
        eps = 1e-6 * mesh.size() / max(float(np.abs(v + w).max()), 1e-300)
        plus = _wall(mesh, mesh.points + eps * v, u + eps * w)
        minus = _wall(mesh, mesh.points - eps * v, u - eps * w)
        out[:, k] = (plus - minus) / (2 * eps)
    return out


def _wall(mesh, X: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The wall's thickness per station of the mesh with reference node positions X (n_nodes, 2)
    at the nodal displacements u (n_nodes, 2)."""
    moved = copy.copy(mesh)
    moved.points = X
    table = thickness_table(moved, u)
    if table is None:
        raise ValueError("the mesh has no through-wall fibres: no thickness to differentiate")
    return table["thickness"]
