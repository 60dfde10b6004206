"""The modal report: files, published values beside ours, the S2 mismatch shown."""

import json

import numpy as np
import pytest

import modal
from modal.measured import read_measured_shapes
from modal.report import printed_unit, summary, write_report

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def s1_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    info = write_report(modal.analyse("S1"), out)
    return out, info


def test_files_are_written(s1_report):
    out, _ = s1_report
    for name in ("S1_modal.md", "S1_modal.json", "S1_eigenvalues.png", "S1_shapes.png"):
        assert (out / name).is_file(), name
    for name in ("S1_eigenvalues.png", "S1_shapes.png"):
        data = (out / name).read_bytes()
        assert data.startswith(PNG) and len(data) > 20_000


def test_markdown_prints_paper_values_beside_ours(s1_report):
    out, info = s1_report
    md = (out / "S1_modal.md").read_text()
    for paper in ("7.6", "41.4", "20.7", "46.9", "298", "2.51"):   # paper 001, Table 1 and Section 4.2
        assert f"| {paper} |" in md
    ours = info["rocking"]["freq_hz"][0]
    assert f"{ours:.4g}" in md
    assert "![S1_shapes](S1_shapes.png)" in md


def test_json_matches_summary_and_has_required_keys(s1_report):
    out, info = s1_report
    data = json.loads((out / "S1_modal.json").read_text())
    assert data == json.loads(json.dumps(info))
    for key in ("specimen", "derived", "full_contact", "rocking", "mac_full_vs_compound", "reference"):
        assert key in data
    assert set(data["derived"]) >= {"m_t", "J_p", "H_cg", "alpha_cg", "p_l"}
    assert data["full_contact"]["freq_hz"] == sorted(data["full_contact"]["freq_hz"])
    assert data["rocking"]["freq_hz"] == sorted(data["rocking"]["freq_hz"])
    assert len(data["rocking"]["rocking_eigenvalues"]) == 2
    assert data["reference"]["J_p"] == 298


def test_s2_mismatch_is_shown_not_hidden():
    info = summary(modal.analyse("S2"))
    rows = info["comparison"]["derived"]
    assert rows["J_p"]["published"] == 509 and not rows["J_p"]["agrees"]     # paper 001, Table 1
    assert rows["H_cg"]["published"] == 1.18 and not rows["H_cg"]["agrees"]
    md = modal.report.markdown(modal.analyse("S2"), info)
    assert "**Mismatch:**" in md and "509" in md


@pytest.mark.parametrize("name", ["S1", "S3"])
def test_s1_s3_derived_agree(name):
    rows = summary(modal.analyse(name))["comparison"]["derived"]
    assert all(r["agrees"] for r in rows.values())


def test_printed_unit():
    assert printed_unit(298) == 1.0
    assert printed_unit(0.84) == pytest.approx(0.01)
    assert printed_unit(2.51) == pytest.approx(0.01)
    assert printed_unit(0.0175) == pytest.approx(1e-4)


def test_measured_shapes_mac(tmp_path):
    res = modal.analyse("S1")
    vc = res.compound_shapes()[:, :2]
    lines = ["node,mode_1,mode_2"] + [f"{n},{a:.6f},{b:.6f}" for n, (a, b) in
                                       zip(res.shape_nodes, vc * [2.0, -3.0])]
    lines.append("freq_hz,20.1,44.0")
    path = tmp_path / "measured.csv"
    path.write_text("\n".join(lines))
    meas = read_measured_shapes(path)
    assert meas.nodes == res.shape_nodes
    np.testing.assert_allclose(meas.freq_hz, [20.1, 44.0])
    info = summary(res, meas)
    macs = np.array(info["measured"]["mac_vs_compound"])
    np.testing.assert_allclose(np.diag(macs[:, :2]), 1.0, atol=1e-9)


@pytest.mark.parametrize("text, fragment", [
    ("mode_1\n0.1\n", "no `node` column"),
    ("node\n2\n3\n", "no mode columns"),
    ("node,m1\n2,0.1\nx,0.2\n", "integer node numbers"),
    ("node,m1\n2,0.1\n3,abc\n", "column `m1`"),
])
def test_measured_shapes_bad_input(tmp_path, text, fragment):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(modal.ModalError, match=fragment):
        read_measured_shapes(p)


def test_measured_nodes_outside_the_model(tmp_path):
    p = tmp_path / "far.csv"
    p.write_text("node,m1\n2,0.1\n9,0.3\n")
    with pytest.raises(modal.ModalError, match="outside"):
        summary(modal.analyse("S1"), read_measured_shapes(p))
