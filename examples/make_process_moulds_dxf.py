#!/usr/bin/env python
"""Write the mould drawings of the process examples (lengths in mm, the x-y plane read as
(r, z), the body to the left of the direction in which each path is drawn):

- bottle_mould.dxf (bottle_blow_moulding.toml), layer MOULD: an extrusion-blow-moulded
  bottle, drawn from the axis at the base (a push-up) out along the base, round the base
  corner, up the body, in over the shoulder and up the neck;
- stretch_blow_mould.dxf (stretch_blow_moulding.toml), layer MOULD: a slimmer bottle for a
  preform, the same way; layer ROD: the stretch rod, drawn down its side and round its
  hemispherical tip to the axis;
- thermoform_cup.dxf (cup_thermoforming.toml), layer MOULD: a deep cup mould with a draft,
  drawn from the axis along the bottom, up the wall, over the entry radius and out along the
  clamp flange; layer PLUG: the plug assist, drawn down its side, round its nose and along
  its face to the axis.

Every path is one LWPOLYLINE whose corners are rounded by exact arcs (bulges).

    python examples/make_process_moulds_dxf.py
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import numpy as np

HERE = Path(__file__).parent

# corner points (r, z) and the radius of the arc that rounds each inner corner
BOTTLE = [(0.0, 5.0), (22.0, 0.0, 10.0), (38.0, 0.0, 10.0), (38.0, 135.0, 25.0), (17.5, 175.0, 10.0), (17.5, 200.0)]
STRETCH = [(0.0, 5.0), (20.0, 0.0, 8.0), (33.0, 0.0, 8.0), (33.0, 150.0, 22.0), (11.5, 185.0, 6.0), (11.5, 200.0)]
ROD = [(5.0, 260.0), (5.0, 108.0, 5.0), (-1.0, 108.0)]
CUP = [(0.0, -50.0), (30.0, -50.0, 8.0), (36.0, 0.0, 4.0), (60.0, 0.0)]
PLUG = [(24.0, 63.0), (24.0, 3.0, 8.0), (-1.0, 3.0)]


def rounded(corners: list[tuple[float, ...]]) -> list[tuple[float, float, float]]:
    """LWPOLYLINE vertices (r, z, bulge) of a polyline whose inner corners (r, z, radius) are
    rounded by arcs tangent to both sides: each corner becomes the arc's two ends, the first
    with the bulge tan(phi / 4) of the turn phi (> 0 to the left)."""
    pts = [np.array(c[:2], float) for c in corners]
    out = [(*pts[0], 0.0)]
    for k in range(1, len(pts) - 1):
        if len(corners[k]) < 3:
            out.append((*pts[k], 0.0))
            continue
        d1 = (pts[k] - pts[k - 1]) / np.linalg.norm(pts[k] - pts[k - 1])
        d2 = (pts[k + 1] - pts[k]) / np.linalg.norm(pts[k + 1] - pts[k])
        phi = np.arctan2(d1[0] * d2[1] - d1[1] * d2[0], d1 @ d2)
        tangent = corners[k][2] * np.tan(abs(phi) / 2)
        out.append((*(pts[k] - tangent * d1), np.tan(phi / 4)))
        out.append((*(pts[k] + tangent * d2), 0.0))
    out.append((*pts[-1], 0.0))
    return out


def drawing(path: Path, layers: dict[str, list[tuple[float, ...]]]) -> None:
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for layer, corners in layers.items():
        msp.add_lwpolyline(rounded(corners), format="xyb", dxfattribs={"layer": layer})
    doc.saveas(path)


def main(folder: Path = HERE) -> None:
    drawing(folder / "bottle_mould.dxf", {"MOULD": BOTTLE})
    drawing(folder / "stretch_blow_mould.dxf", {"MOULD": STRETCH, "ROD": ROD})
    drawing(folder / "thermoform_cup.dxf", {"MOULD": CUP, "PLUG": PLUG})


if __name__ == "__main__":
    main()
