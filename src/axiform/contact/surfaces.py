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

from ..fem.curves import PROPORTIONAL, Curve
from . import pieces, search
from .pieces import Pieces
from .projection import Projection, best_per_node

# `Polyline.local` tests every node against every piece's box at once up to this many pairs
# (N M); beyond, the global search of `search` finds the candidates
DENSE_PAIRS = 1 << 16


@dataclass
class RigidSurface:
    """motion: the rigid translation (r, z) applied as motion * curve(t) (curve: f(t) = t
    unless given)."""

    motion: tuple[float, float] = (0.0, 0.0)
    curve: Curve = PROPORTIONAL
    # the last offset and velocity asked for, by name: (t, curve, motion, value (2,))
    _held: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def offset(self, t: float) -> np.ndarray:
        """The translation at time t (2,) (read-only: kept for the next call at the same t)."""
        return self._kept("offset", t, self.curve)

    def velocity(self, t: float) -> np.ndarray:
        """d offset / dt (2,) (read-only: kept for the next call at the same t)."""
        return self._kept("velocity", t, self.curve.slope)

    def _kept(self, name: str, t: float, factor) -> np.ndarray:
        """motion * factor(t), from the last call of `name` where t, the curve and the motion
        are the same (every evaluation of a pair asks for them twice or more at one t)."""
        held = self._held.get(name)
        if held is None or held[0] != t or held[1] is not self.curve or held[2] is not self.motion:
            value = factor(t) * np.asarray(self.motion, float)
            value.flags.writeable = False
            held = self._held[name] = (t, self.curve, self.motion, value)
        return held[3]

    def local(self, x: np.ndarray, x_prev: np.ndarray, depth: float, method: str = "buckets") -> Projection:
        """The local search of the points x (n, 2), last converged at x_prev (n, 2), in the
        surface's frame: each surface kind gives its own."""
        raise NotImplementedError

    def polyline(self) -> np.ndarray:
        """The surface drawn as a chain of points (k, 2) in its own frame (pictures)."""
        raise NotImplementedError

    def local_sets(self, sets: list, method: str = "buckets") -> list[Projection]:
        """`local` of each set of points (x (n, 2), x_prev (n, 2), depth)."""
        return [self.local(x, x_prev, depth, method) for x, x_prev, depth in sets]


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
        ignored unless they crossed the circle since the last converged step or were less
        than `depth` behind it there."""
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
        # a node that was near the circle at the last converged step and is behind it now went
        # deeper during the increment (a Newton iterate may overshoot): it is still touching
        active = (g > -depth) | crossed | ((g_prev > -depth) & (g < 0))
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
class Polyline(RigidSurface, Pieces):
    """A chain of straight and circular pieces through `points` (k, 2); the body lies on the
    side of the normal n = (-s, c) of the direction of travel (eqs. 36-37): to the left when
    walking along the points.  `centers` (k - 1 entries, None for a straight piece) makes a
    piece a circular arc about that center, counter-clockwise where `ccw` says so.  Arcs are
    exact, not faceted: a node sliding round a die radius sees a smooth surface."""

    points: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))
    centers: list | None = None
    ccw: list | None = None
    polyline = Pieces.polyline  # the pieces' drawing, not the surface's abstract one

    def __post_init__(self):
        P = np.asarray(self.points, float)
        if P.ndim != 2 or P.shape[1] != 2 or len(P) < 2:
            raise ValueError("a polyline needs at least two points [r, z]")
        self.points = P
        m = len(P) - 1
        centers = self.centers or [None] * m
        ccw = self.ccw or [True] * m
        if len(centers) != m or len(ccw) != m:
            raise ValueError("one center (or None) and one ccw flag per piece")
        self._build_pieces(P, centers, ccw)
        self._pair_cache = search.PairCache()  # `_candidates`: the pairs of a step reused
        self._previous_held = None  # `_previous`: the last converged positions' projections, for the next call

    @classmethod
    def from_profile(cls, profile, motion=(0.0, 0.0)) -> Polyline:
        """The exact pieces of an axiform.fem.profile.Profile (lines and arcs)."""
        from ..fem.profile import Arc

        points = [profile.start] + [p.to for p in profile.pieces]
        centers = [p.center if isinstance(p, Arc) else None for p in profile.pieces]
        ccw = [p.ccw if isinstance(p, Arc) else True for p in profile.pieces]
        return cls(motion=motion, points=np.array(points, float), centers=centers, ccw=ccw)

    def reversed(self) -> Polyline:
        """The same pieces walked the other way: the body on the other side."""
        centers = [None if not arc else tuple(c) for arc, c in zip(self.is_arc, self.c, strict=False)][::-1]
        return Polyline(
            motion=self.motion,
            points=self.points[::-1].copy(),
            centers=centers,
            ccw=[bool(d < 0) for d in self.dir[::-1]],
        )

    def _previous(self, x_prev: np.ndarray, i: np.ndarray, k: np.ndarray):
        """xi and g of the last converged positions x_prev (n, 2) on the pairs (node i, piece
        k), from `_project`; kept for the next call, which the iterations of a step make with
        the same x_prev.  For a few pairs in all (n M <= DENSE_PAIRS) every point is projected
        onto every piece once per x_prev, and each call gathers its pairs (the candidates
        change from one iteration to the next as the points move); else the pairs of the
        last call are kept (the same numbers: `_project` works element by element)."""
        held = self._previous_held
        M = len(self.a)
        dense = len(x_prev) * M <= DENSE_PAIRS
        # the same bytes: the same numbers (tobytes: far cheaper than np.array_equal on a few hundred)
        if (
            held is None
            or held[0].shape != x_prev.shape
            or held[0].tobytes() != x_prev.tobytes()
            or (held[1] is None) != dense
            or (
                not dense
                and (
                    held[1].shape != i.shape
                    or held[1].dtype != i.dtype
                    or held[2].dtype != k.dtype
                    or held[1].tobytes() != i.tobytes()
                    or held[2].tobytes() != k.tobytes()
                )
            )
        ):
            xp = np.array(x_prev, float)
            if dense:  # every point on every piece, row by row
                kk = np.tile(np.arange(M), len(xp))
                held = (xp, None, None) + self._project(kk, xp.repeat(M, axis=0), full=False)
            else:
                held = (xp, i, k) + self._project(k, xp.take(i, axis=0), full=False)
            self._previous_held = held
        if held[1] is None:
            flat = i * M + k
            return held[3].take(flat), held[4].take(flat)
        return held[3], held[4]

    def _dense_candidates(self, x: np.ndarray, widen):
        """The (node, piece) pairs, sorted by node then piece, of the nodes x (n, 2) inside the
        pieces' boxes widened by `widen` (a number, or one per node (n, 1)): every node
        against every box at once."""
        xr, xz = x[:, 0, None], x[:, 1, None]
        inside = (xr >= self.lo[:, 0] - widen) & (xr <= self.hi[:, 0] + widen)
        inside &= (xz >= self.lo[:, 1] - widen) & (xz <= self.hi[:, 1] + widen)
        return inside.nonzero()

    def _candidates(self, x: np.ndarray, x_prev: np.ndarray, depth: float, moved: float, method: str):
        """The (node, piece) pairs of the global search (boxes widened by depth + moved),
        sorted by node then piece.  For a few pairs in all (N M <= DENSE_PAIRS) every node
        is tested against every widened box at once: the very pairs every method of `search`
        returns, without its set-up.  Else the search, its pairs of x_prev reused while the
        nodes stay near x_prev (`search.PairCache`: the same pairs)."""
        if len(x) * len(self.a) <= DENSE_PAIRS:
            return self._dense_candidates(x, depth + moved)
        finder = {"buckets": search.buckets, "binary": search.binary_sort, "brute": search.brute_force}[method]
        pairs = self._pair_cache.pairs(finder, x, x_prev, self.lo, self.hi, depth, moved)
        return pairs[:, 0], pairs[:, 1]

    def local(self, x: np.ndarray, x_prev: np.ndarray, depth: float, method: str = "buckets") -> Projection:
        """Candidates from the global search (piece boxes widened by the depth and by how far
        the nodes moved since the last converged step), then for each node:
        1. a piece its path crossed since the last converged step (front to back: paper
           Figure 6), the first one crossed along the path;
        2. else the pieces it projects onto (0 <= xi <= 1, eq. 38) with a gap above -depth
           (or any gap < 0, if it was in range with a gap above -depth at the last converged step):
           the one with the largest gap.  A node that entered a corner where the mould turns
           away from the body faces two pieces (Figure 8): it leaves by the nearer face;
        3. else a corner where the mould turns towards the body (a cavity corner), the node
           behind both pieces and outside both projection ranges, facing none (Figure 8):
           the vertex is its contact point, with the mean of the two normals.
        Every pair of every node is evaluated at once (arrays over the pairs, no loop over
        pieces or nodes)."""
        return self.local_sets([(x, x_prev, depth)], method)[0]

    def local_sets(self, sets: list, method: str = "buckets") -> list[Projection]:
        """`local` of several sets of points, (x (n, 2), x_prev (n, 2), depth) each, in one
        pass over the pairs: the very projections of one `local` per set (each set's
        candidates from its own depth and motion), the fixed cost of a call paid once (the
        slave nodes and the mid-points of their edges)."""
        if method not in ("buckets", "binary", "brute"):
            raise KeyError(method)
        sizes = [len(xs) for xs, _, _ in sets]
        bounds = [0]
        for size in sizes:
            bounds.append(bounds[-1] + size)
        x = np.concatenate([xs for xs, _, _ in sets]) if len(sets) > 1 else sets[0][0]
        x_prev = np.concatenate([xps for _, xps, _ in sets]) if len(sets) > 1 else sets[0][1]
        dxp = x - x_prev
        dist = np.sqrt(dxp[:, 0] * dxp[:, 0] + dxp[:, 1] * dxp[:, 1])
        moved = [float(dist[a:b].max()) if b > a else 0.0 for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
        depth = np.empty(len(x))  # per point
        for (_, _, ds), a, b in zip(sets, bounds[:-1], bounds[1:], strict=True):
            depth[a:b] = float(ds)
        if len(x) * len(self.a) <= DENSE_PAIRS:  # every point against every widened box at once
            widen = np.empty((len(x), 1))
            for (_, _, ds), mv, a, b in zip(sets, moved, bounds[:-1], bounds[1:], strict=True):
                widen[a:b] = float(ds) + mv
            i, k = self._dense_candidates(x, widen)
        else:
            ii, kk = [], []
            for (xs, xps, ds), mv, start in zip(sets, moved, bounds, strict=False):
                i, k = self._candidates(xs, xps, ds, mv, method)
                ii.append(i + start)
                kk.append(k)
            i, k = np.concatenate(ii), np.concatenate(kk)
        out = self._local_pairs(x, x_prev, i, k, depth.take(i))
        return (
            [out] if len(sets) == 1 else [out.rows(slice(a, b)) for a, b in zip(bounds[:-1], bounds[1:], strict=False)]
        )

    def _local_pairs(
        self, x: np.ndarray, x_prev: np.ndarray, i: np.ndarray, k: np.ndarray, depth: np.ndarray
    ) -> Projection:
        """Steps 1-3 of `local` over the candidate pairs (node i, piece k) sorted by node, with
        the depth of each pair's node."""
        nn = len(x)
        out = Projection.empty(nn)
        if len(i) == 0:
            return out
        xi, g, n, t, kappa, m, point = self._project(k, x.take(i, axis=0))
        xi0, g0 = self._previous(x_prev, i, k)
        tol = 1e-9
        dg = g0 - g
        tau = np.divide(g0, dg, out=np.full(len(g), np.inf), where=dg > 0)  # where along the path it crosses
        crossed = (g0 >= 0) & (g < 0) & np.isfinite(tau)
        if np.count_nonzero(crossed):
            ic = i[crossed]
            xp = x_prev.take(ic, axis=0)
            xc = xp + np.minimum(tau[crossed], 1.0)[:, None] * (x.take(ic, axis=0) - xp)
            xic = self._fraction(k[crossed], xc)
            crossed[crossed] = (xic >= -tol) & (xic <= 1 + tol)
        # in front of the piece or less than depth behind it; or behind it now and near it at the
        # last converged step (it went deeper during the increment: a Newton iterate may overshoot
        # the penalty; without this it would fall through the mould)
        near0 = (xi0 >= -tol) & (xi0 <= 1 + tol) & (g0 > -depth)
        inrange = (xi >= -tol) & (xi <= 1 + tol) & ((g > -depth) | (near0 & (g < 0)))
        # rank the pairs of each node: crossings first (earliest), then in-range (largest gap)
        score = np.where(crossed, 2.0 + (1.0 - np.minimum(tau, 1.0)), np.where(inrange, 1.0, -np.inf))
        gap_rank = np.where(crossed | ~inrange, 0.0, g)
        # per node the largest score, then among those the largest gap_rank, then the last such
        # pair: the last pair of each node in a stable sort by (node, score, gap_rank)
        single = np.empty(len(i), bool)  # whether each pair is the only one of its node
        np.not_equal(i[1:], i[:-1], out=single[1:])
        single[0] = True
        if np.count_nonzero(single) == len(i):  # one pair per node (the common case): nothing to choose
            best = np.arange(len(i))
        elif len(i) <= pieces.ARC_SUBSET:
            order = np.lexsort((gap_rank, score, i))
            io = i[order]
            last = np.empty(len(io), bool)
            np.not_equal(io[1:], io[:-1], out=last[:-1])
            last[-1] = True
            best = order[last]
        else:  # the same without the sort (the pairs come sorted by node): maxima per node
            best = best_per_node(i, score, gap_rank)
        best = best.compress(np.isfinite(score.take(best)))
        bi, bk = i.take(best), k.take(best)
        s0, length = self.s0.take(bk), self.L.take(bk)
        out.active[bi] = True
        out.g[bi], out.n[bi], out.t[bi] = g.take(best), n.take(best, axis=0), t.take(best, axis=0)
        out.kappa[bi], out.m[bi], out.point[bi] = kappa.take(best), m.take(best), point.take(best, axis=0)
        out.s[bi] = s0 + np.minimum(np.maximum(xi.take(best), 0.0), 1.0) * length
        out.s_prev[bi] = s0 + np.minimum(np.maximum(xi0.take(best), 0.0), 1.0) * length
        out.kind[bi] = np.where(crossed.take(best), 3, 1)
        if self._any_cavity and len(bi) < nn:  # a node without a point, and a corner to find it
            self._cavity_corners(out, x, i, k, g, xi, depth, tol)
        return out

    def _cavity_corners(
        self,
        out: Projection,
        x: np.ndarray,
        i: np.ndarray,
        k: np.ndarray,
        g: np.ndarray,
        xi: np.ndarray,
        depth: np.ndarray,
        tol: float,
    ) -> None:
        """Step 3 of `local`, in place on `out`: a node still without a contact point, behind
        piece k beyond its end and behind piece k+1 before its start, where the mould turns
        towards the body, touches the vertex, with the mean of the two normals.  Over the
        candidate pairs (i node, k piece), their projections (g, xi) and their nodes' depths."""
        free = ~out.active[i]
        behind = (g < 0) & (g > -depth) & free
        beyond = behind & (xi > 1 + tol)
        before = behind & (xi < -tol) & (k >= 1)
        if not (np.count_nonzero(beyond) and np.count_nonzero(before)):
            return
        M = len(self.a)
        nb, sb = i[before], k[before]
        # the previous piece's pair is a candidate beyond its end, and the mould turns
        # towards the body at the vertex (pairs sorted by node: the first such per node)
        hit = np.isin(nb * M + sb - 1, i[beyond] * M + k[beyond]) & self._cavity[sb]
        nb, sb = nb[hit], sb[hit]
        if not len(nb):
            return
        nb, first = np.unique(nb, return_index=True)
        sb = sb[first]
        v, nv = self.b[sb - 1], self._vertex_n[sb]
        out.active[nb] = True
        out.n[nb] = nv
        out.t[nb] = np.column_stack([nv[:, 1], -nv[:, 0]])
        # np.dot node by node, as ever (BLAS may round a dot product otherwise): few nodes
        out.g[nb] = [float(np.dot(d, e)) for d, e in zip(x[nb] - v, nv, strict=False)]
        out.s[nb] = out.s_prev[nb] = self.s0[sb]
        out.point[nb] = v
        out.kind[nb] = 2
