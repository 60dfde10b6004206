"""The modal report: files, published values beside ours, the S2 mismatch shown."""

import json

import numpy as np
import pytest

from multimass import modal
from multimass.modal.measured import read_measured_shapes
from multimass.modal.report import printed_unit, summary, write_report

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
    for paper in (
        "7.6",
        "41.4",
        "20.7",
        "46.9",
        "298",
        "2.51",
    ):  # paper 001, Table 1 and Section 4.2
        assert f"| {paper} |" in md
    ours = info["rocking"]["freq_hz"][0]
    assert f"{ours:.4g}" in md
    assert "![S1_shapes](S1_shapes.png)" in md


def test_json_matches_summary_and_has_required_keys(s1_report):
    out, info = s1_report
    data = json.loads((out / "S1_modal.json").read_text())
    assert data == json.loads(json.dumps(info))
    for key in (
        "specimen",
        "derived",
        "full_contact",
        "rocking",
        "mac_full_vs_compound",
        "reference",
    ):
        assert key in data
    assert set(data["derived"]) >= {"m_t", "J_p", "H_cg", "alpha_cg", "p_l"}
    assert data["full_contact"]["freq_hz"] == sorted(data["full_contact"]["freq_hz"])
    assert data["rocking"]["freq_hz"] == sorted(data["rocking"]["freq_hz"])
    assert len(data["rocking"]["rocking_eigenvalues"]) == 2
    assert data["reference"]["J_p"] == 298


def test_s2_mismatch_is_shown_not_hidden():
    info = summary(modal.analyse("S2"))
    rows = info["comparison"]["derived"]
    assert rows["J_p"]["published"] == 509 and not rows["J_p"]["agrees"]  # paper 001, Table 1
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
    lines = ["node,mode_1,mode_2"] + [
        f"{n},{a:.6f},{b:.6f}" for n, (a, b) in zip(res.shape_nodes, vc * [2.0, -3.0])
    ]
    lines.append("freq_hz,20.1,44.0")
    path = tmp_path / "measured.csv"
    path.write_text("\n".join(lines))
    meas = read_measured_shapes(path)
    assert meas.nodes == res.shape_nodes
    np.testing.assert_allclose(meas.freq_hz, [20.1, 44.0])
    info = summary(res, meas)
    macs = np.array(info["measured"]["mac_vs_compound"])
    np.testing.assert_allclose(np.diag(macs[:, :2]), 1.0, atol=1e-9)


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("mode_1\n0.1\n", "no `node` column"),
        ("node\n2\n3\n", "no mode columns"),
        ("node,m1\n2,0.1\nx,0.2\n", "integer node numbers"),
        ("node,m1\n2,0.1\n3,abc\n", "column `m1`"),
    ],
)
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


# --- figures: what they draw is what the JSON says; nothing hidden or clipped ------------------


@pytest.fixture(scope="module", params=["S1", "S2", "S3"])
def analysis(request):
    return modal.analyse(request.param)


def test_shape_figure_draws_the_json_numbers(analysis):
    from multimass.modal.plots import shapes_figure

    info = summary(analysis)
    sh = info["shapes"]
    fig = shapes_figure(analysis)
    for j, ax in enumerate(fig.axes[:3]):
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        for label, key in (
            ("full contact v_n", "full_contact"),
            ("uplifted elastic v_t", "elastic"),
            ("uplifted compound v_c", "compound"),
        ):
            np.testing.assert_array_equal(lines[label].get_xdata(), sh[key][j])
            np.testing.assert_array_equal(lines[label].get_ydata(), sh["heights_m"])
    # the height axis starts at the base and shows it
    assert fig.axes[0].get_ylim()[0] == 0.0
    assert any(np.all(np.asarray(ln.get_ydata()) == 0.0) for ln in fig.axes[0].get_lines())


def _centre_px(ax, x, y):
    return ax.transData.transform((x, y))


def _distance_to_box(point, box):
    dx = max(box.x0 - point[0], 0.0, point[0] - box.x1)
    dy = max(box.y0 - point[1], 0.0, point[1] - box.y1)
    return np.hypot(dx, dy)


def test_eigenvalue_zoom_labels_hide_nothing(analysis):
    from multimass.modal.plots import eigenvalue_figure

    fig = eigenvalue_figure(analysis)
    fig.draw_without_rendering()
    zoom = fig.axes[1]
    texts = [t for t in zoom.texts]
    assert len(texts) == 4  # n1, n2, u1, u2
    boxes = [t.get_window_extent() for t in texts]
    frame = zoom.get_window_extent()
    for i, b in enumerate(boxes):
        assert frame.contains(b.x0, b.y0) and frame.contains(b.x1, b.y1), texts[i].get_text()
        for other in boxes[i + 1 :]:
            assert not b.overlaps(other)
    # ±p_l and the rocking pair: no label within a marker's radius (s = 140 pt², dpi 100)
    radius = np.sqrt(140) / 2 * fig.dpi / 72
    p = analysis.structure.p_l
    for x in (p, -p, *analysis.rocking_eigenvalues):
        c = _centre_px(zoom, x, 0.0)
        assert all(_distance_to_box(c, b) > radius for b in boxes)
    # every plotted eigenvalue of modes 1–2 lies outside every label
    for pm in (analysis.full_contact, analysis.rocking):
        for lam in pm.vibration_eigenvalues[pm.mode <= 2]:
            for y in (lam.imag, -lam.imag):
                c = _centre_px(zoom, lam.real, y)
                assert all(_distance_to_box(c, b) > 3 for b in boxes)
    # the legend is outside both panels
    assert not zoom.get_legend() and len(fig.legends) == 1
    legend = fig.legends[0].get_window_extent()
    assert not any(legend.overlaps(ax.get_window_extent()) for ax in fig.axes)
