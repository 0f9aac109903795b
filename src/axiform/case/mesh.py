"""The [mesh] table of the case file: a rectangle, a gmsh file or a layered wall along a profile
of lines and arcs, with its element and formulation; and the mesh it makes."""

from __future__ import annotations

import contextlib
import io
import itertools
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import Field, model_validator

from ..fem.mesh import Mesh, MeshError, layered, read_gmsh, rectangle
from ..io.text import check_regular
from .base import CaseError, PositiveFloat, Strict

if TYPE_CHECKING:  # the profile of a layered mesh: imported where a mesh is one
    from ..fem.profile import Arc, Line, Profile


class LinePiece(Strict):
    to: tuple[float, float]
    divisions: Annotated[int, Field(ge=1)]


class ArcPiece(Strict):
    center: tuple[float, float]
    to: tuple[float, float]
    divisions: Annotated[int, Field(ge=1)]
    ccw: bool = True


class PieceSpec(Strict):
    """One piece of a profile: { line = {...} } or { arc = {...} }."""

    line: LinePiece | None = None
    arc: ArcPiece | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.line is None) == (self.arc is None):
            raise ValueError("a profile piece is either { line = ... } or { arc = ... }")
        return self

    def build(self) -> Line | Arc:
        from ..fem.profile import Arc, Line

        if self.line is not None:
            return Line(self.line.to, self.line.divisions)
        assert self.arc is not None, "a piece is a line or an arc (_one)"
        return Arc(self.arc.center, self.arc.to, self.arc.divisions, self.arc.ccw)


_GRID_KEYS = {
    "rectangle": ("r", "z", "divisions"),
    "gmsh": ("file",),
    "layered": ("start", "profile", "thickness", "layers"),
}


class MeshSpec(Strict):
    kind: Literal["rectangle", "gmsh", "layered"] = "rectangle"
    element: Literal["q4", "q8", "sfr"]
    r: tuple[float, float] | None = None
    z: tuple[float, float] | None = None
    divisions: tuple[Annotated[int, Field(ge=1)], Annotated[int, Field(ge=1)]] | None = None
    file: str | None = None
    start: tuple[float, float] | None = None
    profile: Annotated[list[PieceSpec], Field(min_length=1)] | None = None
    thickness: PositiveFloat | Annotated[list[tuple[float, PositiveFloat]], Field(min_length=2)] | None = None
    wall: Literal["r", "z"] | None = None  # rectangle: direction through the wall (thickness)
    grading: tuple[PositiveFloat, PositiveFloat] | None = None  # rectangle: last element / first
    layers: Annotated[int, Field(ge=1)] | None = None
    sfr_edges: Literal["tie", "fix", "free"] = "tie"
    formulation: Literal["mixed", "displacement"] = "mixed"

    @model_validator(mode="after")
    def _kind(self):
        for kind, keys in _GRID_KEYS.items():
            for key in keys:
                given = getattr(self, key) is not None
                if kind == self.kind and not given:
                    raise ValueError(f"a {kind} mesh needs '{key}'")
                if kind != self.kind and given and key not in _GRID_KEYS[self.kind]:
                    raise ValueError(f"'{key}' belongs to kind = \"{kind}\"")
        if self.wall is not None and self.kind != "rectangle":
            raise ValueError("'wall' belongs to kind = \"rectangle\" (a layered wall knows its own)")
        if self.grading is not None and self.kind != "rectangle":
            raise ValueError("'grading' belongs to kind = \"rectangle\"")
        if self.kind == "rectangle":
            if not self.r[0] < self.r[1] or not self.z[0] < self.z[1]:
                raise ValueError("r and z must be given as [min, max] with min < max")
            if self.r[0] < 0:
                raise ValueError("r must be >= 0 (the meridian plane)")
        if self.kind == "layered" and isinstance(self.thickness, list):
            s = [row[0] for row in self.thickness]
            if any(b <= a for a, b in itertools.pairwise(s)):
                raise ValueError("thickness table: arc lengths must increase")
        return self

    def build_profile(self) -> Profile:
        from ..fem.profile import Profile

        assert self.start is not None and self.profile is not None, "a layered mesh has start and profile (_kind)"
        return Profile(self.start, tuple(p.build() for p in self.profile))


# what building a model takes per unknown, measured (4.5 kB a dof for Q8, 2.9 kB for Q4,
# mesh + model + sparse pattern; the solve takes more): a mesh is refused, before anything is
# allocated, when its dofs at this rate would not fit in the machine's memory
BYTES_PER_DOF = 4096


def physical_memory() -> int:
    """Bytes of memory this process may use: the machine's, or its control group's limit where
    that is lower (a container); a large number where the system does not say."""
    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        memory = 1 << 40
    for limit in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            memory = min(memory, int(Path(limit).read_text().strip()))
        except (OSError, ValueError):  # absent, or "max"
            pass
    return memory


def grid_size(spec: MeshSpec) -> tuple[int, int, str] | None:
    """(nodes, dofs, what sets them: 'key: grid') of a rectangle or layered mesh, counted from
    its divisions without building it; None for a gmsh mesh (its file holds what it holds)."""
    if spec.kind == "rectangle":
        assert spec.divisions is not None, "a rectangle mesh has divisions (_kind)"
        na, nb = spec.divisions
        what = f"mesh.divisions: {na} x {nb}"
    elif spec.kind == "layered":
        assert spec.profile is not None and spec.layers is not None, "a layered mesh has profile and layers (_kind)"
        na = sum(p.build().divisions for p in spec.profile)
        nb = spec.layers
        what = f"mesh.layers: {na} profile divisions x {nb} layers of"
    else:
        return None
    nodes = (2 * na + 1) * (2 * nb + 1) - na * nb if spec.element == "q8" else (na + 1) * (nb + 1)
    return nodes, nodes * (3 if spec.element == "sfr" else 2), what


def check_size(spec: MeshSpec, memory: int | None = None) -> None:
    """CaseError naming the divisions when the mesh would not fit in memory."""
    size = grid_size(spec)
    memory = physical_memory() if memory is None else memory
    if size is not None and size[1] * BYTES_PER_DOF > memory:
        nodes, dofs, what = size
        raise CaseError(
            f"{what} {spec.element} elements make {nodes:,} nodes, {dofs:,} dofs, which would need "
            f"about {dofs * BYTES_PER_DOF / 2**30:,.1f} GiB to build (this machine has "
            f"{memory / 2**30:,.1f} GiB): use fewer divisions"
        )


def build_mesh(spec: MeshSpec, base: Path) -> Mesh:
    """The mesh of a [mesh] table; a relative gmsh file is taken from the folder `base`."""
    check_size(spec)
    if spec.kind == "rectangle":
        assert spec.r is not None and spec.z is not None and spec.divisions is not None, (
            "a rectangle mesh has r, z and divisions (_kind)"
        )
        return rectangle(spec.r, spec.z, spec.divisions, spec.element, grading=spec.grading or (1.0, 1.0))
    if spec.kind == "layered":
        from ..fem.profile import ProfileError

        assert spec.layers is not None, "a layered mesh has layers (_kind)"
        try:
            return layered(spec.build_profile(), spec.thickness, spec.layers, spec.element)
        except ProfileError as exc:
            raise CaseError(f"mesh.profile: {exc}") from None
    assert spec.file is not None, "a gmsh mesh has a file (_kind)"
    path = Path(spec.file)
    path = path if path.is_absolute() else base / path
    try:
        if not path.exists():
            raise CaseError(f"mesh.file: no such file {path}")
        if path.is_dir():
            raise CaseError(f"mesh.file: {path} is a folder, not a gmsh file")
        check_regular(path)
    except OSError as exc:  # a name longer than the file system allows, a folder that cannot be read
        raise CaseError(f"mesh.file: cannot read {path} ({exc.strerror or exc})") from None
    said = io.StringIO()  # meshio prints its warnings and errors itself
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            return read_gmsh(path, spec.element)
    except MeshError as exc:
        raise CaseError(f"mesh.file: {exc}") from None
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio raises anything (and calls sys.exit) on bad files
        why = f"{type(exc).__name__}: {exc}" if not isinstance(exc, SystemExit) else said.getvalue().strip()
        raise CaseError(f"mesh.file: cannot read {path} as a gmsh mesh ({' '.join(why.split())})") from None
