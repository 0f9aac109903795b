"""The geometry of a chain of straight and circular pieces in the (r, z) plane (a Polyline's
pieces): the arrays of the pieces (ends, arcs, lengths, tangents, boxes, cavity corners) and
the projection of points onto given pieces, every (piece, point) pair at once."""

from __future__ import annotations

import numpy as np

# `Pieces._project` evaluates the arc formulas on every pair up to this many pairs (fewer
# array operations), beyond on the arcs' pairs only (less arithmetic)
ARC_SUBSET = 4096
NO_ARC = np.zeros(0, bool)  # `_project`'s arc flags of a chain without arcs (never read)
TURN = np.array([-1.0, 1.0])  # a tangent reversed, times this: turned by +90 degrees
TURN.flags.writeable = False


class Pieces:
    """The pieces of a chain (a mixin of surfaces.Polyline): `_build_pieces` sets the arrays,
    `_project` projects points onto pieces.  Per piece (m,): ends a, b (m, 2), is_arc,
    centers c (m, 2) (NaN for a line), radii R, start angles phi0, direction dir (+1 ccw,
    -1 cw), sweep, length L, end tangents tan_a, tan_b (m, 2), arc-length start s0, box lo,
    hi (m, 2)."""

    a: np.ndarray
    b: np.ndarray
    is_arc: np.ndarray
    c: np.ndarray
    R: np.ndarray
    phi0: np.ndarray
    dir: np.ndarray
    sweep: np.ndarray
    L: np.ndarray
    tan_a: np.ndarray
    tan_b: np.ndarray
    s0: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    _any_arc: bool
    _par: np.ndarray
    _cavity: np.ndarray
    _any_cavity: bool
    _vertex_n: np.ndarray

    def _build_pieces(self, P: np.ndarray, centers: list, ccw: list) -> None:
        """The pieces' arrays of the chain through the points P (k, 2), `centers` (k - 1, None
        for a straight piece) and `ccw` (k - 1 flags): ends, arcs' centers, radii, angles and
        sweeps, lengths, end tangents, arc-length starts, bounding boxes, the packed
        parameters of `_project`, and the cavity corners (where the mould turns towards the
        body) with their mean normals."""
        m = len(P) - 1
        self.a, self.b = P[:-1], P[1:]
        self.is_arc = np.array([c is not None for c in centers])
        self.c = np.array([c if c is not None else (np.nan, np.nan) for c in centers], float)
        chord = np.linalg.norm(self.b - self.a, axis=1)
        if (chord <= 0).any():
            raise ValueError(f"polyline piece {int(np.argmin(chord))} has zero length")
        self.R = np.where(self.is_arc, np.linalg.norm(self.a - np.nan_to_num(self.c), axis=1), np.nan)
        self.phi0 = np.arctan2(self.a[:, 1] - self.c[:, 1], self.a[:, 0] - self.c[:, 0])
        phi1 = np.arctan2(self.b[:, 1] - self.c[:, 1], self.b[:, 0] - self.c[:, 0])
        self.dir = np.where(np.asarray(ccw, bool), 1.0, -1.0)  # +1 ccw, -1 cw
        for k in np.flatnonzero(self.is_arc):
            if abs(np.linalg.norm(self.b[k] - self.c[k]) - self.R[k]) > 1e-9 * max(self.R[k], 1.0):
                raise ValueError(f"polyline piece {k}: the arc's ends are not on one circle")
        self.sweep = np.where(self.is_arc, ((phi1 - self.phi0) * self.dir) % (2 * np.pi), 0.0)
        self.L = np.where(self.is_arc, self.R * self.sweep, chord)
        tan = (self.b - self.a) / chord[:, None]
        self.tan_a, self.tan_b = tan.copy(), tan.copy()
        for k in np.flatnonzero(self.is_arc):
            for end, phi in (("tan_a", self.phi0[k]), ("tan_b", phi1[k])):
                getattr(self, end)[k] = self.dir[k] * np.array([-np.sin(phi), np.cos(phi)])
        self.s0 = np.concatenate([[0.0], np.cumsum(self.L)[:-1]])
        # bounding boxes of the pieces for the global search
        self.lo, self.hi = np.minimum(self.a, self.b), np.maximum(self.a, self.b)
        for k in np.flatnonzero(self.is_arc):
            pts = self._arc_points(int(k), 33)
            self.lo[k], self.hi[k] = pts.min(axis=0), pts.max(axis=0)
        # the pieces as arrays for `_project` (a straight piece: center 0, radius 1, phi0 0,
        # sweep 1, unused), and each vertex k (between pieces k - 1 and k) for cavity corners:
        # whether the mould turns towards the body there, and the mean normal
        arc = self.is_arc
        self._any_arc = bool(arc.any())
        self._par = np.column_stack(
            [
                self.a,
                self.tan_a,
                self.L,
                np.where(arc[:, None], self.c, 0.0),
                np.where(arc, self.R, 1.0),
                np.where(arc, self.phi0, 0.0),
                np.where(arc & (self.sweep > 0), self.sweep, 1.0),
                self.dir,
                -self.tan_a[:, 1],
                self.tan_a[:, 0],
            ]
        )
        self._cavity = np.zeros(m, bool)
        self._vertex_n = np.zeros((m, 2))
        for j in range(1, m):
            t1, t2 = self.tan_b[j - 1], self.tan_a[j]
            self._cavity[j] = t1[0] * t2[1] - t1[1] * t2[0] > 0
            nv = np.array([-t1[1], t1[0]]) + np.array([-t2[1], t2[0]])
            norm = np.linalg.norm(nv)
            self._vertex_n[j] = nv / norm if norm > 0 else nv
        self._any_cavity = bool(self._cavity.any())

    def _arc_points(self, k: int, n: int) -> np.ndarray:
        phi = self.phi0[k] + self.dir[k] * np.linspace(0, self.sweep[k], n)
        return self.c[k] + self.R[k] * np.column_stack([np.cos(phi), np.sin(phi)])

    def polyline(self) -> np.ndarray:
        """Points along the surface, arcs sampled finely (for pictures)."""
        out = [self.a[:1]]
        for k in range(len(self.a)):
            out.append(self._arc_points(k, 25)[1:] if self.is_arc[k] else self.b[k : k + 1])
        return np.vstack(out)

    def _project(self, k: np.ndarray, x: np.ndarray, full: bool = True, subset: bool = True):
        """For pairs (piece k (p,), point x (p, 2)): xi (fraction along the piece, < 0 before
        its start, > 1 beyond its end), gap g, normal n, tangent t, curvature kappa, m, point,
        every pair at once: the pieces' data gathered by k and
        both the straight and the circular formula evaluated for every pair (the arc's only
        where a pair lies on an arc), the right one picked by np.where.  full=False: xi and g
        only (the last converged positions need no more)."""
        P = self._par.take(k, axis=0)  # (p, 13): one gather of every piece's constants (take: no fancy indexing)
        ar, az, tr, tz, L, cr, cz, R, phi0, sweep, sgn = P.T[:11]
        xr, xz = x[:, 0], x[:, 1]
        dx, dz = xr - ar, xz - az
        xi = (dx * tr + dz * tz) / L
        g = dx * -tz + dz * tr  # (x - a) . nor, nor = (-t_z, t_r)
        arc = self.is_arc.take(k) if self._any_arc else NO_ARC
        arcs = self._any_arc and np.count_nonzero(arc) > 0  # the arc formulas only where a pair is on an arc
        if arcs:
            if subset and len(k) > ARC_SUBSET:
                return self._project_subset(k, x, full, arc, xi, g, P)
            dr, dh = xr - cr, xz - cz
            rho = np.maximum(np.sqrt(dr * dr + dh * dh), 1e-300)
            phi = np.arctan2(dh, dr)
            alpha = ((phi - phi0) * sgn) % (2 * np.pi)
            after = alpha - sweep
            before = 2 * np.pi - alpha
            frac = np.where(
                alpha <= sweep, alpha / sweep, np.where(after < before, 1.0 + after / sweep, -before / sweep)
            )
            cos, sin = np.cos(phi), np.sin(phi)
            nar, naz = -(sgn * cos), sgn * -sin  # the arc's normal: its tangent sgn (-sin, cos) turned
            ga = (dr - R * dr / rho) * nar + (dh - R * dh / rho) * naz
            xi = np.where(arc, frac, xi)
            g = np.where(arc, ga, g)
        if not full:
            return xi, g
        xic = np.minimum(np.maximum(xi, 0.0), 1.0)
        t, n = P[:, 2:4], P[:, 11:13]  # the line's tangent and normal
        point = P[:, 0:2] + (xic * L)[:, None] * t
        if arcs:
            isarc = arc[:, None]
            sc = np.empty((len(k), 2))
            np.negative(sin, out=sc[:, 0])
            sc[:, 1] = cos
            ta = sgn[:, None] * sc  # sgn (-sin, cos)
            t = np.where(isarc, ta, t)
            n = np.where(isarc, ta[:, ::-1] * TURN, n)
            kappa = np.where(arc, -sgn / rho, 0.0)  # ccw: the body inside the arc
            m = np.where(arc, R / rho, 1.0)
            ph = phi0 + sgn * xic * sweep
            sc[:, 0] = np.cos(ph)
            sc[:, 1] = np.sin(ph)
            point = np.where(isarc, P[:, 5:7] + R[:, None] * sc, point)
        else:
            kappa, m = np.zeros(len(k)), np.ones(len(k))
        return xi, g, n, t, kappa, m, point

    def _fraction(self, k: np.ndarray, x: np.ndarray) -> np.ndarray:
        """xi of `_project` alone, for pairs (piece k (p,), point x (p, 2)): the fraction along
        the piece (the crossing test needs no more), the same numbers with neither the gap
        nor the arcs' radii."""
        P = self._par.take(k, axis=0)
        ar, az, tr, tz, L, cr, cz, _, phi0, sweep, sgn = P.T[:11]
        xr, xz = x[:, 0], x[:, 1]
        xi = ((xr - ar) * tr + (xz - az) * tz) / L
        arc = self.is_arc.take(k) if self._any_arc else NO_ARC
        if not (self._any_arc and np.count_nonzero(arc)):
            return xi
        alpha = ((np.arctan2(xz - cz, xr - cr) - phi0) * sgn) % (2 * np.pi)
        after = alpha - sweep
        before = 2 * np.pi - alpha
        frac = np.where(alpha <= sweep, alpha / sweep, np.where(after < before, 1.0 + after / sweep, -before / sweep))
        return np.where(arc, frac, xi)

    def _project_subset(self, k, x, full, arc, xi, g, P):
        """`_project` for many pairs: the arc formulas on the arcs' pairs only (the same
        numbers: every formula works element by element)."""
        ia = np.flatnonzero(arc)
        sub = self._project(k[ia], x[ia], full, subset=False)
        xi[ia], g[ia] = sub[0], sub[1]
        if not full:
            return xi, g
        xic = np.minimum(np.maximum(xi, 0.0), 1.0)
        t, n = P[:, 2:4].copy(), P[:, 11:13].copy()
        point = P[:, 0:2] + (xic * P[:, 4])[:, None] * t
        kappa, m = np.zeros(len(k)), np.ones(len(k))
        n[ia], t[ia], kappa[ia], m[ia], point[ia] = sub[2:]
        return xi, g, n, t, kappa, m, point
