"""The one way axiform draws a picture: a matplotlib `Figure` built directly (no pyplot, no
backend switch, no global state: figures can be drawn in any thread or process) and written
by `Figure.savefig`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Literal

DPI = 110  # the results folder's pictures


def new_figure(figsize: tuple[float, float], layout: Literal["constrained", "tight"] | None = "constrained"):
    """An empty figure of `figsize` inches; its axes come from fig.subplots / add_subplot.
    layout: "constrained" (default), "tight" or None."""
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout=layout)


def colormap(name: str):
    """The registered colour map `name` (viridis, Blues...)."""
    import matplotlib

    return matplotlib.colormaps[name]


def save(fig, path: str | Path, dpi: float = DPI, **savefig: Any) -> Path | None:
    """Write `fig` to `path` (PNG unless the name or format= says otherwise) at `dpi`; None
    for no figure.  A PNG at zlib's fastest level: the plate's three pictures saved in
    0.37 s instead of 0.40 s, the files 13 % larger (benchmarks/README.md § 3.6).  The
    figure holds no global state: it is freed with its last reference.  Written whole to a
    temporary name beside `path`, then renamed over it: a reader sees the old picture or the
    new one, never a part.  A figure's layout (constrained) is done here at `dpi`, then the
    engine taken off: savefig would otherwise draw the whole figure once, unseen, to lay it
    out before it draws it (the same pixels; the cup's three pictures 0.77 s instead of 0.88)."""
    if fig is None:
        return None
    path = Path(path)
    engine = fig.get_layout_engine()
    if engine is not None and "bbox_inches" not in savefig:
        import matplotlib

        fig.set_dpi(dpi)
        engine.execute(fig)
        with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
            fig.set_layout_engine(None)  # none at all (a matplotlibrc's default engine is not taken)
    savefig.setdefault("format", path.suffix.lstrip(".").lower() or "png")
    if savefig["format"].lower() == "png":
        savefig.setdefault("pil_kwargs", {"compress_level": 1})
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        fig.savefig(tmp, dpi=dpi, **savefig)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def wrapped(text: str, width_in: float, fontsize: float = 12.0) -> str:
    """`text` with each line broken at spaces to fit `width_in` inches at `fontsize` points
    (about 0.55 em a character): a long title over a narrow figure is not cut at its edges."""
    import textwrap

    chars = max(12, int(width_in * 72.0 / (0.55 * fontsize)) - 2)

    def balanced(line: str) -> str:  # as many lines as needed, of about equal length
        lines = textwrap.wrap(line, chars)
        width = -(-len(line) // max(1, len(lines)))
        while len(textwrap.wrap(line, width)) > len(lines):
            width += 1
        return "\n".join(textwrap.wrap(line, width)) or line

    return "\n".join(balanced(line) for line in text.split("\n"))


def title(fig, text: str, fontsize: float = 12.0, **kwargs: Any):
    """fig.suptitle(text), wrapped to the figure's width (see `wrapped`)."""
    return fig.suptitle(wrapped(text, float(fig.get_size_inches()[0]), fontsize), fontsize=fontsize, **kwargs)
