"""`axiform run CASE.toml [--out DIR]`, `axiform check CASE.toml [--plot [PNG]]`, `axiform plot
DIR`, `axiform fit DATA.csv --model MODEL` (app/fit.py; prony and wlf: app/fit_viscoelastic.py),
`axiform optimize CASE.toml --target T.csv --out DIR` (app/optimize.py, design/), `axiform sweep
SWEEP.toml --out DIR` (app/sweep.py).

Exit codes: 0 finished, 1 stopped (converged steps kept), 2 invalid case (refused before any
work), 3 failed (an unexpected error), 130 / 143 interrupted by SIGINT / SIGTERM.

Streams: what a command produces (progress, the status line, check's verdict) goes to stdout,
warnings and errors to stderr; a closed reader (`axiform run CASE | head -3`) stops neither the
command nor its files, and its exit code stays its own (app/console.guarded_streams).

This module parses the arguments and calls the command's function in axiform.app (app/run.py,
app/check.py, app/plot.py, ...).  The modules behind the commands (NumPy, SciPy, pydantic,
matplotlib, meshio, Dask) are imported by the command that needs them: `import axiform.cli`
itself stays light.
"""

from __future__ import annotations

import argparse
import sys

from . import __version__

VISCOELASTIC_FITS = ("prony", "wlf")  # `fit --model` beyond the hyperelastic laws (app/fit_viscoelastic.py)
NETWORK_FIT = "network"  # `fit --model network` (app/fit_network.py)
DESCRIPTION = (
    "Large-strain axisymmetric hyperelastic solids by finite elements: blow moulding, "
    "thermoforming and rubber parts, described in TOML case files."
)


def build_parser() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The parser of the `axiform` command, and its `fit` sub-parser (whose --model is checked after)."""
    parser = argparse.ArgumentParser(
        prog="axiform",
        description=DESCRIPTION,
        epilog="exit codes: 0 finished, 1 stopped short, 2 invalid input, 3 failed, "
        "130 / 143 interrupted (SIGINT / SIGTERM). Progress and status lines "
        "go to stdout, warnings and errors to stderr.",
    )
    parser.add_argument("--version", action="version", version=f"axiform {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    _run_and_check(sub)
    p_fit = _plot_and_fit(sub)
    _optimize_and_sweep(sub)
    return parser, p_fit


def _run_and_check(sub) -> None:
    """The `run` and `check` sub-parsers."""
    p_run = sub.add_parser(
        "run",
        help="run a case file and write its results folder",
        description="Run a case file and write its results folder as the steps converge.",
    )
    p_run.add_argument("case", help="the case file (TOML)")
    p_run.add_argument(
        "--out",
        help="results folder (default: results/<case name>, or results/<case name>-<n> "
        "when that one holds another case's results)",
    )
    p_run.add_argument("-q", "--quiet", action="store_true", help="print only one line: the final status")
    p_run.add_argument(
        "--resume",
        metavar="DIR",
        help="continue the run in results folder DIR from its last checkpoint (restart/); "
        "the physics of the run ([mesh], [material], [temperature], [thermal], [[convection]], "
        "[[contact]], the loads so far) must be unchanged; a later target or more output may be set",
    )
    p_check = sub.add_parser(
        "check",
        help="validate a case file and build its model, without solving",
        description="Validate a case file and build its model, without solving: exit 0 "
        "if valid (with a warning on stderr for what is valid but probably "
        "not meant), 2 with the key path and the reason if not.",
    )
    p_check.add_argument("case", help="the case file (TOML)")
    p_check.add_argument(
        "--plot",
        nargs="?",
        const="check.png",
        metavar="PNG",
        help="also draw what the case sets up (mesh, supports, loads, moulds and their "
        "normals) in PNG (default: check.png in the current folder)",
    )
    for p in (p_run, p_check):
        p.add_argument(
            "--set",
            action="append",
            default=[],
            metavar="KEY=VALUE",
            help="override a key, VALUE in TOML syntax: --set mesh.element='\"q8\"' "
            "--set mesh.divisions=[40,4] --set contact[1].friction=0.0 (repeatable)",
        )


def _plot_and_fit(sub) -> argparse.ArgumentParser:
    """The `plot` and `fit` sub-parsers; returns `fit`'s."""
    p_plot = sub.add_parser(
        "plot",
        help="write the PNG plots of a results folder",
        description="(Re)write the PNG plots of a results folder: load_curve.png, thickness.png, deformed.png.",
    )
    p_plot.add_argument("folder", help="a results folder written by `axiform run`")
    p_plot.add_argument(
        "--field",
        help="nodal field colouring the deformed shape (default von_mises; J, thickness, ...; "
        "a component as cauchy_stress:zz or displacement:uz; vectors and tensors "
        "alone: their magnitude)",
    )
    p_plot.add_argument(
        "--animate",
        action="store_true",
        help="also write forming.gif: the deformed wall, moulds and thickness, one frame per written step",
    )
    p_fit = sub.add_parser(
        "fit",
        help="fit a hyperelastic law to test data, a Prony series to relaxation or "
        "DMA data, WLF constants to shift factors, viscous networks to curves at several rates",
        description="Fit the constants of a hyperelastic law to uniaxial, equibiaxial and "
        "planar (pure shear) test data by least squares on the relative errors, "
        "and check the law's Drucker stability at stretches 0.1 to 10; or a "
        "Prony series (--model prony) to a relaxation modulus or DMA data; or "
        "the WLF constants (--model wlf) to shift factors; or an equilibrium law and "
        "viscous networks (--model network) to stress-stretch curves at constant stretch rates. "
        "Writes material.toml (the case-file table), fit.json and the plots fit_<mode>.png, "
        "fit_prony.png, fit_wlf.png or fit_network_<mode>.png.",
        epilog="exit codes: 0 fitted, 1 no admissible constants, 2 a bad data file or argument",
    )
    p_fit.add_argument(
        "data",
        nargs="+",
        help="CSV files with the header mode,stretch,stress (one file with "
        "time,modulus or frequency,storage,loss for prony, "
        "temperature,log10_shift for wlf, mode,rate,stretch,stress[,temperature] for network)",
    )
    p_fit.add_argument(
        "--model",
        required=True,
        action=_LawChoice,
    )
    p_fit.add_argument(
        "--terms",
        type=int,
        help="Ogden: number of terms, 1 to 6 (default 3); prony: 1 to 8 (default one per decade of the data)",
    )
    p_fit.add_argument("--out", help="output folder (default: results/fit-<model>)")
    p_fit.add_argument("--kappa", type=float, help="bulk modulus written (default: 1000 x the initial shear modulus)")
    p_fit.add_argument(
        "--reference",
        type=float,
        help="wlf: the reference temperature T_ref (default: where the data's log10_shift is 0); "
        "network: T_ref of the fitted shift (default: the middle temperature of the data)",
    )
    p_fit.add_argument(
        "--law", help="network: the equilibrium network's law (default neo-hooke; any law --model takes)"
    )
    p_fit.add_argument("--networks", type=int, help="network: the number of viscous networks, 1 to 4 (default 1)")
    p_fit.add_argument(
        "--E", dest="flow_E", type=float, help="network: the flow's stretch offset E, fixed (default 0.01)"
    )
    return p_fit


def _optimize_and_sweep(sub) -> None:
    """The `optimize` and `sweep` sub-parsers."""
    p_opt = sub.add_parser(
        "optimize",
        help="program a parison / preform: the thickness table that gives a target final wall",
        description="Find the mesh.thickness table of a layered case whose final wall meets "
        "a target thickness; writes optimized.toml, optimize.csv, "
        "optimize.json, optimize.png and final/ (the results of the optimized case).",
        epilog="exit codes: 0 the tolerance was reached, 1 stopped short, 2 invalid input",
    )
    p_opt.add_argument("case", help="the case file (TOML): a layered mesh with a thickness table, load control")
    p_opt.add_argument(
        "--target",
        required=True,
        help="CSV with the header s,thickness: the wanted final thickness against the reference arc length s",
    )
    p_opt.add_argument("--out", required=True, help="output folder")
    p_opt.add_argument("--max-iter", type=int, default=20, help="most iterations (default 20)")
    p_opt.add_argument(
        "--method",
        choices=["gradient", "fixed-point"],
        default="gradient",
        help="gradient: least squares with direct-differentiation gradients (default); "
        "fixed-point: scale each station by target / achieved",
    )
    p_opt.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        help="stop when the max relative deviation from the target is below this (default 0.01)",
    )
    p_opt.add_argument(
        "--smoothness", type=float, default=1e-4, help="weight of the smoothness term on the design (default 1e-4)"
    )
    p_opt.add_argument(
        "--vary",
        choices=["thickness", "temperature"],
        default="thickness",
        help="thickness: the mesh.thickness table (parison programming, default); temperature: the "
        "[temperature] initial table (temperature programming)",
    )
    p_opt.add_argument(
        "--bounds",
        metavar="LOW,HIGH",
        default=None,
        help="--vary temperature: the bounds of every temperature (default: the table's range +- 30 K)",
    )
    p_opt.add_argument("-q", "--quiet", action="store_true", help="print only one line: the final status")
    p_sweep = sub.add_parser(
        "sweep",
        help="run variants of a case on a Dask cluster: sweep.csv, sweep.png",
        description="Run the cases of a sweep file ([vary]: full factorial, or [[cases]]) "
        "on a Dask cluster, each in OUT/cases/NNNN/; OUT/sweep.csv, OUT/sweep.png. "
        "Exit 0 when every case finished, 1 when some did not, 2 for an invalid "
        "sweep file.",
    )
    p_sweep.add_argument("sweep", help="the sweep file (TOML): case, [vary] or [[cases]], [report]")
    p_sweep.add_argument("--out", required=True, help="the sweep folder: cases/NNNN/, sweep.csv, sweep.png")
    p_sweep.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    p_sweep.add_argument("--workers", type=int, help="worker processes of the LocalCluster (default: the cores)")
    p_sweep.add_argument("-q", "--quiet", action="store_true", help="print only one line: the final status")


def dispatch(args: argparse.Namespace) -> int:
    """Run the parsed command; returns its exit code."""
    if args.command == "fit" and args.model == NETWORK_FIT:
        if args.terms is not None:
            print("axiform fit: --terms is for --model ogden or prony, not network", file=sys.stderr)
            return 2
        from .app.fit_network import run as fit_network

        return fit_network(args.data, args.law, args.networks, args.flow_E, args.out, args.kappa, args.reference)
    if args.command == "fit" and (args.law, args.networks, args.flow_E) != (None, None, None):
        print("axiform fit: --law, --networks and --E are for --model network", file=sys.stderr)
        return 2
    if args.command == "fit" and args.model in VISCOELASTIC_FITS:
        from .app.fit_viscoelastic import run as fit_viscoelastic

        return fit_viscoelastic(args.data, args.model, args.terms, args.out, args.kappa, args.reference)
    if args.command == "fit":
        if args.reference is not None:
            print("axiform fit: --reference is for --model wlf", file=sys.stderr)
            return 2
        from .app.fit import run as fit

        return fit(args.data, args.model, args.terms, args.out, args.kappa)
    if args.command == "optimize":
        from .app.optimize import run as optimize

        return optimize(
            args.case,
            args.target,
            args.out,
            args.max_iter,
            args.method,
            args.tolerance,
            args.smoothness,
            args.quiet,
            args.vary,
            args.bounds,
        )
    if args.command == "sweep":
        from .app.sweep import run_sweep

        return run_sweep(args.sweep, args.out, args.scheduler, args.workers, args.quiet)
    if args.command == "plot":
        from .app.plot import plot

        return plot(args.folder, args.field, args.animate)
    if args.command == "run":
        from .app.run import run

        return run(args.case, args.out, args.quiet, args.set, args.resume, stream=sys.stdout)
    from .app.check import check

    return check(args.case, args.set, args.plot)


def _fitted_laws() -> list[str]:
    """The hyperelastic laws `fit --model` takes: those of the registry with a fit family."""
    from .materials import LAWS

    return [name for name, entry in LAWS.items() if entry.fit is not None]


class _LawChoice(argparse.Action):
    """`fit --model`: its help lists the laws of the registry when the help is shown (the
    registry and numpy are not imported to build the parser)."""

    @property
    def help(self) -> str:
        return f"the law: {', '.join(_fitted_laws())}; or {', '.join(VISCOELASTIC_FITS)}, {NETWORK_FIT}"

    @help.setter
    def help(self, value: str | None) -> None:
        """The help is the property's (argparse.Action.__init__ sets it)."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        setattr(namespace, self.dest, values)


def main(argv: list[str] | None = None) -> int:
    """The `axiform` command line; returns the exit code.  stdout and stderr are guarded while
    it runs: a reader that closes them early (`| head`) costs the command nothing."""
    from .app.console import guarded_streams

    with guarded_streams():
        parser, p_fit = build_parser()
        args = parser.parse_args(argv)
        if args.command == "fit":
            choices = (*_fitted_laws(), *VISCOELASTIC_FITS, NETWORK_FIT)
            if args.model not in choices:
                p_fit.error(f"argument --model: invalid choice: {args.model!r} (choose from {', '.join(choices)})")
        try:
            return dispatch(args)
        except KeyboardInterrupt:
            print("axiform: interrupted", file=sys.stderr)
            return 130


def entry() -> None:
    """The `axiform` command: exits with main()'s code."""
    sys.exit(main())


if __name__ == "__main__":
    entry()
