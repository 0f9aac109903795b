"""`axiform check CASE.toml`: validate a case and build its model, without solving."""

from __future__ import annotations

from pathlib import Path

from .console import failed, invalid


def check(case_path: str, overrides: list[str] = ()) -> int:
    """Validate a case and build its model, without solving; returns the exit code (0 valid,
    2 invalid, 3 an unexpected error)."""
    from ..case.schema import CaseError, build, parse, read

    case_file = Path(case_path)
    try:
        built = build(parse(read(case_file, overrides)), case_file.parent)
    except CaseError as exc:
        return invalid(case_file, exc)
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's, not of the case: exit 3
        return failed(exc, f"failed while building the model of {case_file}")
    m = built.model
    print(f"{case_file}: valid; {m.mesh.n_cells} {m.mesh.element.name} elements, {m.mesh.n_nodes} nodes, "
          f"{m.n_free} free dofs")
    return 0
