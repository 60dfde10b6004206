"""Chart details of the benchmarks (benchmarks/charts.py)."""

from matplotlib.figure import Figure
from matplotlib.ticker import NullFormatter

from multimass.bench.charts import _major_labels_only


def test_minor_labels_dropped_only_where_a_power_of_ten_is_labelled():
    ax = Figure().subplots()
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(0.015, 0.35)  # holds 10⁻¹: its label is enough
    ax.set_ylim(2.0, 8.0)  # no power of ten: the minor labels are all there is
    _major_labels_only(ax)
    assert isinstance(ax.xaxis.get_minor_formatter(), NullFormatter)
    assert not isinstance(ax.yaxis.get_minor_formatter(), NullFormatter)
