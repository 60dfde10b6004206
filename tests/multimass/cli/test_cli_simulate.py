"""The `multimass simulate`, `stability` and `spectrum` commands."""

import json

import numpy as np
import pytest

from multimass.cli import main


def _json(capsys):
    return json.loads(capsys.readouterr().out)


def test_simulate_release_writes_files_and_json(tmp_path, capsys):
    assert (
        main(
            [
                "simulate",
                "S1",
                "--impact",
                "DD2",
                "--release",
                "0.05",
                "--t-end",
                "1.2",
                "--out",
                str(tmp_path),
                "--json",
            ]
        )
        == 0
    )
    info = _json(capsys)
    for key in (
        "status",
        "n_impacts",
        "n_full_contact",
        "theta_max",
        "peaks",
        "energy_balance_error",
        "wall_time_s",
    ):
        assert key in info
    assert info["status"] == "completed" and info["theta_max"] == pytest.approx(0.05)
    for name in (
        "S1_series.csv",
        "S1_events.csv",
        "S1_summary.json",
        "S1_rocking.png",
        "S1_energy.png",
        "S1_accelerations.png",
    ):
        assert (tmp_path / name).is_file(), name


def test_simulate_pulse_and_block(capsys):
    assert (
        main(
            [
                "simulate",
                "S1",
                "--pulse",
                "cosine",
                "--omega",
                "15",
                "--amp",
                "0.4g",
                "--t-end",
                "1.0",
                "--json",
            ]
        )
        == 0
    )
    assert _json(capsys)["options"]["excitation"]["kind"] == "cosine_pulse"
    assert (
        main(
            [
                "simulate",
                "B6M",
                "--release",
                "0.19666",
                "--impact",
                "CIM",
                "--restitution",
                "housner",
                "--t-end",
                "1.0",
                "--json",
            ]
        )
        == 0
    )
    peaks = _json(capsys)["peaks"]
    assert peaks[1] == pytest.approx(0.135551, abs=2e-6)  # exact energy solution, paper 004 Eq 9


def test_simulate_record(ground_motions, capsys):
    assert (
        main(
            [
                "simulate",
                "S1",
                "--record",
                str(ground_motions / "elcentro_1940_NS.dat"),
                "--units",
                "g",
                "--scale",
                "1.1",
                "--t-end",
                "2",
                "--json",
            ]
        )
        == 0
    )
    assert _json(capsys)["status"] == "completed"


def test_simulate_full_contact_flag(ground_motions, capsys):
    argv = ["simulate", "S1", "--record", str(ground_motions / "elcentro_1940_NS.dat")]
    argv += ["--units", "g", "--scale", "1.1", "--t-end", "3", "--json", "--backend", "compiled"]
    runs = {}
    for how in ("exact", "integrate"):
        assert main(argv + ["--full-contact", how]) == 0
        runs[how] = _json(capsys)
    assert runs["exact"]["n_impacts"] == runs["integrate"]["n_impacts"] >= 3
    # both at the default rtol = 1e-8: they differ by the rocking phases' error (3.5e-6 here)
    assert runs["exact"]["theta_max"] == pytest.approx(runs["integrate"]["theta_max"], rel=1e-4)
    assert runs["exact"]["options"]["full_contact"] == "exact"


def test_simulate_method_exponential(ground_motions, capsys):
    argv = ["simulate", "S1", "--record", str(ground_motions / "elcentro_1940_NS.dat")]
    argv += ["--units", "g", "--scale", "1.1", "--t-end", "3", "--json", "--backend", "compiled"]
    runs = {}
    for method in ("DOP853", "exponential"):
        assert main(argv + ["--method", method]) == 0
        runs[method] = _json(capsys)
    assert runs["exponential"]["options"]["method"] == "exponential"
    assert runs["exponential"]["n_impacts"] == runs["DOP853"]["n_impacts"] >= 3
    # both at the default rtol = 1e-8 (DOP853 is the more accurate: its steps are
    # held by stability); they differ by the rocking phases' error
    assert runs["exponential"]["theta_max"] == pytest.approx(runs["DOP853"]["theta_max"], rel=1e-4)
    # without the compiled backend: one clean line that says what to pass
    assert main(["simulate", "S1", "--release", "0.05", "--method", "exponential"]) != 0
    assert "needs backend='compiled'" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["simulate", "S1", "--release", "0.05", "--impact", "XYZ"], "unknown impact model"),
        (
            ["simulate", "S1", "--release", "0.05", "--t-end", "0"],
            "argument --t-end: must be a finite number > 0, got '0'",
        ),
        (["simulate", "S1", "--release", "0.5"], "α_cg"),
        (["simulate", "S1"], "exactly one excitation"),
        (["simulate", "S1", "--pulse", "sine", "--omega", "10", "--amp", "0.4parsecs"], "--amp"),
        (["simulate", "S1", "--record", "x.dat", "--units", "furlongs"], "units"),
        (
            ["simulate", "S1", "--release", "0.05", "--full-contact", "exact"],
            "needs backend='compiled'",
        ),
        (
            ["simulate", "S1", "--pulse", "sine", "--omega", "10", "--amp", "0.4g"]
            + ["--backend", "compiled", "--full-contact", "exact"],
            "not a record or a free release",
        ),
        (["stability", "B6M", "--omega-p", "5:1:4", "--executor", "serial"], "inverted"),
        (["stability", "B6M", "--amp", "1:2:0", "--executor", "serial"], "empty"),
        (
            [
                "stability",
                "B6M",
                "--k",
                "1.4",
                "--executor",
                "serial",
                "--omega-p",
                "1",
                "--amp",
                "1",
            ],
            "argument --k: must be a number in [0, 1], got '1.4'",
        ),
        (["stability", "B99", "--executor", "serial"], "no such bundled specimen"),
        (["stability", "S1", "--executor", "serial"], "column"),
        (
            [
                "spectrum",
                "S1",
                "--pulse",
                "cosine",
                "--omega",
                "-3",
                "--amp",
                "0.4g",
                "--executor",
                "serial",
            ],
            "`--omega` = [-3]: every value must be > 0",
        ),
    ],
)
def test_bad_input_exits_2(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_stability_json_and_files(tmp_path, capsys):
    assert (
        main(
            [
                "stability",
                "B6M",
                "--pulse",
                "sine",
                "--restitution",
                "modified",
                "--omega-p",
                "2:6:3",
                "--amp",
                "0.5:4:4",
                "--refine",
                "1",
                "--integrator",
                "newmark",
                "--executor",
                "serial",
                "--out",
                str(tmp_path),
                "--json",
            ]
        )
        == 0
    )
    info = _json(capsys)
    for key in (
        "block",
        "pulse",
        "restitution",
        "k",
        "omega_p",
        "min_overturn_amp",
        "n_simulations",
        "wall_time_s",
    ):
        assert key in info
    assert info["k"] == 0.8241 and info["omega_p"] == [2.0, 4.0, 6.0]
    assert (tmp_path / "B6M_sine_modified_map.png").is_file()


def test_spectrum_json(capsys, tmp_path):
    assert (
        main(
            [
                "spectrum",
                "S1",
                "--pulse",
                "cosine",
                "--omega",
                "10:20:2",
                "--amp",
                "0.4g",
                "--t-free",
                "1",
                "--executor",
                "serial",
                "--out",
                str(tmp_path),
                "--json",
            ]
        )
        == 0
    )
    info = _json(capsys)
    assert info["n_simulations"] == 2 and len(info["stats"]) == 2
    assert (tmp_path / "S1_spectrum_omega.png").is_file()
    # a column's spectrum chooses its method unless --method names one (S1: not stiff)
    assert info["options"]["method"] == "DOP853"
    assert "not stiff" in info["options"]["method_choice"]["reason"]


# --- what a user sees: one line for a mistake, a status for a doubtful run --------------------


def test_simulate_newmark_from_the_command_line(capsys):
    # README's table documents --integrator newmark; the CLI refused it
    assert (
        main(
            [
                "simulate",
                "B6M",
                "--release",
                "0.19666",
                "--impact",
                "CIM",
                "--restitution",
                "housner",
                "--integrator",
                "newmark",
                "--dt",
                "1e-4",
                "--t-end",
                "1.0",
                "--json",
            ]
        )
        == 0
    )
    info = _json(capsys)
    assert info["options"]["integrator"] == "newmark" and info["status"] == "completed"
    assert info["peaks"][1] == pytest.approx(0.135551, abs=2e-5)  # exact energy solution, Eq 9


def test_inaccurate_run_says_why_and_exits_1(capsys):
    assert (
        main(
            [
                "simulate",
                "B6M",
                "--release",
                "0.19",
                "--impact",
                "CIM",
                "--restitution",
                "housner",
                "--rtol",
                "1e-3",
                "--atol",
                "1e-5",
                "--max-step",
                "inf",
                "--t-end",
                "2.5",
            ]
        )
        == 1
    )
    out = capsys.readouterr().out
    assert "B6M: inaccurate;" in out and "the run completed, but an accuracy check failed" in out
    assert "warning: energy ledger does not close" in out


def test_failed_run_prints_its_reason(capsys, monkeypatch):
    import multimass
    from multimass.response import Response

    real = multimass.simulate

    def failing(*args, **kwargs):
        r = real(*args, **kwargs)
        return Response(
            **{
                **r.__dict__,
                "status": "failed",
                "outcome": "failed",
                "message": "solve_ivp failed at t = 0.1 s: step size too small",
            }
        )

    monkeypatch.setattr(multimass, "simulate", failing)
    assert main(["simulate", "S1", "--release", "0.05", "--t-end", "0.2"]) == 1
    assert "failed: solve_ivp failed at t = 0.1 s: step size too small" in capsys.readouterr().out


def test_implausible_pulse_amplitude_is_one_line_naming_amp(capsys):
    """`--amp 1e300g` is refused before the run in one line naming --amp, its value and
    the fix (it reached the solver, which failed on a non-finite state)."""
    argv = ["simulate", "B6M", "--impact", "CIM", "--pulse", "sine", "--omega", "10"]
    assert main(argv + ["--amp", "1e300g"]) == 2
    err = capsys.readouterr().err
    assert "`--amp` = 9.81e+300 m/s² (1e+300 g)" in err and "0.4g" in err
    assert err.count("\n") == 1


def test_implausible_amplitude_in_a_spectrum_range_is_named(capsys):
    """An amplitude range reaching 1e300 g is refused before any run, naming --amp and
    the implausible value (the range parser kept only its generic format message)."""
    argv = ["spectrum", "S1", "--pulse", "cosine", "--omega", "15", "--executor", "serial"]
    assert main(argv + ["--amp", "0.1g:1e300g:3"]) == 2
    err = capsys.readouterr().err
    assert "`--amp` = 9.81e+300 m/s² (1e+300 g)" in err and err.count("\n") == 1


def test_solver_failure_is_reported_in_text_mode_with_out(tmp_path, capsys, monkeypatch):
    """A run the solver cannot carry ends as "failed" with the solver's message on the
    terminal, also when files go to --out, and exit 1 — not a traceback (solve_ivp's
    failure before its first output sample, whose ``t`` is an empty list, raised an
    AttributeError), nor only "files in DIR/"."""
    from scipy.integrate._ivp.ivp import OdeResult

    import multimass.engines._run

    def fails_at_once(fun, t_span, y0, **kw):
        message = "Required step size is less than spacing between numbers."
        return OdeResult(t=[], y=np.zeros((len(y0), 0)), status=-1, message=message, nfev=7)

    monkeypatch.setattr(multimass.engines._run, "solve_ivp", fails_at_once)
    argv = ["simulate", "S1", "--release", "0.05", "--t-end", "0.2", "--backend", "scipy"]
    assert main(argv + ["--out", str(tmp_path / "o")]) == 1
    out = capsys.readouterr().out
    assert "S1: failed" in out
    assert "failed: solve_ivp (DOP853) failed at t = 0 s: Required step size" in out
    assert f"files in {tmp_path / 'o'}/" in out


def test_a_record_scaled_beyond_any_earthquake_is_refused_before_the_run(tmp_path, capsys):
    """A 0.5 g record scaled by 1e300 (the solver then stepped for minutes, or failed on a
    non-finite state) is refused in one line naming the record's peak and the fix."""
    rec = tmp_path / "rec.dat"
    rec.write_text("".join(f"{0.01 * i:.2f} {0.5 * (-1) ** i:.1f}\n" for i in range(200)))
    argv = ["simulate", "B6M", "--impact", "CIM", "--record", str(rec), "--units", "g"]
    assert main(argv + ["--scale", "1e300", "--t-end", "1"]) == 2
    err = capsys.readouterr().err
    assert "`rec: peak` = 4.905e+300 m/s² (5e+299 g)" in err and "--scale" in err
    assert err.count("\n") == 1


def test_output_step_too_fine_is_one_line_and_a_large_series_is_written_with_a_bar(
    tmp_path, capsys
):
    """--output-dt 1e-7 (10⁷ rows) is refused before the run in one line; a large but
    allowed series is written in chunks with a progress bar, to the same file as
    pandas writes it at once."""
    from multimass import FreeRelease, simulate
    from multimass.cli._output import write_csv

    argv = ["simulate", "B6M", "--impact", "CIM", "--release", "0.1", "--t-end", "1"]
    assert main(argv + ["--output-dt", "1e-7"]) == 2
    err = capsys.readouterr().err
    assert "`output_dt` (--output-dt) = 1e-07" in err and err.count("\n") == 1
    series = simulate("B6M", FreeRelease(0.1), "CIM", 0.3, output_dt=2e-6).series
    write_csv(series, tmp_path / "bar.csv", progress=True)
    series.to_csv(tmp_path / "once.csv", index=False)
    assert (tmp_path / "bar.csv").read_text() == (tmp_path / "once.csv").read_text()
    assert "writing bar.csv" in capsys.readouterr().err


def test_output_folder_is_checked_before_computing(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert main(["simulate", "S1", "--release", "0.05", "--t-end", "60", "--out", str(afile)]) == 2
    err = capsys.readouterr().err
    assert "is an existing file; give a folder" in err and err.count("\n") == 1
    # a folder that cannot be created (its parent is a file): refused, whoever runs the test
    assert main(["simulate", "S1", "--release", "0.05", "--out", str(afile / "sub")]) == 2
    assert "cannot write there" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            ["stability", "B6M", "--omega-p", "-1:10:6", "--amp", "1:2:2"],
            "`--omega-p` = [-1, 1.2, 3.4",
        ),
        (
            ["simulate", "S1", "--release", "0.1", "--seed", "-1", "--impact", "DD5"],
            "argument --seed",
        ),
        (
            [
                "spectrum",
                "S1",
                "--pulse",
                "cosine",
                "--omega",
                "15",
                "--amp",
                "0.4g",
                "--t-free",
                "nan",
            ],
            "argument --t-free: must be a finite number > 0, got 'nan'",
        ),
        (
            [
                "spectrum",
                "S1",
                "--record",
                "x.dat",
                "--units",
                "g",
                "--scale",
                "1",
                "--repeats",
                "0",
            ],
            "argument --repeats: must be a whole number ≥ 1, got '0'",
        ),
        (["stability", "B6M", "--integrator", "newmark", "--dt", "nan"], "argument --dt"),
        (["simulate", "S1", "--release", "0.1", "--t-end", "1e9"], "over the budget of 1 h"),
        (
            ["simulate", "S1", "--pulse", "sine", "--omega", "1e-6", "--amp", "0.4g"],
            "the excitation lasts 6.28e+06 s",
        ),
    ],
)
def test_user_mistakes_are_one_line(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1, err


def test_every_flag_has_a_help_text():
    import argparse

    from multimass.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = [
        f"{name} {action.dest}"
        for name, p in sub.choices.items()
        for action in p._actions
        if not isinstance(action, argparse._HelpAction) and not action.help
    ]
    assert not missing, missing
