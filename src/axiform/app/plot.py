"""`axiform plot DIR [--field F] [--animate]`: (re)write the PNG plots of a results folder."""

from __future__ import annotations

from pathlib import Path

from .console import failed, say


def fields_of(folder: Path) -> set[str] | None:
    """The nodal fields of the last VTU file of a results folder (None: no VTU file)."""
    from xml.etree import ElementTree as ET

    from ..post.plots import last_vtu

    vtu = last_vtu(folder)
    if vtu is None or not vtu.exists():
        return None
    return {
        name
        for a in ET.parse(vtu).getroot().iter("DataArray")
        if (name := a.get("Name")) and name not in ("types", "offsets", "connectivity", "Points")
    }


def plot(folder: str, field: str | None = None, animate: bool = False) -> int:
    """(Re)write the PNG plots of a results folder, deformed.png coloured by `field` (None:
    von_mises); returns the exit code."""
    from ..case.suggest import nearest
    from ..post.plots import FieldError, plot_folder, read_history
    from ..post.results_folder import FolderInfo, UnreadableResults
    from .run import writable

    path = Path(folder)
    try:
        there = (path / "history.csv").is_file()
    except OSError as exc:  # a name longer than the file system allows
        say(f"axiform: {folder}: {exc.strerror or exc}")
        return 2
    if not there:
        say(f"axiform: {folder} is not a results folder (no history.csv)")
        return 2
    try:
        read_history(path / "history.csv")
        FolderInfo.read(path)
        fields = fields_of(path)
    except (OSError, ValueError, KeyError, IndexError, SyntaxError) as exc:  # SyntaxError: XML
        say(f"axiform: {folder}: unreadable results ({type(exc).__name__}: {exc})")
        return 2
    if field is not None and fields is None:
        say(f"axiform: --field: {folder} has no VTU files (its run had output.vtu = false): no shape to colour")
        return 2
    field = field or "von_mises"
    if fields is not None and field.split(":")[0] not in fields:
        guess = nearest(field.split(":")[0], sorted(fields))
        hint = f'; did you mean "{guess}"?' if guess else ""
        say(f"axiform: --field: no field '{field}' in {folder}; there are: {', '.join(sorted(fields))}{hint}")
        return 2
    problem = writable(path)
    if problem:
        say(f"axiform: {problem}")
        return 2
    try:
        pngs = plot_folder(path, field, animate)
    except FieldError as exc:
        say(f"axiform: --field: {exc}")
        return 2
    except UnreadableResults as exc:
        say(f"axiform: {folder}: unreadable results ({exc})")
        return 2
    except OSError as exc:  # the folder turned read-only, or the disk is full
        say(f"axiform: cannot write the plots in {folder} ({exc.strerror or exc})")
        return 2
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's: exit 3
        return failed(exc, f"failed while plotting {folder}")
    for png in pngs:
        print(png)
    return 0
