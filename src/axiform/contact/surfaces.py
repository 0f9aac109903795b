"""Rigid master surfaces in the (r, z) plane and the local search on them (eqs. 36-39).

A surface may move rigidly: its position is the reference one translated by lambda * motion.
Everything here works in the surface's own frame, x_rel = x - lambda * motion.

The local search of a node gives the contact point, the unit normal n (pointing to the
body's side), the tangent t (n = t turned by +90 degrees), the normal gap g = (x - x_p) . n
(g < 0: penetration, eq. 39), a surface coordinate s (arc length, for the tangential slip),
and the surface's curvature terms: dn/dx = kappa t t^T, dt/dx = -kappa n t^T, ds/dx = m t^T.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import search


@dataclass
class Projection:
    """Local search result for every slave node (rows); `active` marks nodes with a contact
    point (they may still have g >= 0: the law decides)."""

    active: np.ndarray
    g: np.ndarray
    n: np.ndarray
    t: np.ndarray
    s: np.ndarray
    kappa: np.ndarray
    m: np.ndarray
    point: np.ndarray
    s_prev: np.ndarray  # surface coordinate of the last converged position on the same piece
    kind: np.ndarray  # 0 none, 1 segment or circle, 2 cavity corner (vertex), 3 crossing

    @classmethod
    def empty(cls, n: int) -> "Projection":
        z = np.zeros(n)
        return cls(np.zeros(n, bool), z.copy(), np.zeros((n, 2)), np.zeros((n, 2)), z.copy(), z.copy(),
                   np.ones(n), np.zeros((n, 2)), z.copy(), np.zeros(n, np.int8))


@dataclass
class RigidSurface:
    motion: tuple[float, float] = (0.0, 0.0)

    def offset(self, lam: float) -> np.ndarray:
        return lam * np.asarray(self.motion, float)


@dataclass
class Circle(RigidSurface):
    """A circle of the (r, z) plane (a torus or a sphere in 3D); the body is outside it
    (a punch, the toric cylinder of section 4.2) or inside it (a cavity)."""

    center: tuple[float, float] = (0.0, 0.0)
    radius: float = 1.0
    inside: bool = False

    def polyline(self, n: int = 180) -> np.ndarray:
        a = np.linspace(0, 2 * np.pi, n + 1)
        return np.asarray(self.center) + self.radius * np.column_stack([np.cos(a), np.sin(a)])

    def local(self, x: np.ndarray, x_prev: np.ndarray, depth: float, method: str = "buckets") -> Projection:
        """Closed form: the nearest point of the circle.  Nodes deeper than `depth` are
        ignored unless they crossed the circle since the last converged step."""
        c = np.asarray(self.center, float)
        d = x - c
        rho = np.linalg.norm(d, axis=1)
        rho = np.where(rho == 0, 1e-300, rho)
        e = d / rho[:, None]
        sgn = -1.0 if self.inside else 1.0
        n = sgn * e
        g = sgn * (rho - self.radius)
        t = np.column_stack([n[:, 1], -n[:, 0]])  # n is t turned by +90 degrees
        phi = np.arctan2(e[:, 1], e[:, 0])
        s = -sgn * self.radius * phi
        dp = x_prev - c
        g_prev = sgn * (np.linalg.norm(dp, axis=1) - self.radius)
        phi_prev = np.arctan2(dp[:, 1], dp[:, 0])
        phi_prev = phi + (phi_prev - phi + np.pi) % (2 * np.pi) - np.pi  # no jump across +-pi
        crossed = (g_prev >= 0) & (g < 0)
        active = (g > -depth) | crossed
        p = Projection.empty(len(x))
        p.active = active
        p.g, p.n, p.t, p.s = g, n, t, s
        p.kappa = sgn / rho
        p.m = self.radius / rho
        p.point = c + self.radius * e
        p.s_prev = -sgn * self.radius * phi_prev
        p.kind = np.where(active, np.where(crossed, 3, 1), 0).astype(np.int8)
        return p


@dataclass
class Polyline(RigidSurface):
    """Straight segments through `points` (k, 2); the body lies on the side of the normal
    n = (-s, c) of each segment (eqs. 36-37): to the left when walking along the points."""

    points: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))

    def __post_init__(self):
        self.points = np.asarray(self.points, float)
        if self.points.ndim != 2 or self.points.shape[1] != 2 or len(self.points) < 2:
            raise ValueError("a polyline needs at least two points [r, z]")
        a, b = self.points[:-1], self.points[1:]
        L = np.linalg.norm(b - a, axis=1)
        if (L <= 0).any():
            raise ValueError(f"polyline segment {int(np.argmin(L))} has zero length")
        self.a, self.b, self.L = a, b, L
        self.tan = (b - a) / L[:, None]  # (c, s), eq. 36
        self.nor = np.column_stack([-self.tan[:, 1], self.tan[:, 0]])  # (-s, c), eq. 37
        self.s0 = np.concatenate([[0.0], np.cumsum(L)[:-1]])  # arc length at each segment start

    def polyline(self) -> np.ndarray:
        return self.points

    def local(self, x: np.ndarray, x_prev: np.ndarray, depth: float, method: str = "buckets") -> Projection:
        """Candidates from the global search (segments widened by the depth and by how far
        the nodes moved since the last converged step), then for each node:
        1. a segment its path crossed since the last converged step (front to back: paper
           Figure 6), the first one crossed along the path;
        2. else the segments it projects onto (0 <= xi <= 1, eq. 38) with a gap above -depth:
           the one with the largest gap.  A node that entered a corner where the mould turns
           away from the body faces two segments (Figure 8): it leaves by the nearer face;
        3. else a corner where the mould turns towards the body (a cavity corner), the node
           behind both segments and outside both projection ranges, facing none (Figure 8):
           the vertex is its contact point, with the mean of the two normals."""
        nn = len(x)
        moved = float(np.linalg.norm(x - x_prev, axis=1).max()) if nn else 0.0
        widen = depth + moved
        finder = {"buckets": search.buckets, "binary": search.binary_sort, "brute": search.brute_force}[method]
        pairs = finder(x, self.a, self.b, widen)
        out = Projection.empty(nn)
        if len(pairs) == 0:
            return out
        i, k = pairs[:, 0], pairs[:, 1]
        a, t, nrm, L = self.a[k], self.tan[k], self.nor[k], self.L[k]
        xi = np.einsum("ij,ij->i", x[i] - a, t) / L  # eq. 38
        g = np.einsum("ij,ij->i", x[i] - a, nrm)  # eq. 39
        xi0 = np.einsum("ij,ij->i", x_prev[i] - a, t) / L
        g0 = np.einsum("ij,ij->i", x_prev[i] - a, nrm)
        tol = 1e-9
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.where(g0 - g > 0, g0 / (g0 - g), np.inf)  # where along the path it crosses
            xic = np.where(np.isfinite(tau), xi0 + tau * (xi - xi0), np.nan)
        crossed = (g0 >= 0) & (g < 0) & (xic >= -tol) & (xic <= 1 + tol)
        inrange = (xi >= -tol) & (xi <= 1 + tol) & (g > -depth)
        # rank the pairs of each node: crossings first (earliest), then in-range (largest gap)
        score = np.where(crossed, 2.0 + (1.0 - np.minimum(tau, 1.0)), np.where(inrange, 1.0, -np.inf))
        gap_rank = np.where(crossed | ~inrange, 0.0, g)
        order = np.lexsort((gap_rank, score, i))  # ascending: the best pair of a node is its last
        last = np.r_[i[order][1:] != i[order][:-1], True]
        best = order[last]
        best = best[np.isfinite(score[best])]
        bi, bk = i[best], k[best]
        out.active[bi] = True
        out.g[bi] = g[best]
        out.n[bi] = self.nor[bk]
        out.t[bi] = self.tan[bk]
        xib = np.clip(xi[best], 0.0, 1.0)
        out.s[bi] = self.s0[bk] + xib * self.L[bk]
        out.point[bi] = self.a[bk] + (xib * self.L[bk])[:, None] * self.tan[bk]
        out.s_prev[bi] = self.s0[bk] + np.clip(xi0[best], 0.0, 1.0) * self.L[bk]
        out.kind[bi] = np.where(crossed[best], 3, 1)
        # cavity corners: a node behind segment k beyond its end and behind k+1 before its start
        free = ~out.active
        if free.any() and len(self.a) > 1:
            beyond = (xi > 1 + tol) & (g < 0) & (g > -depth) & free[i]
            before = (xi < -tol) & (g < 0) & (g > -depth) & free[i]
            key_end = set(zip(i[beyond].tolist(), k[beyond].tolist()))
            for node, seg in zip(i[before].tolist(), k[before].tolist()):
                if seg >= 1 and (node, seg - 1) in key_end and not out.active[node]:
                    prev = seg - 1
                    turn = self.tan[prev, 0] * self.tan[seg, 1] - self.tan[prev, 1] * self.tan[seg, 0]
                    if turn <= 0:  # the mould turns away from the body: no such dead zone
                        continue
                    v = self.b[prev]
                    nv = self.nor[prev] + self.nor[seg]
                    nv /= np.linalg.norm(nv)
                    out.active[node] = True
                    out.n[node] = nv
                    out.t[node] = [nv[1], -nv[0]]
                    out.g[node] = float(np.dot(x[node] - v, nv))
                    out.s[node] = out.s_prev[node] = self.s0[seg]
                    out.point[node] = v
                    out.kind[node] = 2
        return out
