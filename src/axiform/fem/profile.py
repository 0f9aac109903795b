"""Mid-surface profiles in the (r, z) plane made of straight and circular pieces, sampled by
arc length: the skeleton of layered shells (balloons, parisons, preforms, plates)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Line:
    """A straight piece to the point `to`, cut into `divisions` elements."""

    to: tuple[float, float]
    divisions: int


@dataclass(frozen=True)
class Arc:
    """A circular piece about `center` to the point `to` (which must lie on the circle
    through the current point), counter-clockwise if ccw else clockwise, cut into
    `divisions` elements."""

    center: tuple[float, float]
    to: tuple[float, float]
    divisions: int
    ccw: bool = True


class ProfileError(ValueError):
    pass


@dataclass(frozen=True)
class Profile:
    """A chain of pieces from `start`."""

    start: tuple[float, float]
    pieces: tuple[Line | Arc, ...]

    def length(self) -> float:
        return float(self.sample(1)[2][-1])

    def sample(self, per_division: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Points (n, 2), unit tangents (n, 2), arc lengths (n,) and miter factors (n,) at every
        division end, with per_division - 1 extra points inside each division (2 for Q8).
        Where two pieces meet at an angle phi the tangent is their mean and an offset along
        the normal must be stretched by the miter factor 1 / cos(phi / 2) to keep the wall
        thickness."""
        if not self.pieces:
            raise ProfileError("a profile needs at least one piece")
        pts: list[np.ndarray] = [np.array(self.start, float)]
        tans: list[np.ndarray] = []
        arcs: list[float] = [0.0]
        miter = [1.0]
        p = np.array(self.start, float)
        s0 = 0.0
        first_tangent: np.ndarray | None = None
        for k, piece in enumerate(self.pieces):
            n = piece.divisions * per_division
            if piece.divisions < 1:
                raise ProfileError(f"piece {k}: divisions must be >= 1")
            q = np.array(piece.to, float)
            if isinstance(piece, Line):
                L = float(np.linalg.norm(q - p))
                if L == 0:
                    raise ProfileError(f"piece {k}: a line of zero length")
                t = (q - p) / L
                f = np.linspace(0, 1, n + 1)[1:]
                new = p + np.outer(f, q - p)
                newt = np.tile(t, (n, 1))
                start_t = t
                news = s0 + f * L
            else:
                c = np.array(piece.center, float)
                rad = float(np.linalg.norm(p - c))
                if abs(np.linalg.norm(q - c) - rad) > 1e-9 * max(rad, 1.0) or rad == 0:
                    raise ProfileError(
                        f"piece {k}: the arc's end {tuple(piece.to)} is not on the circle about "
                        f"{tuple(piece.center)} through {tuple(p)}"
                    )
                a0 = np.arctan2(*(p - c)[::-1])
                a1 = np.arctan2(*(q - c)[::-1])
                sweep = (a1 - a0) % (2 * np.pi)
                if not piece.ccw:
                    sweep -= 2 * np.pi
                if abs(sweep) < 1e-14:
                    raise ProfileError(f"piece {k}: an arc of zero sweep")
                a = a0 + np.linspace(0, 1, n + 1)[1:] * sweep
                new = c + rad * np.column_stack([np.cos(a), np.sin(a)])
                sgn = 1.0 if piece.ccw else -1.0
                newt = sgn * np.column_stack([-np.sin(a), np.cos(a)])
                start_t = sgn * np.array([-np.sin(a0), np.cos(a0)])
                news = s0 + np.linspace(0, 1, n + 1)[1:] * abs(sweep) * rad
            if first_tangent is None:
                first_tangent = start_t
            else:
                # average the tangents where two pieces meet
                avg = tans[-1] + start_t
                if np.linalg.norm(avg) < 1e-6:
                    raise ProfileError(f"piece {k}: the profile turns back on itself")
                tans[-1] = avg / np.linalg.norm(avg)
                miter[-1] = 2.0 / float(np.linalg.norm(avg))
            pts.extend(new)
            miter.extend([1.0] * n)
            tans.extend(newt)
            arcs.extend(news)
            p, s0 = q, news[-1]
        assert first_tangent is not None  # set by the first piece
        tans.insert(0, first_tangent)
        return np.array(pts), np.array(tans), np.array(arcs), np.array(miter)
