#!/usr/bin/env python
"""Write the example data of `axiform fit --model prony|wlf` into examples/data/: synthetic
curves of an amorphous thermoplastic sheet above its glass transition (MPa, s, deg C), drawn
from the classic analytic forms with 1 % noise (0.05 decades on the shifts), seed 1:

- relaxation.csv: a tensile relaxation modulus of the Kohlrausch-Williams-Watts form
  (Williams & Watts, Trans. Faraday Soc. 66 (1970) 80),
  E(t) = E_inf + (E_g - E_inf) exp(-(t / tau)^beta), E_inf = 1.5, E_g = 30, tau = 2, beta = 0.45;
- dma.csv: storage and loss moduli of the Havriliak-Negami form (Havriliak & Negami,
  Polymer 8 (1967) 161), E* = E_inf + (E_g - E_inf) (1 - 1 / (1 + (i w tau)^a)^b),
  w = 2 pi f, the same moduli, tau = 0.3, a = 0.5, b = 0.5;
- wlf_shift.csv: log10 a_T of the "universal" WLF constants C1 = 17.44, C2 = 51.6 K at the
  glass transition (Williams, Landel & Ferry, J. Am. Chem. Soc. 77 (1955) 3701), T_g = 105.

    python examples/make_viscoelastic_data.py
"""

from pathlib import Path

import numpy as np

DATA = Path(__file__).with_name("data")
E_INF, E_G = 1.5, 30.0


def write(path: Path, comment: str, header: str, columns: list[np.ndarray], digits: int = 5) -> None:
    rows = [",".join(f"{v:.{digits}g}" for v in row) for row in zip(*columns, strict=False)]
    path.write_text(
        f"# {comment}\n# written by examples/make_viscoelastic_data.py\n{header}\n" + "\n".join(rows) + "\n"
    )


def main(folder: Path = DATA) -> None:
    rng = np.random.default_rng(1)
    t = np.geomspace(0.01, 1e4, 31)
    E = E_INF + (E_G - E_INF) * np.exp(-((t / 2.0) ** 0.45))
    write(
        folder / "relaxation.csv",
        "synthetic tensile relaxation modulus (MPa) against time (s), KWW form + 1 % noise",
        "time,modulus",
        [t, E * (1 + 0.01 * rng.standard_normal(t.size))],
    )
    f = np.geomspace(0.01, 100.0, 21)
    iwt = 2j * np.pi * f * 0.3
    Es = E_INF + (E_G - E_INF) * (1 - 1 / (1 + iwt**0.5) ** 0.5)
    noise = 1 + 0.01 * rng.standard_normal((2, f.size))
    write(
        folder / "dma.csv",
        "synthetic storage and loss moduli (MPa) against frequency (Hz), Havriliak-Negami form + 1 % noise",
        "frequency,storage,loss",
        [f, Es.real * noise[0], Es.imag * noise[1]],
    )
    T = np.arange(105.0, 166.0, 5.0)
    dT = T - 105.0
    shift = -17.44 * dT / (51.6 + dT) + 0.05 * rng.standard_normal(T.size) * (dT > 0)
    write(
        folder / "wlf_shift.csv",
        "synthetic log10 a_T against temperature (deg C), universal WLF at Tg = 105 + 0.05 decades of noise",
        "temperature,log10_shift",
        [T, shift],
        digits=4,
    )


if __name__ == "__main__":
    main()
