"""The shape of the package, read from its source with `ast` (nothing is imported): no import
cycle between modules (imports under TYPE_CHECKING and inside functions count), no import
from a package to a package above it in LAYERS (the order axiform/__init__.py states), no
module over MAX_MODULE_LINES lines, no function over MAX_FUNCTION_LINES, no private name
(a leading underscore) imported from another module; the benchmarks' scripts under
MAX_BENCHMARK_LINES lines together."""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "axiform"

# lowest first: a package imports only from its own layer and those before it.  "axiform" is
# the package's __init__ (its public names are imported on first use, never at import time).
LAYERS = ("axiform", "materials", "fem", "contact", "model", "solve", "post", "io", "case", "design", "app", "cli")
MAX_MODULE_LINES = 450
MAX_FUNCTION_LINES = 80
BENCHMARKS = SRC.parent / "benchmarks"
MAX_BENCHMARK_LINES = 4000  # the speed studies' Python, all together (a study run once goes to git history)


def modules() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its own name)."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


@cache
def tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def imports(name: str, path: Path) -> list[tuple[str, list[str], int]]:
    """(module imported, names taken from it, line) of every import of a module of the
    package, wherever it stands (top level, TYPE_CHECKING, inside a function)."""
    known = modules()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(tree(path)):
        if isinstance(node, ast.Import):
            out += [(a.name, [], node.lineno) for a in node.names if a.name.split(".")[0] == "axiform"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "axiform":
                continue
            names = [a.name for a in node.names]
            submodules = [f"{target}.{n}" for n in names if f"{target}.{n}" in known]
            out += [(m, [], node.lineno) for m in submodules]
            rest = [n for n in names if f"{target}.{n}" not in known]
            if rest or not submodules:
                out.append((target, rest, node.lineno))
    return out


def graph() -> dict[str, set[str]]:
    return {name: {m for m, _, _ in imports(name, path)} - {name} for name, path in modules().items()}


def layer(module: str) -> int:
    parts = module.split(".")
    return LAYERS.index(parts[1] if len(parts) > 1 else parts[0])


def test_no_import_cycle():
    g = graph()
    state: dict[str, int] = {}  # 1 on the path, 2 done
    cycles = []

    def visit(m: str, path: list[str]) -> None:
        state[m] = 1
        for n in sorted(g.get(m, ())):
            if state.get(n) == 1:
                cycles.append(" -> ".join(path[path.index(n) :] + [m, n]) if n in path else f"{m} -> {n}")
            elif n not in state:
                visit(n, [*path, m])
        state[m] = 2

    for m in sorted(g):
        if m not in state:
            visit(m, [])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_packages_import_only_their_own_layer_and_below():
    wrong = [
        f"{path.relative_to(SRC)}:{line}: {name} imports {target}"
        for name, path in modules().items()
        for target, _, line in imports(name, path)
        if layer(target) > layer(name)
    ]
    assert not wrong, f"imports against the layers {' < '.join(LAYERS)}:\n" + "\n".join(wrong)


def test_layers_are_the_ones_the_package_states():
    """LAYERS is the order axiform/__init__.py's docstring gives, and names every package."""
    doc = ast.get_docstring(tree(PACKAGE / "__init__.py")) or ""
    assert " < ".join(LAYERS[1:]) in " ".join(doc.split())
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()} | {"cli"}
    assert packages == set(LAYERS[1:])


def test_no_module_over_the_line_limit():
    long = {
        f"{path.relative_to(SRC)}": n
        for path in modules().values()
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES
    }
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"


def test_the_benchmarks_stay_under_their_line_budget():
    lines = {path.name: len(path.read_text(encoding="utf-8").splitlines()) for path in BENCHMARKS.glob("*.py")}
    assert lines, "the benchmarks' scripts are where this test looks for them"
    assert sum(lines.values()) < MAX_BENCHMARK_LINES, f"benchmarks/*.py: {sum(lines.values())} lines: {lines}"


def long_functions() -> dict[str, int]:
    out = {}
    for path in modules().values():
        for node in ast.walk(tree(path)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    out[f"{path.relative_to(SRC)}:{node.name}"] = n
    return out


def test_no_function_over_the_line_limit():
    long = long_functions()
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines: {long}"


def test_no_private_name_is_imported_from_another_module():
    private = [
        f"{path.relative_to(SRC)}:{line}: {n} from {target}"
        for name, path in modules().items()
        for target, names, line in imports(name, path)
        for n in names
        if n.startswith("_") and not (n.startswith("__") and n.endswith("__")) and target != name
    ]
    assert not private, "private names imported across modules:\n" + "\n".join(private)


def test_the_checks_see_what_they_look_for(tmp_path):
    """The import reader resolves relative imports, submodules taken by `from . import`, and
    imports under TYPE_CHECKING and inside functions."""
    found = {m for m, _, _ in imports("axiform.app.optimize", PACKAGE / "app" / "optimize.py")}
    assert {"axiform.design.optimize", "axiform.io.files", "axiform.app.run", "axiform.case.schema"} <= found
    found = {m for m, _, _ in imports("axiform.io.results", PACKAGE / "io" / "results.py")}
    assert {"axiform.io.gid", "axiform.post.plots"} <= found
    assert layer("axiform.post.plots") < layer("axiform.io.results") < layer("axiform.app.run")


def test_nothing_cites_a_document_outside_the_repository():
    """The code, tests, scripts and documents speak of the repository alone: no design notes
    or shared folders of the developers."""
    root = Path(__file__).resolve().parents[1]
    folders = ("src", "tests", "validation", "benchmarks", "docs", "examples")
    files = [p for f in folders for p in (root / f).rglob("*") if p.suffix in {".py", ".md", ".toml"}]
    files += [root / "README.md", root / "CHANGELOG.md"]
    marks = ("DESIGN" + ".md", "DESIGN" + " §", "../" + "shared")
    offenders = [str(p.relative_to(root)) for p in files if any(m in p.read_text(errors="ignore") for m in marks)]
    assert not offenders, offenders
