"""The anti-alias filter and the sampling of synthetic traces (multimass.identify.sampling)."""

import numpy as np
import pytest

from multimass import InputError
from multimass.identify import anti_alias_fir, fir_figures, resample

FS_IN, FS = 8000.0, 200.0  # synthetic_trace's defaults: 40 × 200 Hz


@pytest.fixture(scope="module")
def taps():
    return anti_alias_fir(FS_IN, FS)


def _dtft(h, f, fs):
    """|H(f)| of the taps, summed term by term (independent of scipy.signal.freqz)."""
    k = np.arange(h.size)
    return np.abs(np.exp(-2j * np.pi * np.outer(f, k) / fs) @ h)


def test_design_is_linear_phase_with_unit_gain(taps):
    assert taps.size % 2 == 1
    np.testing.assert_array_equal(taps, taps[::-1])
    assert taps.sum() == pytest.approx(1.0, abs=1e-14)


def test_measured_figures(taps):
    fig = fir_figures(taps, FS_IN, FS)
    assert fig["passband_hz"] == 80.0 and fig["stopband_hz"] == 100.0
    assert fig["passband_ripple_db"] < 1e-3
    assert fig["stopband_attenuation_db"] >= 80.0
    # the same figures from the taps summed directly, on a coarser grid
    gain = _dtft(taps, np.linspace(0.0, 80.0, 161), FS_IN)
    assert np.max(np.abs(20 * np.log10(gain))) <= fig["passband_ripple_db"] + 1e-9
    stop = _dtft(taps, np.linspace(100.0, FS_IN / 2, 4001), FS_IN)
    assert -20 * np.log10(stop.max()) >= fig["stopband_attenuation_db"] - 1e-6


@pytest.mark.parametrize("f_hz", [0.7, 5.0, 40.0, 79.0])
def test_a_low_frequency_sinusoid_passes_unchanged(taps, f_hz):
    # closed form: sin(2π f t + φ) at the output times, shifted by a fraction of a sample
    t0 = -1.0
    x_t = t0 + np.arange(int(5 * FS_IN)) / FS_IN
    times = np.arange(0.0, 3.0, 1 / FS) + 0.0123
    y = resample(np.sin(2 * np.pi * f_hz * x_t + 0.3), FS_IN, t0, times, taps)
    exact = np.sin(2 * np.pi * f_hz * times + 0.3)
    assert np.max(np.abs(y - exact)) < 1.5e-4  # ripple 0.001 dB = 1.2e-4, spline < 1e-5


@pytest.mark.parametrize("f_hz", [101.0, 150.0, 350.0, 1234.5])
def test_a_sinusoid_above_the_output_nyquist_is_suppressed(taps, f_hz):
    # sampled at 200 Hz without a filter it would alias to |f − 200 k| with amplitude 1
    t0 = -1.0
    x_t = t0 + np.arange(int(5 * FS_IN)) / FS_IN
    times = np.arange(0.0, 3.0, 1 / FS) + 0.0123
    y = resample(np.sin(2 * np.pi * f_hz * x_t), FS_IN, t0, times, taps)
    assert np.max(np.abs(y)) < 1e-4  # at least 80 dB


def test_the_filter_is_zero_phase(taps):
    # a symmetric pulse stays centred where it was: no delay
    t0 = -1.0
    x_t = t0 + np.arange(int(2 * FS_IN)) / FS_IN
    pulse = np.exp(-(((x_t - 0.2) / 0.02) ** 2))
    times = np.linspace(0.1, 0.3, 4001)
    y = resample(pulse, FS_IN, t0, times, taps)
    assert times[np.argmax(y)] == pytest.approx(0.2, abs=1e-4)


def test_bad_arguments(taps):
    x = np.zeros(5000)
    with pytest.raises(InputError, match=r"`times`: from 0 to 0 s, but .*\(the filter needs"):
        resample(x, FS_IN, 0.0, [0.0], taps)
    with pytest.raises(InputError, match=r"`taps`: give an odd number of symmetric"):
        resample(x, FS_IN, 0.0, [0.3], taps[:-1])
    with pytest.raises(InputError, match=r"`values`: give a 1-D array of finite"):
        resample(np.full(5000, np.nan), FS_IN, 0.0, [0.3], taps)
    with pytest.raises(InputError, match=r"`values`: 100 samples, fewer than"):
        resample(x[:100], FS_IN, 0.0, [0.005], taps)
    with pytest.raises(InputError, match=r"`fs_out` = 3000 Hz with `fs_in` = 8000 Hz"):
        anti_alias_fir(FS_IN, 3000.0)
    with pytest.raises(InputError, match=r"`passband` = 0.5"):
        anti_alias_fir(FS_IN, FS, passband=0.5)
    with pytest.raises(InputError, match=r"`fs_in` = 0"):
        anti_alias_fir(0, FS)
