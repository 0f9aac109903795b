"""The interface every law offers (materials.protocol): an elastic law through the adapter
gives its own stress and tangent, no state, its constants at the points' temperatures."""

import numpy as np

from axiform import MooneyRivlin, NeoHooke
from axiform.materials.protocol import Elastic, StatefulLaw
from axiform.materials.temperature import Table, TemperatureDependent

X = np.array([[1.2, 0.1, -0.05, 0.9, 1.1], [0.8, -0.2, 0.15, 1.3, 0.95]])


def test_an_elastic_law_through_the_adapter_is_the_law():
    law = MooneyRivlin(0.4, 0.1, 100.0)
    adapted = Elastic(law)
    assert isinstance(adapted, StatefulLaw)
    assert adapted.initial_state((3, 4)) == {}
    P, A, trial = adapted.update(X, {}, 0.1, None)
    P0, A0 = law.stress_tangent(X)
    assert trial == {}
    np.testing.assert_array_equal(P, P0)
    np.testing.assert_array_equal(A, A0)
    P_iso, A_iso, _ = adapted.update(X, {}, 0.1, None, volumetric=False)
    np.testing.assert_array_equal(P_iso, law.iso_stress(X))
    np.testing.assert_array_equal(A_iso, law.iso_stress_tangent(X)[1])


def test_the_adapter_takes_the_constants_at_each_points_temperature():
    law = TemperatureDependent(
        lambda k: NeoHooke(k["C1"], k["kappa"]), {"C1": Table((100.0, 200.0), (1.0, 0.5))}, {"kappa": 50.0}, 150.0
    )
    T = np.array([100.0, 200.0])
    P, _, _ = Elastic(law).update(X, {}, 0.0, T)
    for k in range(2):
        np.testing.assert_allclose(P[k], NeoHooke(1.0 - 0.5 * k, 50.0).stress(X[k]), rtol=1e-14)
