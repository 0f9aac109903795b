"""The local search of `Polyline` as it was before it was vectorized (a loop-free but
per-piece-masked evaluation, the bucket search for every call, a Python loop for cavity
corners), kept verbatim as the reference the array version must reproduce."""

import numpy as np

from axiform.contact import search
from axiform.contact.surfaces import Projection


def piece_local(self, k: np.ndarray, x: np.ndarray):
    arc = self.is_arc[k]
    a, tan = self.a[k], self.tan_a[k]
    nor = np.column_stack([-tan[:, 1], tan[:, 0]])
    xi = np.einsum("ij,ij->i", x - a, tan) / self.L[k]
    g = np.einsum("ij,ij->i", x - a, nor)
    t, n = tan.copy(), nor
    kappa = np.zeros(len(k))
    m = np.ones(len(k))
    if arc.any():
        ka, xa = k[arc], x[arc]
        d = xa - self.c[ka]
        rho = np.maximum(np.linalg.norm(d, axis=1), 1e-300)
        phi = np.arctan2(d[:, 1], d[:, 0])
        sweep, sgn = self.sweep[ka], self.dir[ka]
        alpha = ((phi - self.phi0[ka]) * sgn) % (2 * np.pi)
        after = alpha - sweep
        before = 2 * np.pi - alpha
        xa_frac = np.where(
            alpha <= sweep,
            alpha / np.where(sweep > 0, sweep, 1.0),
            np.where(after < before, 1.0 + after / sweep, -before / sweep),
        )
        ta = sgn[:, None] * np.column_stack([-np.sin(phi), np.cos(phi)])
        na = np.column_stack([-ta[:, 1], ta[:, 0]])
        xi[arc] = xa_frac
        g[arc] = np.einsum("ij,ij->i", d - self.R[ka, None] * d / rho[:, None], na)
        t[arc], n[arc] = ta, na
        kappa[arc] = -sgn / rho
        m[arc] = self.R[ka] / rho
    xic = np.clip(xi, 0.0, 1.0)
    point = np.where(arc[:, None], np.nan, a + (xic * self.L[k])[:, None] * tan)
    if arc.any():
        ka = k[arc]
        phi = self.phi0[ka] + self.dir[ka] * xic[arc] * self.sweep[ka]
        point[arc] = self.c[ka] + self.R[ka, None] * np.column_stack([np.cos(phi), np.sin(phi)])
    return xi, g, n, t, kappa, m, point


def local(self, x, x_prev, depth, method="buckets") -> Projection:
    nn = len(x)
    moved = float(np.linalg.norm(x - x_prev, axis=1).max()) if nn else 0.0
    widen = depth + moved
    finder = {"buckets": search.buckets, "binary": search.binary_sort, "brute": search.brute_force}[method]
    pairs = finder(x, self.lo, self.hi, widen)
    out = Projection.empty(nn)
    if len(pairs) == 0:
        return out
    i, k = pairs[:, 0], pairs[:, 1]
    xi, g, n, t, kappa, m, point = piece_local(self, k, x[i])
    xi0, g0, *_ = piece_local(self, k, x_prev[i])
    tol = 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(g0 - g > 0, g0 / (g0 - g), np.inf)
    crossed = (g0 >= 0) & (g < 0) & np.isfinite(tau)
    if crossed.any():
        xc = x_prev[i[crossed]] + np.minimum(tau[crossed], 1.0)[:, None] * (x[i[crossed]] - x_prev[i[crossed]])
        xic = piece_local(self, k[crossed], xc)[0]
        crossed[crossed] = (xic >= -tol) & (xic <= 1 + tol)
    near0 = (xi0 >= -tol) & (xi0 <= 1 + tol) & (g0 > -depth)
    inrange = (xi >= -tol) & (xi <= 1 + tol) & ((g > -depth) | (near0 & (g < 0)))
    score = np.where(crossed, 2.0 + (1.0 - np.minimum(tau, 1.0)), np.where(inrange, 1.0, -np.inf))
    gap_rank = np.where(crossed | ~inrange, 0.0, g)
    order = np.lexsort((gap_rank, score, i))
    last = np.r_[i[order][1:] != i[order][:-1], True]
    best = order[last]
    best = best[np.isfinite(score[best])]
    bi, bk = i[best], k[best]
    out.active[bi] = True
    out.g[bi], out.n[bi], out.t[bi] = g[best], n[best], t[best]
    out.kappa[bi], out.m[bi], out.point[bi] = kappa[best], m[best], point[best]
    out.s[bi] = self.s0[bk] + np.clip(xi[best], 0.0, 1.0) * self.L[bk]
    out.s_prev[bi] = self.s0[bk] + np.clip(xi0[best], 0.0, 1.0) * self.L[bk]
    out.kind[bi] = np.where(crossed[best], 3, 1)
    free = ~out.active
    if free.any() and len(self.a) > 1:
        beyond = (xi > 1 + tol) & (g < 0) & (g > -depth) & free[i]
        before = (xi < -tol) & (g < 0) & (g > -depth) & free[i]
        key_end = set(zip(i[beyond].tolist(), k[beyond].tolist(), strict=False))
        for node, seg in zip(i[before].tolist(), k[before].tolist(), strict=False):
            if seg >= 1 and (node, seg - 1) in key_end and not out.active[node]:
                prev = seg - 1
                t1, t2 = self.tan_b[prev], self.tan_a[seg]
                if t1[0] * t2[1] - t1[1] * t2[0] <= 0:
                    continue
                v = self.b[prev]
                nv = np.array([-t1[1], t1[0]]) + np.array([-t2[1], t2[0]])
                nv /= np.linalg.norm(nv)
                out.active[node] = True
                out.n[node] = nv
                out.t[node] = [nv[1], -nv[0]]
                out.g[node] = float(np.dot(x[node] - v, nv))
                out.s[node] = out.s_prev[node] = self.s0[seg]
                out.point[node] = v
                out.kind[node] = 2
    return out
