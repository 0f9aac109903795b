"""`axiform check CASE.toml [--plot [PNG]]`: validate a case and build its model, without
solving.  Its verdict on stdout, then each pre-run warning of case.preflight on stderr
(`warning: <line>`: valid, but probably not what was meant; the exit code stays 0); with
--plot, the picture of what the case sets up (post/check_plot.py), in the current folder
unless a path is given, and where it went on stdout."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .console import failed, invalid, say, tell, warn


def check(case_path: str, overrides: Sequence[str] = (), plot: str | None = None) -> int:
    """Validate a case and build its model, without solving; returns the exit code (0 valid,
    2 invalid, 3 an unexpected error).  plot: the PNG to draw the case in, or None."""
    from ..case.preflight import preflight
    from ..case.schema import CaseError, build, parse, read

    case_file = Path(case_path)
    png = None
    if plot is not None:
        from ..post.check_plot import png_path

        try:
            png = png_path(plot, case_file)
        except (ValueError, OSError) as exc:
            say(f"axiform: --plot: {exc}")
            return 2
    try:
        built = build(parse(read(case_file, list(overrides))), case_file.parent)
    except CaseError as exc:
        return invalid(case_file, exc)
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's, not of the case: exit 3
        return failed(exc, f"failed while building the model of {case_file}")
    m = built.model
    tell(
        f"{case_file}: valid; {m.mesh.n_cells} {m.mesh.element.name} elements, {m.mesh.n_nodes} nodes, "
        f"{m.n_free} free dofs"
    )
    warn(*preflight(built))
    if png is not None:
        from ..post.check_plot import plot_check

        try:
            png.parent.mkdir(parents=True, exist_ok=True)
            written = plot_check(built, png)
        except OSError as exc:
            say(f"axiform: --plot: cannot write {png} ({exc.strerror or exc})")
            return 2
        except Exception as exc:  # noqa: BLE001 - a fault of axiform's: exit 3
            return failed(exc, f"failed while drawing {png}")
        tell(f"wrote {written}")
    return 0
