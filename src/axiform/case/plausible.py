"""Pre-run warnings of a built case about its units (case.preflight runs them): numbers that
are valid but probably typed in another unit than the rest of the case.

- a table of T (a constant of the law, the frozen network's G_f, a heat property) whose
  temperatures lie wholly outside every temperature the case can reach (the initial field,
  and with heat conduction the moulds' and films' temperatures x their curves): only its end
  value is ever used, a sign of a kelvin / Celsius mix-up (a table at 110 to 150 in a case
  at 423);
- a shear modulus above MAX_MPA_MODULUS in a case whose [units] pressure is MPa (a modulus
  in Pa: 1e6 times too stiff).

Each warning is one line that begins with the table and key at fault.
"""

from __future__ import annotations

import numpy as np

# the stiffest shear modulus a hyperelastic law of axiform's stands for in MPa: a glassy polymer's
# is about 1e3, a rubber's 0.1 to 10, a polymer melt's below 1
MAX_MPA_MODULUS = 1.0e4
MPA = ("MPa", "N/mm^2", "N/mm2", "N/mm²")


def reachable_range(built) -> tuple[float, float] | None:
    """The lowest and highest temperature the case can reach (the initial field plus its
    prescribed change, and with [thermal] the moulds' and films' temperatures x their curves),
    None without [temperature]."""
    T = built.model.temperature
    if T is None:
        return None
    from .temperature import boundary_temperatures, change_values

    values = [float(T.min()), float(T.max())]
    if built.case.thermal is not None:
        values += [v for _, v, _ in boundary_temperatures(built.case)]
    for dT, _ in change_values(built.case):
        values += [float(T.min()) + dT, float(T.max()) + dT]
    return min(values), max(values)


def _tables(case):
    """(key, T knots) of every table of T of the case: the law's constants, its frozen
    network's G_f(T), the heat properties."""
    for name, table in case.material.tables().items():
        yield f"material.{name}", np.asarray(table.T)
    if case.material.freeze is not None:
        yield "material.freeze.modulus", np.array([row[0] for row in case.material.freeze.modulus], float)
    if case.thermal is not None:
        for name in ("conductivity", "density", "specific_heat"):
            value = getattr(case.thermal, name)
            if isinstance(value, list):
                yield f"thermal.{name}", np.array([row[0] for row in value], float)


def tables_out_of_reach(built) -> list[str]:
    """Tables of T whose temperatures lie wholly outside those the case reaches."""
    reach = reachable_range(built)
    if reach is None:
        return []
    low, high = reach
    unit = built.case.units.temperature or ""
    out = []
    for key, T in _tables(built.case):
        if T.max() < low or T.min() > high:
            out.append(
                f"{key}: the table's temperatures ({T.min():g} to {T.max():g}{unit and ' ' + unit}) lie outside "
                f"every temperature the case reaches ({low:g} to {high:g}): only its "
                f"{'last' if T.max() < low else 'first'} value is used; are they in the case's temperature unit "
                f"(kelvin and Celsius mixed)?"
            )
    return out


def modulus_units(built) -> list[str]:
    """A shear modulus above MAX_MPA_MODULUS in a case whose [units] pressure is MPa."""
    if built.case.units.pressure not in MPA:
        return []
    mu = float(getattr(built.model.material, "shear_modulus", 0.0))
    if not mu > MAX_MPA_MODULUS:
        return []
    return [
        f"material: a shear modulus of {mu:.3g} MPa is above {MAX_MPA_MODULUS:g} MPa (a glassy polymer's is "
        f'about 1e3, a rubber\'s 0.1 to 10): is it in Pa ([units] pressure = "{built.case.units.pressure}")?'
    ]
