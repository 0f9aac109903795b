"""What the numbers of a results folder are, read back for the pictures: the unit of each
quantity from the case's [units] (unit_of, with_unit), the loaded quantity at given load
factors (load_values) and numbers rounded for titles (short).  The results writer puts the
labels of a case (case.labels.case_labels) in summary.json (`units`, `load`,
`monitor_quantities`, `applied`, `process`, `real_time`), so that `axiform plot DIR` labels
every axis from the folder alone; case.labels says what each holds.
"""

from __future__ import annotations

from typing import Any

import numpy as np

QUANTITY_UNIT = {
    "pressure": "pressure",
    "stress": "pressure",
    "force": "force",
    "displacement": "length",
    "length": "length",
    "time": "time",
    "temperature": "temperature",
}  # quantity -> key of [units]


def load_values(load: dict[str, Any], lam: np.ndarray, start: float = 0.0) -> np.ndarray:
    """The loaded quantity v f(lambda) at the load factors lam (a value-scaled load); with
    `start` (a cavity's initial volume V0), start + f(lambda) (v - start)."""
    lam = np.asarray(lam, float)
    curve = load.get("curve")
    if curve is None:
        f = lam
    else:
        t, fk = np.asarray(curve, float).T
        f = np.interp(lam, t, fk)
    return start + f * (load["value"] - start)


def unit_of(quantity: str, units: dict[str, str]) -> str:
    """The unit of a quantity from the case's [units] ("" when not given): area and volume
    are length squared and cubed, a gas content pressure times volume, rotations are in rad."""
    length = units.get("length")
    if quantity == "content":
        return f"{units['pressure']}·{length}³" if length and units.get("pressure") else ""
    if quantity == "area":
        return f"{length}²" if length else ""
    if quantity == "volume":
        return f"{length}³" if length else ""
    if quantity == "rotation":
        return "rad"
    return units.get(QUANTITY_UNIT.get(quantity, ""), "")


def with_unit(label: str, quantity: str, units: dict[str, str]) -> str:
    """'label (unit)', or the label alone when the unit is not known."""
    unit = unit_of(quantity, units)
    return f"{label} ({unit})" if unit else label


def short(value: float) -> str:
    """A number rounded for a title: three significant digits (172, 33.4, 0.0276), an
    exponent only below 1e-3 or from 1e5 on."""
    a = float(f"{abs(value):.3g}")
    if a == 0:
        return "0"
    if a < 1e-3 or a >= 1e5:
        return f"{value:.2e}"
    return f"{value:.{max(0, 2 - int(np.floor(np.log10(a))))}f}"
