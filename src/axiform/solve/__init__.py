"""Path following: controls, Newton, arc length, the linear solvers.

`axiform.solve(model, control)` is both this package and the function that runs a model
(`solve.solver.solve`): the package is callable, so that the public name kept its meaning
when the solver moved into a package of its own.
"""

import sys
from types import ModuleType


class _CallablePackage(ModuleType):
    def __call__(self, *args, **kwargs):
        from .solver import solve

        return solve(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
