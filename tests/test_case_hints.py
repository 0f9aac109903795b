"""What a person meets before a run (DESIGN § 13): "did you mean" for a misspelt key or word,
pre-run warnings of a built case (case.preflight), and the picture of `check --plot`."""

import re
import tomllib

import pytest

from axiform.case.schema import CaseError, parse


PLATE = """
[mesh]
kind = "rectangle"
r = [0.0, 7.5]
z = [0.0, 0.5]
divisions = [10, 2]
element = "q4"
[material]
model = "mooney-rivlin"
C1 = 80.0
C2 = 20.0
kappa = 1.0e4
[[fix]]
at = { r = 7.5 }
dofs = ["ur", "uz"]
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 0.0 }
value = 1.0
[solver]
steps = 10
"""


def refused(text: str) -> str:
    with pytest.raises(CaseError) as exc:
        parse(tomllib.loads(text))
    return str(exc.value)


@pytest.mark.parametrize("old, new, message", [
    ("steps = 10", "stesp = 10", 'solver.stesp: unknown key; did you mean "steps"?'),
    ("kappa = 1.0e4", "kapa = 1.0e4", 'material.kapa: unknown key; did you mean "kappa"?'),
    ("[solver]", "[solvr]", 'solvr: unknown key; did you mean "solver"?'),
    ("[[pressure]]", "[[presure]]", 'presure: unknown key; did you mean "pressure"?'),
    ("on = { z = 0.0 }", "on = { zz = 0.0 }", 'pressure[0].on.zz: unknown key; did you mean "z"?'),
    ('dofs = ["ur"]\n', 'dofs = ["ur"]\ncurv = [[0.0, 0.0], [1.0, 1.0]]\n',
     'fix[1].curv: unknown key; did you mean "curve"?'),
    ('"mooney-rivlin"', '"mooney-rivlen"', 'material.model: Input should be .*; did you mean "mooney-rivlin"?'),
    ("steps = 10", 'steps = 10\ncontrol = "arclength"', 'solver.control: .*; did you mean "arc-length"?'),
    ('element = "q4"', 'element = "Q4"', 'mesh.element: .*; did you mean "q4"?'),
])
def test_a_misspelt_key_or_word_gets_the_nearest_valid_one(old, new, message):
    assert re.search(re.escape(message).replace(r"\.\*", ".*"), refused(PLATE.replace(old, new)))


def test_no_guess_where_nothing_is_close():
    message = refused(PLATE.replace("steps = 10", "steps = 10\nxyzzy = 1"))
    assert "solver.xyzzy: unknown key" in message
    assert "did you mean" not in message


def test_a_union_of_tables_offers_the_keys_of_its_members():
    text = PLATE + """
[[contact]]
surface = { profile = { start = [0.0, 1.0], pieces = [{ lin = { to = [8.0, 1.0] } }] } }
slaves = { z = 0.5 }
"""
    assert 'contact[0].surface.profile.pieces[0].lin: unknown key; did you mean "line"?' in refused(text)
