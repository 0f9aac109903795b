"""The commands behind the CLI: run, sweep, fit, optimize and its sensitivities."""
