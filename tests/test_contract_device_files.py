"""A device named where a mould's drawing belongs is refused (exit 2) saying what it is, not
that there is no such file."""

from __future__ import annotations

import copy

from test_fuzz import BASE, toml
from test_fuzz_files import call


def test_a_device_as_a_mould_drawing_is_named_as_such(tmp_path):
    """contact.surface.dxf = "/dev/zero": exit 2 saying it is not a regular file (it said
    "no such file /dev/zero")."""
    case = copy.deepcopy(BASE)
    case["contact"] = [{"surface": {"dxf": "/dev/zero"}, "slaves": {"z": 0.2}}]
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["check", str(tmp_path / "case.toml")])
    assert code == 2 and "contact[0].surface.dxf: /dev/zero is not a regular file" in err, err
