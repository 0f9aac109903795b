"""What a person sees on the console: progress and status on stdout, warnings and errors on
stderr, a reader that closes the pipe early (`| head`) costing the command nothing, the
pre-run warnings of `check` and `run` (and a stop naming them as its likely cause), the
progress line within 80 columns, and the help texts."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from axiform.app.console import COLUMNS, Guarded, ProgressLine, apart, guarded_streams
from axiform.app.run import status_line
from axiform.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
PLATE = EXAMPLES / "hughes_carnoy_plate.toml"  # 40 steps in about a second
BALLOON = EXAMPLES / "balloon.toml"
IN_PA = "pressure[0].value=1.0e5"  # the balloon's pressure in Pa: stops at step 1
RESULTS = ("history.csv", "summary.json", "fields.pvd", "thickness.csv", "load_curve.png", "deformed.png")


def axiform(*args: str, **kw) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.Popen(
        [sys.executable, "-m", "axiform.cli", *args], env=env, stdout=subprocess.PIPE, text=True, **kw
    )


def read_one_line_and_close(proc: subprocess.Popen) -> str:
    """What `| head -1` does: one line, then the pipe closed while the command still writes."""
    line = proc.stdout.readline()
    proc.stdout.close()
    return line


# ---- a closed reader ------------------------------------------------------------------------------
class Closed(io.StringIO):
    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")

    def flush(self):
        raise BrokenPipeError(32, "Broken pipe")


def test_a_guarded_stream_drops_what_a_closed_reader_cannot_take():
    stream = Guarded(Closed())
    assert stream.write("step 1\n") == len("step 1\n") and stream.broken
    stream.flush()
    print("more", file=stream)  # no error, nothing written
    assert not stream.isatty()


def test_a_guarded_pipe_points_its_descriptor_at_devnull():
    r, w = os.pipe()
    os.close(r)  # the reader is gone
    raw = os.fdopen(w, "w")
    stream = Guarded(raw)
    stream.write("x" * 100_000)
    stream.flush()
    assert stream.broken
    raw.write("at exit")  # what the interpreter's last flush does: devnull takes it
    raw.flush()
    raw.close()


def test_other_os_errors_are_not_swallowed():
    class Full(io.StringIO):
        def write(self, text):
            raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        Guarded(Full()).write("x")


def test_the_streams_are_put_back_after_a_command():
    out, err = sys.stdout, sys.stderr
    with guarded_streams():
        assert isinstance(sys.stdout, Guarded) and isinstance(sys.stderr, Guarded)
    assert (sys.stdout, sys.stderr) == (out, err)


@pytest.mark.parametrize("merged", [False, True])  # `axiform run X | head -1`, `... 2>&1 | head -1`
def test_a_run_whose_reader_closes_goes_on_and_writes_everything(tmp_path, merged):
    out = tmp_path / "plate"
    proc = axiform("run", str(PLATE), "--out", str(out), stderr=subprocess.STDOUT if merged else subprocess.PIPE)
    assert read_one_line_and_close(proc).startswith("axiform ")  # the header
    err = "" if merged else proc.stderr.read()
    assert proc.wait(timeout=300) == 0, err
    assert "Traceback" not in err and "BrokenPipe" not in err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "finished" and summary["steps"] == 40
    for name in RESULTS:
        assert (out / name).is_file(), name
    assert len(list((out / "fields").glob("*.vtu"))) == 40


def test_a_stopped_run_whose_reader_closes_keeps_its_own_exit_code(tmp_path):
    out = tmp_path / "balloon"
    proc = axiform("run", str(BALLOON), "--set", IN_PA, "--out", str(out), "-q", stderr=subprocess.PIPE)
    line = read_one_line_and_close(proc)
    err = proc.stderr.read()
    assert proc.wait(timeout=300) == 1
    assert line.startswith("axiform: stopped at step 1 ") and "likely cause: pressure[0].value" in line
    assert err.startswith("warning: pressure[0].value: 100000 MPa would invert elements") and "Traceback" not in err
    assert json.loads((out / "summary.json").read_text())["status"] == "stopped"


def test_fit_whose_reader_closes_writes_its_files(tmp_path):
    out = tmp_path / "fit"
    proc = axiform(
        "fit", str(EXAMPLES / "data" / "treloar.csv"), "--model", "neo-hooke", "--out", str(out), stderr=subprocess.PIPE
    )
    assert read_one_line_and_close(proc).startswith("neo-hooke fitted to")
    err = proc.stderr.read()
    assert proc.wait(timeout=300) == 0 and "Traceback" not in err, err
    for name in ("material.toml", "fit.json", "fit_uniaxial.png"):
        assert (out / name).is_file(), name


def test_help_whose_reader_closes_says_nothing_more():
    proc = axiform("--help", stderr=subprocess.PIPE)
    assert read_one_line_and_close(proc).startswith("usage: axiform")
    err = proc.stderr.read()
    assert proc.wait(timeout=60) == 0 and err == "", err


# ---- which stream says what ------------------------------------------------------------------------
def test_a_run_prints_progress_and_status_on_stdout_and_nothing_on_stderr(tmp_path, capsys):
    assert main(["run", str(PLATE), "--out", str(tmp_path / "plate")]) == 0
    cap = capsys.readouterr()
    lines = cap.out.splitlines()
    assert cap.err == ""
    assert lines[0].startswith("axiform ") and lines[-1].startswith("axiform: finished after 40 steps")
    steps = lines[1:-1]
    assert len(steps) == 40 and steps[0].startswith("step 1  lambda ")  # a plain pressure: lambda
    assert all(len(line) <= COLUMNS for line in steps)


def test_two_steps_a_cut_apart_are_printed_as_two_times():
    """A step cut eight times lands 7.3e-5 after the last one: four digits printed both as
    0.9386; the progress gives the digits that tell them apart, and no more elsewhere."""
    assert apart(0.9386474609375, 0.9385742187499999) == "0.93865"
    assert apart(0.9385742187499999, 0.93828125) == "0.9386"
    assert apart(0.5, None) == "0.5" and apart(0.5, 0.5) == "0.5"
    assert apart(1.0 + 1e-13, 1.0) == "1.0000000000001"


def test_the_load_factor_is_called_t_where_it_is_the_process_time(tmp_path, capsys):
    """The die drawing's punch moves with the process time; an early target keeps it short."""
    main(["run", str(EXAMPLES / "die_drawing.toml"), "--set", "solver.target=0.02", "--out", str(tmp_path / "dd")])
    steps = [line for line in capsys.readouterr().out.splitlines() if line.startswith("step ")]
    assert steps and all(line.split()[2] == "t" and len(line) <= COLUMNS for line in steps), steps


def test_a_stop_names_the_pre_run_warning_first(tmp_path, capsys):
    assert main(["run", str(BALLOON), "--set", IN_PA, "--out", str(tmp_path / "b")]) == 1
    cap = capsys.readouterr()
    (warning,) = cap.err.splitlines()
    assert warning.startswith("warning: pressure[0].value: 100000 MPa would invert elements")
    status = cap.out.splitlines()[-1]
    assert status.startswith("axiform: stopped at step 1 after 0 steps")
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    solver = summary["message"]  # the solver's own: 'step 1: ...', the warnings beside it
    assert solver.startswith("step 1: ")
    assert status.endswith(
        f": likely cause: {warning.removeprefix('warning: ')}; then {solver.removeprefix('step 1: ')}"
    )


def test_quiet_keeps_the_status_line_and_the_warnings(tmp_path, capsys):
    assert main(["run", str(BALLOON), "--set", IN_PA, "--out", str(tmp_path / "b"), "-q"]) == 1
    cap = capsys.readouterr()
    assert len(cap.out.splitlines()) == 1 and cap.out.startswith("axiform: stopped at step 1")
    assert len(cap.err.splitlines()) == 1 and cap.err.startswith("warning: ")


def test_status_line_without_warnings_or_step_is_the_solvers_message():
    out = Path("results/x")
    assert (
        status_line("stopped", "step 3: no convergence", [], 2, 9, 1.0, out)
        == "axiform: stopped after 2 steps, 9 Newton iterations, 1.00 s -> results/x: step 3: no convergence"
    )
    assert status_line("stopped", "the end was not reached in 5 steps", ["a", "b"], 5, 9, 1.0, out).endswith(
        ": likely cause: a; b; then the end was not reached in 5 steps"
    )
    assert status_line("finished", "", ["a"], 5, 9, 1.0, out).endswith("-> results/x")


def test_invalid_case_is_an_error_on_stderr(tmp_path, capsys):
    assert main(["run", str(PLATE), "--set", "solver.steps=0", "--out", str(tmp_path / "p")]) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and "solver.steps" in cap.err


# ---- check -----------------------------------------------------------------------------------------
def test_check_prints_the_warnings_after_valid(capsys):
    assert main(["check", str(BALLOON), "--set", IN_PA]) == 0
    cap = capsys.readouterr()
    assert ": valid; " in cap.out
    assert cap.err.startswith("warning: pressure[0].value: 100000 MPa would invert elements")


def test_check_plot_writes_check_png_in_the_current_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["check", str(BALLOON), "--plot"]) == 0
    cap = capsys.readouterr()
    assert (tmp_path / "check.png").stat().st_size > 1000
    assert cap.out.splitlines()[-1] == "wrote check.png" and cap.err == ""


def test_check_plot_to_a_path(tmp_path, capsys):
    png = tmp_path / "pics" / "balloon.png"
    assert main(["check", str(BALLOON), "--plot", str(png)]) == 0
    assert png.is_file() and capsys.readouterr().out.splitlines()[-1] == f"wrote {png}"


# ---- the progress line on a terminal ---------------------------------------------------------------
class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_the_progress_bar_stays_within_80_columns():
    term = Terminal()
    line = ProgressLine(term, 1.0)
    line.show(0.35, "35.0%  step 12  t 0.35  its 4  1.2 s  " + "punch_travel -2.804  " * 5, "unused")
    line.close()
    drawn = [part for part in term.getvalue().replace("\n", "\r").split("\r") if part.strip()]
    assert drawn and all(len(part) <= COLUMNS for part in drawn), drawn


# ---- help texts ------------------------------------------------------------------------------------
def _helps():
    parser, _ = build_parser()
    yield "axiform", parser.format_help()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name, p in sub.choices.items():
        yield name, p.format_help()


def test_every_help_text_describes_its_command_and_names_nothing_outside_the_repository():
    for name, text in _helps():
        assert "DESIGN" not in text and "§" not in text, name
        body = text.split("\n\n")
        assert len(body) >= 3, f"{name}: no description"  # usage, description, arguments
    top = dict(_helps())["axiform"].split("\n\n")[1]
    assert top.rstrip().endswith(".") and "`" not in top
    assert "Fit the constants" in dict(_helps())["fit"]
