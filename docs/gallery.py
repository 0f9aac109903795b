"""Rebuild the gallery's pictures (docs/img/): run every example, draw its plots, and keep
small palette PNGs; the forming animations of the toric plate and the process examples as
GIFs.

    python docs/gallery.py          (about two minutes)
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from PIL import Image

from axiform.cli import main

ROOT = Path(__file__).resolve().parents[1]
IMG = ROOT / "docs" / "img"
EXAMPLES = [
    "hughes_carnoy_plate",
    "plate_arc_length",
    "thick_cylinder",
    "balloon",
    "toric_plate",
    "die_drawing",
    "bottle_blow_moulding",
    "parison_bottle",
    "cup_thermoforming",
    "stretch_blow_moulding",
]
ANIMATED = ["toric_plate", "bottle_blow_moulding", "cup_thermoforming", "stretch_blow_moulding"]


def small_png(source: Path, target: Path) -> None:
    """The picture with a 256-colour palette: a third of the size, no visible change."""
    with Image.open(source) as im:
        im.convert("RGB").quantize(256, dither=Image.Dither.NONE).save(target, optimize=True)


def build() -> int:
    IMG.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name in EXAMPLES:
            out = Path(tmp) / name
            if main(["run", str(ROOT / "examples" / f"{name}.toml"), "--out", str(out), "-q"]) != 0:
                return 1
            if name in ANIMATED:
                main(["plot", str(out), "--animate"])
                shutil.copy(out / "forming.gif", IMG / f"{name}_forming.gif")
            for png in ("load_curve", "thickness", "deformed"):
                small_png(out / f"{png}.png", IMG / f"{name}_{png}.png")
    return 0


if __name__ == "__main__":
    sys.exit(build())
