"""Design loops over a case: the sensitivities of every converged state to design variables
(sensitivity), the problem of parison and preform programming (problem: the thickness
table, the target wall, the misfit; temperature_design: the initial temperature table) and
its methods (optimize).  The command `axiform optimize` is app.optimize."""
