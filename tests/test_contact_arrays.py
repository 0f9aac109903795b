"""The array local search of `Polyline` (every (node, piece) pair at once, small problems
tested against every widened box without the bucket search) against the previous per-piece
one (tests/contact_reference.py) on random points: lines and arcs both ways, points on the
pieces' ends, crossings, cavity corners, depth; and the cached Gauss rules."""

import contact_reference as ref
import numpy as np
import pytest

from axiform.contact import pieces, surfaces
from axiform.contact.projection import best_per_node
from axiform.contact.surfaces import Polyline
from axiform.fem.elements import edge_rule, edge_shape, gauss_1d, gauss_quad

FIELDS = ("active", "g", "n", "t", "s", "kappa", "m", "point", "s_prev", "kind")


def same(p, q):
    """Bitwise equal projections (NaN equal to NaN)."""
    for f in FIELDS:
        a, b = getattr(p, f), getattr(q, f)
        assert a.dtype == b.dtype and a.shape == b.shape, f
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), (f, np.abs(a.astype(float) - b).max())


def random_polyline(rng, pieces):
    """A chain of lines and arcs (ccw and cw, sweeps up to 270 degrees), tangent or kinked."""
    p = np.array([0.0, 0.0])
    heading = rng.uniform(0, 2 * np.pi)
    points, centers, ccw = [p.copy()], [], []
    for _ in range(pieces):
        heading += rng.choice([0.0, rng.uniform(-2, 2)])
        d = np.array([np.cos(heading), np.sin(heading)])
        if rng.random() < 0.5:
            p = p + rng.uniform(0.3, 2.0) * d
            centers.append(None)
            ccw.append(True)
        else:
            turn = rng.choice([1.0, -1.0])
            R = rng.uniform(0.2, 1.5)
            c = p + turn * R * np.array([-d[1], d[0]])
            sweep = rng.uniform(0.2, 1.5 * np.pi)
            phi = np.arctan2(*(p - c)[::-1]) + turn * sweep
            p = c + R * np.array([np.cos(phi), np.sin(phi)])
            heading += turn * sweep
            centers.append(tuple(c))
            ccw.append(bool(turn > 0))
        points.append(p.copy())
    return Polyline(points=np.array(points), centers=centers, ccw=ccw)


def near_points(rng, surf, n, spread):
    """Points around the surface: on it (ends and interior), in front and behind."""
    pts = surf.polyline()
    base = pts[rng.integers(0, len(pts), n)]
    x = base + rng.normal(0, spread, (n, 2))
    x[: n // 10] = base[: n // 10]  # on the surface, piece ends included
    ends = np.vstack([surf.a, surf.b[-1:]])
    x[n // 10 : n // 5] = ends[rng.integers(0, len(ends), n // 5 - n // 10)]
    return x


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("method", ["buckets", "binary", "brute"])
def test_array_local_search_is_the_per_piece_one(seed, method):
    rng = np.random.default_rng(seed)
    surf = random_polyline(rng, int(rng.integers(1, 9)))
    n = int(rng.integers(1, 400))
    x_prev = near_points(rng, surf, n, 0.3)
    step = rng.normal(0, rng.choice([0.01, 0.1, 0.5]), (n, 2))  # small and large increments: crossings
    x = x_prev + step
    x[: n // 7] = x_prev[: n // 7]
    for depth in (0.02, 0.2, 1.0):
        for p_prev, p_now in ((x_prev, x), (x, x), (x, x_prev)):
            same(surf.local(p_now, p_prev, depth, method), ref.local(surf, p_now, p_prev, depth, method))
        same(surf.reversed().local(x, x_prev, depth, method), ref.local(surf.reversed(), x, x_prev, depth, method))


@pytest.mark.parametrize("seed", range(4))
def test_dense_and_searched_candidates_agree(seed, monkeypatch):
    """Small problems skip the global search (every box tested at once): the same answer."""
    rng = np.random.default_rng(100 + seed)
    surf = random_polyline(rng, 6)
    x_prev = near_points(rng, surf, 300, 0.2)
    x = x_prev + rng.normal(0, 0.05, x_prev.shape)
    dense = surf.local(x, x_prev, 0.1)
    monkeypatch.setattr(surfaces, "DENSE_PAIRS", 0)
    for method in ("buckets", "binary", "brute"):
        same(surf.local(x, x_prev, 0.1, method), dense)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("dense", [True, False])
def test_one_pass_over_several_sets_is_one_call_per_set(seed, dense, monkeypatch):
    """`local_sets` (the slave nodes and their edges' mid-points in one pass) gives each set
    the very projection of its own `local` call: its own depth and motion."""
    if not dense:
        monkeypatch.setattr(surfaces, "DENSE_PAIRS", 0)
    rng = np.random.default_rng(200 + seed)
    surf = random_polyline(rng, int(rng.integers(2, 9)))
    sets = []
    for n, spread, depth in (
        (int(rng.integers(1, 300)), 0.3, 0.05),
        (int(rng.integers(1, 300)), 0.1, 0.4),
        (0, 0.1, 0.1),
    ):
        x_prev = near_points(rng, surf, n, spread) if n else np.zeros((0, 2))
        sets.append((x_prev + rng.normal(0, rng.choice([0.01, 0.2]), (n, 2)), x_prev, depth))
    for method in ("buckets", "binary"):
        for p, (x, x_prev, depth) in zip(surf.local_sets(sets, method), sets, strict=False):
            same(p, surf.local(x, x_prev, depth, method))


def test_the_projection_is_the_reference_on_every_pair():
    rng = np.random.default_rng(7)
    surf = random_polyline(rng, 8)
    x = near_points(rng, surf, 500, 1.0)
    k = rng.integers(0, len(surf.a), len(x))
    for a, b in zip(surf._project(k, x), ref.piece_local(surf, k, x), strict=False):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("seed", range(4))
def test_the_fraction_alone_is_that_of_the_projection(seed):
    """The crossing test's xi (Pieces._fraction) is _project's, number for number, on lines and
    arcs, and on a chain of lines only."""
    rng = np.random.default_rng(40 + seed)
    surf = random_polyline(rng, int(rng.integers(1, 9)))
    x = near_points(rng, surf, 300, 1.0)
    k = rng.integers(0, len(surf.a), len(x))
    assert np.array_equal(surf._fraction(k, x), surf._project(k, x, full=False)[0])
    lines = np.flatnonzero(~surf.is_arc)
    if len(lines):
        kl = rng.choice(lines, len(x))
        assert np.array_equal(surf._fraction(kl, x), surf._project(kl, x, full=False)[0])


def test_points_on_piece_ends_and_cavity_corners():
    """A cup-like cavity (line, cw arc, line, a sharp cavity corner, line): nodes on every
    vertex, nodes behind the sharp corner (vertex contact, kind 2), nodes crossing a face."""
    cav = Polyline(
        points=[[0.0, 0.0], [2.0, 0.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]],
        centers=[None, (2.0, 1.0), None, None],
        ccw=[True, True, True, True],
    )
    x_prev = np.vstack([cav.points, [[3.05, 3.04], [0.5, 0.1], [2.5, 1.5]]])
    x = np.vstack([cav.points, [[3.05, 3.04], [0.5, -0.3], [3.2, 1.5]]])
    p = cav.local(x, x_prev, 0.1)
    same(p, ref.local(cav, x, x_prev, 0.1))
    assert p.active[:5].all() and np.allclose(p.g[:5], 0.0, atol=1e-12)
    assert p.kind[5] == 2 and np.allclose(p.point[5], [3.0, 3.0])
    assert p.kind[6] == 3 and p.kind[7] == 3  # crossed the bottom and the wall in the increment
    q = cav.local(x, x, 0.1)  # without the path: too deep behind the bottom
    assert not q.active[6]
    same(q, ref.local(cav, x, x, 0.1))


def test_no_candidates_and_no_nodes():
    surf = Polyline(points=[[0.0, 0.0], [1.0, 0.0]])
    far = np.array([[10.0, 10.0]])
    same(surf.local(far, far, 0.1), ref.local(surf, far, far, 0.1))
    none = np.zeros((0, 2))
    assert len(surf.local(none, none, 0.1).g) == 0


def test_gauss_rules_are_built_once_and_read_only():
    s, w = gauss_1d(3)
    assert gauss_1d(3)[0] is s
    assert np.array_equal(s, np.polynomial.legendre.leggauss(3)[0])
    with pytest.raises(ValueError):
        w[0] = 1.0
    xi, wq = gauss_quad(2)
    assert xi.shape == (4, 2) and not wq.flags.writeable and np.isclose(wq.sum(), 4.0)


@pytest.mark.parametrize("seed", range(6))
def test_many_pairs_path_is_the_reference(seed, monkeypatch):
    """Beyond ARC_SUBSET pairs the arc formulas run on the arcs' pairs only and the best pair
    of each node is found without a sort: the same answer."""
    monkeypatch.setattr(pieces, "ARC_SUBSET", 0)
    rng = np.random.default_rng(200 + seed)
    surf = random_polyline(rng, int(rng.integers(1, 9)))
    x_prev = near_points(rng, surf, 500, 0.3)
    x = x_prev + rng.normal(0, 0.1, x_prev.shape)
    for depth in (0.05, 0.5):
        same(surf.local(x, x_prev, depth), ref.local(surf, x, x_prev, depth))
    k = rng.integers(0, len(surf.a), len(x))
    for a, b in zip(surf._project(k, x), ref.piece_local(surf, k, x), strict=False):
        assert np.array_equal(a, b)


def test_best_per_node_is_the_last_of_a_stable_sort():
    rng = np.random.default_rng(3)
    i = np.sort(rng.integers(0, 300, 2000))
    score = rng.choice([-np.inf, 1.0, 2.25, 2.5], len(i))
    rank = rng.choice([0.0, -0.0, 0.5, -1.0, 3.0], len(i))
    order = np.lexsort((rank, score, i))
    expected = order[np.r_[i[order][1:] != i[order][:-1], True]]
    assert np.array_equal(best_per_node(i, score, rank), expected)


@pytest.mark.parametrize("method", ["buckets", "binary", "brute"])
def test_pair_cache_returns_what_a_new_search_returns(method):
    """Iterations of a step (x near the same x_prev, small and large moves: reuse and new
    searches), a new step, a second set of nodes (the guards) in between."""
    from axiform.contact import search

    plain = {"buckets": search.buckets, "binary": search.binary_sort, "brute": search.brute_force}[method]
    searches = []

    def finder(*args):
        searches.append(1)
        return plain(*args)

    rng = np.random.default_rng(11)
    surf = random_polyline(rng, 7)
    cache = search.PairCache()
    for _step in range(4):
        x_prev = near_points(rng, surf, 400, 0.3)
        mids = near_points(rng, surf, 399, 0.3)
        for _it, size in enumerate([0.0, 0.02, 0.01, 0.3, 0.05, 0.001]):
            for xp in (x_prev, mids):
                x = xp + rng.normal(0, size, xp.shape)
                x[::5] = xp[::5] + size  # some exactly the largest move
                moved = float(np.linalg.norm(x - xp, axis=1).max())
                got = cache.pairs(finder, x, xp, surf.lo, surf.hi, 0.05, moved)
                assert np.array_equal(got, plain(x, surf.lo, surf.hi, 0.05 + moved))
    assert 16 <= len(searches) < 48  # a new search per step and set of nodes, and after large moves


def test_large_problems_reuse_the_search_and_agree(monkeypatch):
    """Through Polyline.local with the dense test off: calls of a step agree with the
    per-piece reference, whether the pairs were searched or reused."""
    monkeypatch.setattr(surfaces, "DENSE_PAIRS", 0)
    rng = np.random.default_rng(5)
    surf = random_polyline(rng, 6)
    x_prev = near_points(rng, surf, 600, 0.2)
    for size in (0.0, 0.01, 0.02, 0.2, 0.01):
        x = x_prev + rng.normal(0, size, x_prev.shape)
        same(surf.local(x, x_prev, 0.05), ref.local(surf, x, x_prev, 0.05))


def test_calls_of_a_step_agree_with_a_surface_that_saw_none(monkeypatch):
    """Calls of steps on one surface (one x_prev a step, the candidates changing as x moves;
    its projections kept once a step for every piece, or per pairs above DENSE_PAIRS) give
    the very projections of a new surface, and those of the per-piece reference."""
    rng = np.random.default_rng(8)
    surf = random_polyline(rng, 6)
    for dense in (1 << 16, 0, 1 << 16):
        monkeypatch.setattr(surfaces, "DENSE_PAIRS", dense)
        x_prev = near_points(rng, surf, 300, 0.2)
        for size in (0.0, 0.01, 0.2, 0.02, 0.0):
            x = x_prev + rng.normal(0, size, x_prev.shape)
            got = surf.local(x, x_prev, 0.05)
            same(got, Polyline(points=surf.points, centers=surf.centers, ccw=surf.ccw).local(x, x_prev, 0.05))
            same(got, ref.local(surf, x, x_prev, 0.05))


@pytest.mark.parametrize("k", [2, 3])
def test_edge_rule_is_the_gauss_rule_with_the_edge_shapes(k):
    s, w, N, dN = edge_rule(k, 3)
    assert s is gauss_1d(3)[0] and w is gauss_1d(3)[1] and edge_rule(k, 3)[2] is N
    N2, dN2 = edge_shape(k, s)
    assert np.array_equal(N, N2) and np.array_equal(dN, dN2) and not dN.flags.writeable
