"""Bad input to the trace tools is a named error with the fix.

The cases — a trace with no rocking, half-cycles too short for what is asked,
sensors the specimen names missing, a sampling rate too low for the modes asked, NaN
samples, an ``ag`` channel in the wrong unit — for each tool: `restitution`,
`operational_modes` and `calibrate` from Python (an `InputError` whose message names
the field, the value and the fix) and as ``multimass restitution | identify |
calibrate`` (exit status 2, one line on stderr, no traceback). The good traces the bad
ones were made from pass the same checks (`test_the_good_traces_pass_every_check`).

The traces are short synthetic tests (`synthetic_trace`) corrupted one way each: S1
released from 0.11 rad (paper 001 Section 4.3's free-vibration test) and from 0.004 rad,
and two table tests (cosine pulses; S1 at 0.4 g, S2 at 0.28 g). Reference values: the
model's frequencies of S1 (`multimass.modal.analyse`: uplifted 20.5 and 45.65 Hz) and
the Nyquist frequency fs / 2 of the rate each trace is decimated to.
"""

import re

import numpy as np
import pytest

from multimass import FreeRelease
from multimass.cli import main
from multimass.errors import InputError
from multimass.identify import _calibration_setup as setup
from multimass.identify import _modes_select as select
from multimass.identify import calibrate, operational_modes, restitution, synthetic_trace
from multimass.identify._trace_checks import (
    check_ag,
    check_frozen,
    check_theta,
    require_sensors,
)
from multimass.identify.segments import segment_trace
from multimass.inputs.excitations import CosinePulse
from multimass.inputs.traces import Trace, format_trace, read_trace, write_trace
from multimass.modal import analyse
from multimass.model.structure import from_specimen

G = 9.81
TOOLS = ("restitution", "identify", "calibrate")


def _derive(trace, source, *, drop=(), step=1, channels=None, units=None):
    """`trace` with columns dropped, decimated by `step`, or channels replaced (SI)."""
    chans = {k: v[::step] for k, v in trace.channels.items() if k not in drop}
    chans.update(channels or {})
    written = {**trace.units, **(units or {})}
    return Trace(
        time=trace.time[::step], channels=chans, units={k: written[k] for k in chans},
        source=source, g=trace.g, specimen=trace.specimen,
    )  # fmt: skip


@pytest.fixture(scope="module")
def traces():
    """The good traces and the bad ones made from them, by name."""
    free = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 4.0, seed=1).trace
    tiny = synthetic_trace("S1", FreeRelease(theta0=0.004), "DD2", 1.5, seed=1).trace
    pulse_s1 = CosinePulse(amplitude=0.4 * G, omega=15.0)  # paper 001 Sec 4.4, Fig 9
    table1 = synthetic_trace("S1", pulse_s1, "DD2", 2.0, seed=1).trace
    pulse_s2 = CosinePulse(amplitude=0.28 * G, omega=6.0)
    table2 = synthetic_trace("S2", pulse_s2, "DD2", 2.5, seed=2).trace
    rng = np.random.default_rng(0)
    n = 400
    still = Trace(
        time=free.time[:n],
        channels={k: (1e-4 if k == "theta" else 0.01) * rng.standard_normal(n) for k in free.names},
        units=dict(free.units), source="still.csv", specimen="S1",
    )  # fmt: skip
    ag1, ag2 = table1.channels["ag"], table2.channels["ag"]
    # a logger that held its last value: the first 1.2 s of `free`, then 50 s of its last row
    k = int(np.searchsorted(free.time, 1.2, side="right"))
    dt = float(free.time[1] - free.time[0])
    held = free.time[k - 1] + dt * np.arange(1, int(round(50.0 / dt)) + 1)
    frozen = Trace(
        time=np.concatenate([free.time[:k], held]),
        channels={c: np.concatenate([x[:k], np.full(held.size, x[k - 1])])
                  for c, x in free.channels.items()},
        units=dict(free.units), source="frozen.csv", specimen="S1",
    )  # fmt: skip
    return {
        "free": free,
        "table1": table1,
        "table2": table2,
        "tiny": _derive(tiny, "tiny.csv"),
        "still": still,
        "no_a2_a4": _derive(free, "no_a2_a4.csv", drop=("a_A2", "a_A4")),
        "no_theta": _derive(free, "no_theta.csv", drop=("theta",)),
        "fs100": _derive(free, "fs100.csv", step=2),
        "fs50": _derive(free, "fs50.csv", step=4),
        "fs40": _derive(free, "fs40.csv", step=5),
        # m/s2 under a `g` header: 9.81 times too large (4.3 g; 2.9 g)
        "ag_big": _derive(table1, "ag_big.csv", channels={"ag": G * ag1}),
        "ag_large": _derive(table2, "ag_large.csv", channels={"ag": G * ag2}),
        # g under an `m/s2` header: 9.81 times too small
        "ag_small": _derive(table2, "ag_small.csv", channels={"ag": ag2 / G}, units={"ag": "m/s2"}),
        "frozen": frozen,
        # θ written in degrees under a `[rad]` header: 180/π times too large
        "deg_as_rad": _derive(
            free, "deg_as_rad.csv", channels={"theta": np.degrees(free.channels["theta"])}
        ),
    }


NO_ROCKING = r"no rocking half-cycle reaches theta_min = 0\.01 rad \(largest "
SLOW_50 = (
    r"20\.5 Hz in the model, above 0\.4 × the sampling rate 50 Hz = 20 Hz "
    r"\(the anti-alias passband; Nyquist frequency 25 Hz\): not identifiable; "
    r"record at 52 Hz or more"
)
SLOW_40 = (
    r"sampled at 40 Hz, too slow to cut θ into half-cycles: θ is low-passed at "
    r"cutoff_hz = 20 Hz, which must stay below 0\.45 × the sampling rate = 18 Hz; "
    r"record at 45 Hz or more"
)
SENSORS = r"no column for sensor\(s\) A2, A4 of 'S1' \(a_A2, a_A4 missing; the trace has theta, a_A1, a_A3\)"
AG_BIG = r"column `ag` \[g\]: the table acceleration peaks at 4\.\d+ g, beyond any shake-table test \(3 g\)"
AG_LARGE = (
    r"column `ag` \[g\]: the lowest sensor `a_A1` \[g\] measures 0\.1\d* × the table acceleration"
)
AG_SMALL = (
    r"column `ag` \[m/s2\]: the table acceleration peaks at 0\.29\d* m/s2, under 25% of what "
    r"uplifts 'S2' \(g tan α_cg = 2\.57 m/s2\), yet θ rocks to 0\.\d+ rad"
)
TO_MPS2 = r"m/s2 under a `g` header .*write it as `ag \[m/s2\]`"
FROZEN = (
    r"every channel \(theta, a_A1, a_A2, a_A3, a_A4\) is frozen from t = 1\.2 s to the end "
    r"\(50 s, 10000 samples, each constant to the bit\): the logger held its last value; "
    r"crop the trace at t = 1\.2 s"
)
# S1's α_cg = 0.3472 rad (atan of paper 001 Table 1's B over H_cg, computed); the release
# at 0.11 rad reads 6.3 "rad" in degrees
DEGREES = (
    r"column `theta` \[rad\]: \|θ\| reaches 6\.\d+ rad at t = \S+ s, beyond the overturning "
    r"angle of 'S1' \(α_cg = 0\.3472 rad\), yet the trace goes on: the values look like "
    r"degrees under a `\[rad\]` header \(0\.11\d rad if so\): write the column as `theta \[deg\]`"
)
TO_G = r"in g under an `m/s2` header .*write it as `ag \[g\]`, or, for a free-vibration test"

# (case, tool, trace, Python keywords, command-line flags, what the message must say)
CASES = [
    # (a) no rocking: a release below theta_min; a column that never uplifts
    *[("a: small release", tool, "tiny", {}, [], [NO_ROCKING + r"0\.00\d+ rad", r"lower theta_min"])
      for tool in TOOLS],
    *[("a: at rest", tool, "still", {}, [],
       [NO_ROCKING + r"0 rad", r"give a (test that rocks|trace with rocking)"]) for tool in TOOLS],
    # (b) half-cycles too short for what is asked
    ("b: theta_min above every peak", "restitution", "free", {"theta_min": 0.2},
     ["--theta-min", "0.2"], [r"theta_min = 0\.2 rad \(largest 0\.11\d rad", r"lower theta_min"]),
    ("b: periods longer than a half-cycle", "identify", "free", {"min_periods": 30},
     ["--min-periods", "30"],
     [r"too short for the modes asked: the lowest, 20\.5 Hz, needs \d+ samples",
      r"ask for higher modes only .* lower min_periods, or record faster"]),
    ("b: one half-cycle above theta_min", "calibrate", "free", {"theta_min": 0.1},
     ["--theta-min", "0.1"],
     [r"`fit` has r_er, the mean restitution of impacts on the right corner",
      r"theta_min = 0\.1 rad \(\S+: 1 large half-cycle\(s\), 0 right and 0 left impact",
      r"lower theta_min \(--theta-min\), or leave r_er out of `fit` \(--fit\)"]),
    # (c) the sensors the tool needs are missing (restitution fits θ alone)
    ("c: no theta", "restitution", "no_theta", {}, [],
     [r"no `theta` column", r"add a column `theta \[rad\]`"]),
    ("c: no a_A2, a_A4", "identify", "no_a2_a4", {}, [],
     [SENSORS, r"\[sensors\] table: add the missing column\(s\), or .*--sensors A1,A3"]),
    ("c: no a_A2, a_A4", "calibrate", "no_a2_a4", {}, [],
     [SENSORS, r"add the missing column\(s\), or .*--channels a_A1,a_A3"]),
    # (d) the sampling rate is too low for the modes asked
    ("d: 50 Hz, modes 1 and 2", "identify", "fs50", {"modes": [1, 2]}, ["--modes", "1,2"],
     [r"no rocking mode to identify \(mode 1: " + SLOW_50, r"mode 2: 45\.65 Hz .* record at 115 Hz"]),
    ("d: 50 Hz, every mode", "identify", "fs50", {}, [],
     [r"no rocking mode to identify \(the lowest, mode 1: " + SLOW_50,
      r"record faster, or identify the full-contact modes alone"]),
    ("d: 100 Hz, modes 1 and 2", "identify", "fs100", {"modes": [1, 2]}, ["--modes", "1,2"],
     [r"mode\(s\) 2 asked cannot be identified in the rocking phase \(mode 2: 45\.65 Hz in "
      r"the model, .*Nyquist frequency 50 Hz\)", r"ask for fewer modes \(modes=\[1\], --modes 1\)"]),
    ("d: 50 Hz, zeta1 and zeta2", "calibrate", "fs50", {"fit": "zeta1,zeta2"},
     ["--fit", "zeta1,zeta2"],
     [r"`fit` has zeta1, zeta2: .* they show full-contact mode 1 \(7\.469 Hz\); the next, "
      r"uplifted mode 1 in \S+: "
      + SLOW_50, r"fit fewer damping ratios \(--fit\), or record faster"]),
    ("d: 100 Hz, zeta1 and zeta2", "calibrate", "fs100", {"fit": "zeta1,zeta2"},
     ["--fit", "zeta1,zeta2"],
     [r"they show uplifted mode 1 \(20\.5 Hz\); the next, uplifted mode 2 in \S+: 45\.65 "
      r"Hz in the model, .*Nyquist frequency 50 Hz\): not identifiable; record at 115 Hz"]),
    *[("d: 40 Hz", tool, "fs40", {}, [], [SLOW_40]) for tool in TOOLS],
    # (f) ag in the wrong unit
    *[("f: m/s2 as g, 4.3 g", tool, "ag_big", {}, [], [AG_BIG, TO_MPS2]) for tool in TOOLS],
    *[("f: m/s2 as g, 2.9 g", tool, "ag_large", {}, [], [AG_LARGE, TO_MPS2]) for tool in TOOLS],
    *[("f: g as m/s2", tool, "ag_small", {}, [], [AG_SMALL, TO_G]) for tool in TOOLS],
    # (g) a logger that held its last value for 50 s; θ in degrees under a `[rad]` header
    *[("g: frozen tail", tool, "frozen", {}, [], [FROZEN]) for tool in TOOLS],
    *[("g: degrees as rad", tool, "deg_as_rad", {}, [], [DEGREES]) for tool in TOOLS],
]  # fmt: skip
IDS = [f"{tool}-{case}" for case, tool, *_ in CASES]


def _specimen(trace) -> str:
    return trace.specimen or "S1"


def _python(tool, trace, **kw):
    """The tool's Python function on `trace` (calibrate fits the corner means by default)."""
    if tool == "restitution":
        return restitution(trace, _specimen(trace), "DD2", progress=False, **kw)
    if tool == "identify":
        return operational_modes(trace, _specimen(trace), **kw)
    return calibrate(trace, _specimen(trace), "DD2", **({"fit": "r_er,r_el"} | kw), progress=False)


def _argv(tool, path, specimen, flags, out) -> list[str]:
    """The command line of the issue: `multimass TOOL TRACE --specimen S ...`."""
    argv = [tool, str(path), "--specimen", specimen]
    if tool == "identify":
        argv += ["--out", str(out)]
    elif tool == "calibrate":
        argv += ["--impact", "DD2", "--fit", "r_er,r_el", "--quiet", "--no-figures"]
        argv += ["--out", str(out)]
    return argv + flags


def _one_line_error(tool, capsys) -> str:
    captured = capsys.readouterr()
    err = captured.err
    assert "Traceback" not in err and "Traceback" not in captured.out
    assert len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"multimass {tool}: error: ")
    return err


@pytest.mark.parametrize("case, tool, name, kw, flags, patterns", CASES, ids=IDS)
def test_python_names_the_field_and_the_fix(traces, case, tool, name, kw, flags, patterns):
    with pytest.raises(InputError) as err:
        _python(tool, traces[name], **kw)
    for pattern in patterns:
        assert re.search(pattern, str(err.value)), (pattern, str(err.value))


@pytest.mark.parametrize("case, tool, name, kw, flags, patterns", CASES, ids=IDS)
def test_command_line_is_one_line_and_exit_2(
    traces, tmp_path, capsys, case, tool, name, kw, flags, patterns
):
    trace = traces[name]
    path = write_trace(trace, tmp_path / f"{name}.csv")
    assert main(_argv(tool, path, _specimen(trace), flags, tmp_path / "out")) == 2
    err = _one_line_error(tool, capsys)
    for pattern in patterns:
        assert re.search(pattern, err), (pattern, err)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


# ---------------------------------------------------------------------------- (e) NaN
@pytest.mark.parametrize("column, index", [("t", 0), ("theta", 1), ("a_A2", 3)])
def test_nan_names_the_column_and_the_first_row(traces, tmp_path, capsys, column, index):
    lines = format_trace(traces["free"]).splitlines()  # line 1 `# specimen`, 2 the header
    for row in (101, 150):  # two bad rows: the first is named
        cells = lines[row - 1].split(",")
        cells[index] = "nan"
        lines[row - 1] = ",".join(cells)
    path = tmp_path / "nan.csv"
    path.write_text("\n".join(lines) + "\n")
    name = "time" if column == "t" else column
    expected = f"nan.csv, line 101, column `{name}`: value nan is not a finite number; fix or remove the row"
    with pytest.raises(InputError, match=re.escape(expected)):
        read_trace(path)  # what restitution's and operational_modes' traces come from
    with pytest.raises(InputError, match=re.escape(expected)):
        calibrate(path, "S1", fit="r_er", progress=False)  # calibrate reads the paths itself
    for tool in TOOLS:
        assert main(_argv(tool, path, "S1", [], tmp_path / "out")) == 2
        assert expected in _one_line_error(tool, capsys)


def test_nan_in_arrays_names_the_column_and_the_sample(traces):
    free = traces["free"]
    theta = np.array(free.channels["theta"])
    theta[[7, 9]] = np.nan
    with pytest.raises(InputError, match=r"arrays, sample 7, column `theta`: value nan"):
        _derive(free, "arrays", channels={"theta": theta})


# ---------------------------------------------------------------------------- the good traces pass
def test_the_good_traces_pass_every_check(traces):
    # the same checks on the traces the bad ones were made from: they must not fire
    free, s1 = traces["free"], from_specimen("S1")
    for name, spec in (("table1", "S1"), ("table2", "S2"), ("free", "S1")):
        tr = traces[name]
        check_ag(tr, from_specimen(spec), segment_trace(tr))
        check_frozen(tr)
        check_theta(tr, from_specimen(spec))
    require_sensors(free, s1, s1.specimen.sensors, "")
    for trace in (traces["fs50"], traces["fs100"]):
        assert segment_trace(trace).half_cycles  # 45 Hz and more: segmented
    model = analyse(s1)
    for fs, asked in ((200.0, [1, 2]), (100.0, [1]), (200.0, None)):
        keep, _, _, skip = select.model_modes(model.rocking, asked, fs)
        select.check_modes("x", "rocking", keep, skip, asked)
    fit = ("r_er", "r_el", "cp", "zeta1", "zeta2")
    cases = setup.cases([free], s1, fit, None, 0.01)
    assert len(cases[0].large) >= 5
    assert setup.cases([traces["fs100"]], s1, ("zeta1",), None, 0.01)  # 20.5 Hz < 0.4 fs


def test_identify_checks_every_phase_before_fitting(traces, monkeypatch):
    # the 4 s trace rocks to its end: no full contact; nothing is fitted before saying so
    from multimass.identify import _modes_combine

    def fitted(*args, **kw):
        raise AssertionError("a phase was fitted before the checks of every phase")

    monkeypatch.setattr(_modes_combine, "estimate", fitted)
    with pytest.raises(InputError, match="no full-contact stretch with a free decay"):
        operational_modes(traces["free"], "S1")


def test_restitution_needs_theta_alone(traces):
    # restitution fits θ: the accelerometers the specimen names are not needed
    short = Trace(
        time=traces["free"].time[:300], channels={"theta": traces["free"].channels["theta"][:300]},
        units={"theta": "rad"}, source="theta_only.csv", specimen="S1",
    )  # fmt: skip
    est = restitution(short, "S1", "DD2", progress=False)
    assert len(est.impacts) >= 1 and np.isfinite(est.r_mean_left)


def test_a_trace_the_model_cannot_start_from_is_a_named_error(traces, monkeypatch):
    """Behind the checks of the trace: a first fitting point the model refuses (here θ
    read 180/π too large, the θ check switched off) is an InputError that names the trace
    and the fix, never the fitting's internal rejection escaping as a traceback."""
    import multimass.identify.impacts as impacts

    for module in (impacts, setup):
        monkeypatch.setattr(module, "check_theta", lambda trace, st: None)
    with pytest.raises(InputError, match=r"deg_as_rad.csv: the model of 'S1' cannot run .*units"):
        restitution(traces["deg_as_rad"], "S1", "DD2", progress=False)
