"""Input fuzzing: Hypothesis writes case files, valid and broken, and runs the command line on
them in-process, with a time bound.  Whatever the input: exit 0, 1 or 2, never a traceback,
never a hang, and every exit 2 names its key path (or the file at fault).

What the cases hold: a small plate (load or displacement control, a monitor, a mould) with
1 to 3 mutations: any key set to a value of a wrong type, NaN, +-inf, a negative, zero or
huge number, a string, a boolean, a list or a table; keys deleted, unknown keys added;
degenerate meshes (zero or negative extent, zero divisions, r < 0); selectors matching no
node or several nodes; moulds with one point, repeated points, crossing polylines, arcs off
their circle, CSV files with text, NaN or one column; gmsh files missing, empty, corrupt,
binary or holding triangles only; TOML that does not parse, binary and non-UTF-8 files.

In the suite: AXIFORM_FUZZ_EXAMPLES cases (default 600, about 8 s), derandomized so the run
is the same each time.  The long run (README): AXIFORM_FUZZ_EXAMPLES=10000 AXIFORM_FUZZ_SEED=
<any> python -m pytest -s tests/test_fuzz.py (prints the exit codes met).
"""

import copy
import io
import json
import math
import os
import re
import signal
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout

import meshio
import numpy as np
import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from axiform.cli import main

EXAMPLES = int(os.environ.get("AXIFORM_FUZZ_EXAMPLES", "600"))
SEED = os.environ.get("AXIFORM_FUZZ_SEED")
TIME_BOUND_S = 30.0
TALLY: Counter = Counter()  # (command, exit code) -> cases, printed at the end (pytest -s)

BASE = {
    "title": "fuzz",
    "mesh": {"kind": "rectangle", "r": [0.0, 2.0], "z": [0.0, 0.2], "divisions": [4, 1], "element": "q4"},
    "material": {"model": "mooney-rivlin", "C1": 80.0, "C2": 20.0, "kappa": 1.0e4},
    "fix": [{"at": {"r": 2.0}, "dofs": ["ur", "uz", "rot"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
    "pressure": [{"on": {"z": 0.0}, "value": 5.0}],
    "monitor": [{"name": "w", "at": {"r": 0.0, "z": 0.2}, "dof": "uz"}],
    "solver": {"control": "load", "steps": 2},
    "output": {"vtu": False, "plots": False},
}
CONTACT = {"surface": {"circle": {"center": [1.0, 1.5], "radius": 1.0}}, "slaves": {"z": 0.2}, "friction": 0.1}


def toml(value, top: bool = True) -> str:
    """A TOML text for a tree of dicts, lists and scalars (every table inline)."""
    if isinstance(value, dict):
        items = [f"{json.dumps(str(k))} = {toml(v, False)}" for k, v in value.items()]
        return "\n".join(items) + "\n" if top else "{ " + ", ".join(items) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(toml(v, False) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, int):
        return str(value)
    return json.dumps(value)


def paths(tree, prefix=()):
    """Every key path of a tree, as tuples of keys and indices."""
    out = []
    items = tree.items() if isinstance(tree, dict) else enumerate(tree) if isinstance(tree, list) else []
    for k, v in items:
        out.append((*prefix, k))
        out += paths(v, (*prefix, k))
    return out


numbers = st.one_of(
    st.sampled_from([0.0, -1.0, 1e-300, 1e300, -1e300, math.nan, math.inf, -math.inf, 2.0, 7.5]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-3, 12),
)
scalars = st.one_of(
    numbers,
    st.booleans(),
    st.text("abcrzuq48 _-.", max_size=6),
    st.sampled_from(
        [
            "q8",
            "sfr",
            "neo-hooke",
            "gmsh",
            "layered",
            "arc-length",
            "displacement",
            "ur",
            "uz",
            "rot",
            "step",
            "load_factor",
            "",
        ]
    ),
)
values = st.one_of(
    scalars,
    st.lists(scalars, max_size=3),
    st.lists(st.lists(numbers, max_size=3), max_size=3),
    st.dictionaries(st.sampled_from(["r", "z", "box", "set", "x", "to"]), scalars, max_size=2),
)

GMSH = {
    "missing.msh": None,
    "empty.msh": "",
    "corrupt.msh": "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 x\n",
    "binary.msh": bytes(range(256)),
    "triangles.msh": "tri",
    "quads.msh": "quad",
    "mixed.msh": "mixed",
    "nan.msh": "nan",
    "x" * 300 + ".msh": None,
}
CSV = {
    "good.csv": "0.0, 1.0\n2.0, 1.2\n",
    "text.csv": "0.0, 1.0\nabc, 2.0\n",
    "nan.csv": "0.0, nan\n1.0, 2.0\n",
    "one.csv": "0.0\n1.0\n",
    "empty.csv": "",
    "repeat.csv": "0.0, 1.0\n0.0, 1.0\n",
    "huge.csv": "0.0, 1e308\n1.0, 2.0\n",
}
polylines = st.lists(st.lists(numbers, min_size=2, max_size=2), min_size=0, max_size=5)


@st.composite
def mutations(draw, case):
    """Change one thing of the case tree in place."""
    kind = draw(st.sampled_from(["set", "set", "set", "delete", "unknown", "mesh", "contact", "selector", "output"]))
    if kind in ("set", "delete"):
        path = draw(st.sampled_from(paths(case)))
        node = case
        for p in path[:-1]:
            node = node[p]
        if kind == "delete" and isinstance(node, dict):
            del node[path[-1]]
        else:
            old = node[path[-1]]
            plausible = (
                st.floats(-3.0, 10.0)
                if isinstance(old, float)
                else st.integers(-1, 6)
                if isinstance(old, int) and not isinstance(old, bool)
                else values
            )
            node[path[-1]] = draw(st.one_of(plausible, values))
    elif kind == "unknown":
        tables = [t for t in (case, case.get("mesh"), case.get("solver")) if isinstance(t, dict)]
        table = draw(st.sampled_from(tables))
        table[draw(st.sampled_from(["extra", "divisons", "Kappa", "value"]))] = draw(scalars)
    elif kind == "mesh":
        choice = draw(st.sampled_from(["gmsh", "degenerate", "layered"]))
        if choice == "gmsh":
            case["mesh"] = {"kind": "gmsh", "file": draw(st.sampled_from(sorted(GMSH))), "element": "q4"}
        elif choice == "degenerate":
            case["mesh"] = copy.deepcopy(BASE["mesh"])
            case["mesh"]["r"] = draw(st.sampled_from([[0.0, 0.0], [-1.0, 1.0], [2.0, 1.0], [0.0, 1e-300]]))
            case["mesh"]["divisions"] = draw(st.sampled_from([[0, 1], [4, 1], [1, -1]]))
        else:
            case["mesh"] = {
                "kind": "layered",
                "element": draw(st.sampled_from(["q4", "q8", "sfr"])),
                "start": [1.0, 0.0],
                "thickness": draw(numbers),
                "layers": draw(st.integers(0, 2)),
                "profile": [
                    {
                        "line": {
                            "to": draw(st.lists(numbers, min_size=2, max_size=2)),
                            "divisions": draw(st.integers(0, 4)),
                        }
                    },
                    {
                        "arc": {
                            "center": [0.0, 0.0],
                            "to": draw(st.lists(numbers, min_size=2, max_size=2)),
                            "divisions": 2,
                        }
                    },
                ],
            }
    elif kind == "contact":
        contact = copy.deepcopy(CONTACT)
        choice = draw(st.sampled_from(["circle", "polyline", "file", "profile"]))
        if choice == "polyline":
            contact["surface"] = {"polyline": draw(polylines)}
        elif choice == "file":
            contact["surface"] = {"file": draw(st.sampled_from(sorted(CSV)))}
        elif choice == "profile":
            contact["surface"] = {
                "profile": {
                    "start": [0.0, 1.0],
                    "pieces": [{"arc": {"center": draw(st.lists(numbers, min_size=2, max_size=2)), "to": [2.0, 1.0]}}],
                }
            }
        else:
            contact["surface"]["circle"]["radius"] = draw(numbers)
        contact[draw(st.sampled_from(["penalty", "friction", "depth", "motion"]))] = draw(
            st.one_of(numbers, st.just({"uz": -0.5}))
        )
        case["contact"] = [contact]
    elif kind == "output":  # a monitor name that would break history.csv, a huge revolved copy or mesh
        choice = draw(st.sampled_from(["name", "revolved", "divisions"]))
        if choice == "name":
            case["monitor"] = copy.deepcopy(BASE["monitor"])
            case["monitor"][0]["name"] = draw(st.sampled_from(["a,b", 'w"', "w\nx", "w;", "w\t", "\x00", "ok name"]))
        elif choice == "revolved":
            case["output"] = dict(copy.deepcopy(BASE["output"]), revolved=draw(st.sampled_from([1, 3600, 3601, 10**9])))
        else:  # deep copies: later mutations change lists in place
            case["mesh"] = dict(
                copy.deepcopy(BASE["mesh"]), divisions=draw(st.sampled_from([[10**5, 10**5], [10**9, 1]]))
            )
    else:  # a selector matching nothing, several nodes or a set that is not there
        sel = draw(st.sampled_from([{"r": 1.234}, {"z": 0.0}, {"set": "nowhere"}, {"box": [[0, 0], [9, 9]]}, {}]))
        where = draw(st.sampled_from(["fix", "pressure", "monitor"]))
        case[where] = copy.deepcopy(BASE[where])
        case[where][0]["on" if where == "pressure" else "at"] = sel


@st.composite
def case_files(draw):
    """(file content as bytes, command) for a fuzzed case."""
    case = copy.deepcopy(BASE)
    if draw(st.booleans()):
        case["solver"] = {
            "control": "displacement",
            "dof": {"at": {"r": 0.0, "z": 0.2}, "dof": "uz"},
            "target": 0.3,
            "steps": 2,
        }
    for _ in range(draw(st.sampled_from([0, 1, 1, 1, 2, 3]))):
        draw(mutations(case))
    text = toml(case).encode()
    spoil = draw(st.sampled_from(["none"] * 27 + ["truncate", "binary", "latin1"]))
    if spoil == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif spoil == "binary":
        text = bytes(draw(st.lists(st.integers(0, 255), max_size=40)))
    elif spoil == "latin1":
        text = b'title = "D\xfcse"\n' + text
    return text, draw(st.sampled_from(["check", "run", "run"]))


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The files the cases may name: gmsh and CSV files, good and bad."""
    d = tmp_path_factory.mktemp("fuzz")
    for name, content in GMSH.items():
        if content in ("tri", "quad", "mixed", "nan"):
            pts = np.array([[0, 0, 0], [2, 0, 0], [2, 0.2, 0], [0, 0.2, 0.0], [3, 0, 0]])
            pts[4, 1] = np.nan if content == "nan" else 0.0
            cells = [("triangle", np.array([[0, 1, 2]]))] if content == "tri" else [("quad", np.array([[0, 1, 2, 3]]))]
            if content in ("mixed", "nan"):
                cells.append(
                    ("triangle", np.array([[1, 4, 2]])) if content == "mixed" else ("quad", np.array([[1, 4, 4, 2]]))
                )
            meshio.write(d / name, meshio.Mesh(pts, cells), file_format="gmsh22")
        elif isinstance(content, bytes):
            (d / name).write_bytes(content)
        elif content is not None:
            (d / name).write_text(content)
    for name, content in CSV.items():
        (d / name).write_text(content)
    return d


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang(f"no answer in {TIME_BOUND_S} s")


KEY = re.compile(r"^(\(case\)|--set [^:]*|--out|[A-Za-z_][\w-]*(\[\d+\])*(\.[A-Za-z_\"][\w\"-]*(\[\d+\])*)*):")


def check_answer(code: int, out: str, err: str, case_path: str) -> None:
    assert code in (0, 1, 2), f"exit {code}:\n{err}"
    assert "Traceback" not in err + out
    if code == 2:
        lines = err.strip().splitlines()
        assert lines, "exit 2 without a message"
        body = lines[1:] if lines[0].startswith(("axiform: invalid case", "axiform: invalid output")) else lines
        for line in body:
            assert KEY.match(line) or line.startswith(case_path), f"no key path in: {line!r}\n{err}"


def fuzz(folder, content: bytes, command: str) -> None:
    case = folder / "case.toml"
    case.write_bytes(content)
    argv = [command, str(case)] + (["--out", str(folder / "out"), "-q"] if command == "run" else [])
    out, err = io.StringIO(), io.StringIO()
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, TIME_BOUND_S)
    try:
        with redirect_stdout(out), redirect_stderr(err):
            code = main(argv)
    except Hang as exc:
        pytest.fail(f"{exc}:\n{content.decode(errors='replace')}")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    check_answer(code, out.getvalue(), err.getvalue(), str(case))
    TALLY[(command, code)] += 1


_settings = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=SEED is None,
    database=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.function_scoped_fixture,
        HealthCheck.data_too_large,
        HealthCheck.filter_too_much,
    ],
)


@_settings
@given(case_files())
def _fuzz_cases(folder, case):
    fuzz(folder, *case)


def test_fuzzed_case_files_never_crash(folder):
    run = seed(int(SEED))(_fuzz_cases) if SEED else _fuzz_cases
    run(folder)
    print(f"\nfuzzed cases by (command, exit code): {dict(sorted(TALLY.items()))}")


def test_the_unmutated_base_case_runs(folder):
    """The base of the fuzzing is a valid case that finishes (so mutations start from sense)."""
    fuzz(folder, toml(BASE).encode(), "run")
    assert json.loads((folder / "out" / "summary.json").read_text())["status"] == "finished"
