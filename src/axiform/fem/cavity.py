"""Gas cavities: the volume enclosed by a chain of boundary edges, the axis and planes
z = const, and the pressure of the gas in it.

V = pi |oint r^2 dz| (the whole body of revolution): along the axis r = 0 and along the
closing planes dz = 0, so only the boundary edges contribute, integrated with the element's
own edge interpolation (exact: r^2 dz is of degree 5 at most on a quadratic edge, 3-point
Gauss).  The gas pressure p does the work p dV on the wall, so the wall load is p g with
g = dV/du and its stiffness -p d2V/du2 (symmetric: the gas has a potential).

Controls (t the process time, f(t) the cavity's curve, f(t) = t without one):
- "pressure": p(t) = pressure f(t), a given gauge pressure;
- "volume":   V(u) = V0 + f(t) (volume - V0), p an unknown of the system;
- "gas":      (p + ambient) V(u) = ambient V0 + f(t) (content - ambient V0), an isothermal
              ideal gas of the given content (absolute pressure x volume), p unknown.
Under volume and gas control each cavity adds one equation and one unknown (its pressure)
to the system, bordering the tangent: [[K - p H, -g], [dC/du, dC/dp]].
"""

from __future__ import annotations

import numpy as np

from .assembly import element_dofs
from .curves import PROPORTIONAL, Curve
from .elements import edge_interpolation
from .mesh import Mesh

CONTROLS = ("pressure", "volume", "gas")


class CavityError(ValueError):
    """A cavity boundary that does not close with the axis and planes z = const."""


def _chain_ends(edges: np.ndarray) -> np.ndarray:
    """The two end nodes of a chain of edges (corner nodes (m, 2)), or none if it is closed;
    CavityError if the edges do not form one chain."""
    nodes, count = np.unique(edges, return_counts=True)
    if (count > 2).any():
        raise CavityError(f"the boundary branches at node {int(nodes[count > 2][0])}")
    ends = nodes[count == 1]
    if len(ends) not in (0, 2):
        raise CavityError(f"the boundary is not one chain of edges ({len(ends) // 2} pieces)")
    # connectivity: walk the chain
    adj: dict[int, list[int]] = {}
    for a, b in edges:
        adj.setdefault(int(a), []).append(int(b))
        adj.setdefault(int(b), []).append(int(a))
    start = int(ends[0]) if len(ends) else int(edges[0, 0])
    seen, prev, node = {start}, None, start
    while True:
        nxt = [n for n in adj[node] if n != prev and n not in seen]
        if not nxt:
            break
        prev, node = node, nxt[0]
        seen.add(node)
    if len(seen) != len(nodes):
        raise CavityError("the boundary is not one chain of edges (it has separate pieces)")
    return ends


class Cavity:
    """A gas cavity bounded by boundary edges (indices of mesh.boundary_edges).

    held_z: full-dof flags (n_nodes,) of nodes whose uz is held: an open end of the chain
    off the axis must be one of them (it then closes the cavity along its plane z = const).
    """

    def __init__(
        self,
        mesh: Mesh,
        edges: np.ndarray,
        name: str,
        control: str = "pressure",
        value: float = 0.0,
        ambient: float = 0.0,
        curve: Curve = PROPORTIONAL,
        held_z: np.ndarray | None = None,
    ):
        if control not in CONTROLS:
            raise ValueError(f"control must be one of {CONTROLS}, not {control!r}")
        if control == "gas" and not ambient > 0:
            raise ValueError("a gas cavity needs an absolute ambient pressure > 0")
        self.name, self.control, self.value, self.ambient, self.curve = (
            name,
            control,
            float(value),
            float(ambient),
            curve,
        )
        self.nodes = mesh.boundary_edges[np.asarray(edges)]
        if len(self.nodes) == 0:
            raise CavityError("the boundary holds no edge")
        ends = _chain_ends(self.nodes[:, :2])
        tol = 1e-6 * mesh.size()
        for n in ends:
            on_axis = abs(mesh.points[n, 0]) <= tol
            if not on_axis and (held_z is None or not held_z[n]):
                r, z = mesh.points[n]
                raise CavityError(
                    f"the open end at (r, z) = ({r:.6g}, {z:.6g}) lies neither on the axis "
                    "nor on a plane z = const (its uz is not held)"
                )
        self.dofs = element_dofs(self.nodes, mesh.element.dofs_per_node)
        self.Xs, self.dXs, self.H, self.dH, self.w = edge_interpolation(mesh.element, mesh.points[self.nodes])
        # the boundary edges run counter-clockwise around the body, so clockwise around the
        # gas on their right: V = -pi sum int r^2 dz (Green: oint_ccw r^2 dz = int 2 r dA)
        self.sign = -1.0
        self.V0 = self._volume(np.zeros(mesh.n_nodes * mesh.element.dofs_per_node))
        if control != "pressure" and not self.V0 > 0:
            raise CavityError(
                f"the boundary encloses no volume on its gas side (V0 = {self.V0:.6g}): "
                "volume and gas control need V0 > 0"
            )

    @property
    def unknown(self) -> bool:
        """True when the pressure is an unknown of the system (volume or gas control)."""
        return self.control != "pressure"

    def _volume(self, u_full):
        ue = u_full[self.dofs]
        x = self.Xs + np.einsum("mpin,mn->mpi", self.H, ue)
        dx = self.dXs + np.einsum("mpin,mn->mpi", self.dH, ue)
        return self.sign * np.pi * np.einsum("p,mp,mp->", self.w, x[..., 0] ** 2, dx[..., 1])

    def evaluate(self, u_full: np.ndarray, tangent: bool = True):
        """V, g_e = dV/du per edge (m, nd), and, if asked, H_e = d2V/du2 (m, nd, nd)."""
        ue = u_full[self.dofs]
        x = self.Xs + np.einsum("mpin,mn->mpi", self.H, ue)
        dx = self.dXs + np.einsum("mpin,mn->mpi", self.dH, ue)
        r, dz = x[..., 0], dx[..., 1]
        c = self.sign * np.pi * self.w  # (p,)
        V = float(np.einsum("p,mp,mp->", c, r * r, dz))
        Hr, dHz = self.H[:, :, 0], self.dH[:, :, 1]  # (m, p, nd)
        g = np.einsum("p,mpn->mn", c, 2.0 * (r * dz)[..., None] * Hr + (r * r)[..., None] * dHz)
        if not tangent:
            return V, g, None
        He = (
            np.einsum("p,mp,mpi,mpj->mij", 2.0 * c, dz, Hr, Hr)
            + np.einsum("p,mp,mpi,mpj->mij", 2.0 * c, r, Hr, dHz)
            + np.einsum("p,mp,mpi,mpj->mij", 2.0 * c, r, dHz, Hr)
        )
        return V, g, He

    def target(self, t: float) -> tuple[float, float]:
        """The controlled quantity at time t and its rate: the gauge pressure (pressure
        control), the volume (volume control) or the gas content p_abs V (gas control)."""
        f, df = self.curve(t), self.curve.slope(t)
        if self.control == "pressure":
            return self.value * f, self.value * df
        start = self.V0 if self.control == "volume" else self.ambient * self.V0
        return start + f * (self.value - start), df * (self.value - start)
