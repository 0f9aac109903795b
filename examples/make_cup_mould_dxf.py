#!/usr/bin/env python
"""Write examples/cup_mould.dxf, the drawing of examples/cup_thermoforming.toml (lengths in mm),
in the x-y plane read as (r, z):

- layer MOULD, the female cup mould: its bottom (LINE), bottom corner (ARC, radius 8), wall
  (LINE, drawn the other way on purpose) and entry radius with flange (LWPOLYLINE with a
  bulge), in no particular order; the bottom line comes first, so the path runs from the
  axis outwards and the sheet, above it, lies to its left;
- layer PLUG, the plug assist: one LWPOLYLINE down its side, round its nose (bulge) and
  along its face to the axis;
- layer NOTES, a title (not read: the case names its layers).

    python examples/make_cup_mould_dxf.py
"""

from pathlib import Path

import ezdxf

QUARTER_CW = -0.41421356237309503  # bulge of a clockwise quarter circle: -tan(90 deg / 4)


DRAWING = Path(__file__).with_name("cup_mould.dxf")


def main(path: Path = DRAWING) -> None:
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    mould = {"layer": "MOULD"}
    msp.add_line((0.0, -30.0), (32.0, -30.0), dxfattribs=mould)
    msp.add_lwpolyline([(40.0, -5.0, QUARTER_CW), (45.0, 0.0, 0.0), (60.0, 0.0, 0.0)], format="xyb", dxfattribs=mould)
    msp.add_line((40.0, -5.0), (40.0, -22.0), dxfattribs=mould)
    msp.add_arc((32.0, -22.0), 8.0, -90.0, 0.0, dxfattribs=mould)
    msp.add_lwpolyline(
        [(28.0, 60.0, 0.0), (28.0, 10.0, QUARTER_CW), (22.0, 4.0, 0.0), (-1.0, 4.0, 0.0)],
        format="xyb",
        dxfattribs={"layer": "PLUG"},
    )
    msp.add_text("cup mould and plug, mm", dxfattribs={"layer": "NOTES", "height": 2.0}).set_placement((0.0, 70.0))
    doc.saveas(path)


if __name__ == "__main__":
    main()
