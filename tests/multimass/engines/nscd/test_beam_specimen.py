"""The bundled beam base of paper 002 and the validation of beam specimen files."""

import pytest

from multimass import specimens
from multimass.specimens import BeamSpecimen, SpecimenError


def test_paper_002_beam():
    beam = specimens.load("beam_mudric2024")
    assert isinstance(beam, BeamSpecimen) and beam.kind == "beam"
    # paper 002, Section 6: span 30 cm, section 40 x 1.71 mm, nu 0.334, rho 2795 kg/m3, mu 0.364,
    # Rayleigh 0.05 at mode 1 and 0.2 at mode 3; Section 6.1: E = 1e24 Pa rigid base, 6 elements
    assert (beam.span, beam.section_width, beam.section_height) == (0.30, 0.040, 0.00171)
    assert (beam.nu, beam.rho, beam.mu) == (0.334, 2795.0, 0.364)
    assert beam.damping_ratios == (0.05, 0.2) and beam.damping_modes == (1, 3)
    assert beam.E == 1e24 and beam.n_elements == 6
    # closed form: A = w h, I = w h^3 / 12
    assert beam.area == pytest.approx(0.040 * 0.00171, rel=1e-14)
    assert beam.second_moment == pytest.approx(0.040 * 0.00171**3 / 12, rel=1e-14)


def test_listed_with_its_kind():
    assert "beam_mudric2024" in specimens.available()


@pytest.mark.parametrize(
    "old, new, fragment",
    [
        ("n_elements = 6", "n_elements = 2", "`mesh.n_elements`"),
        ("modes = [1, 3]", "modes = [3, 1]", "`damping.modes`"),
        ("ratios = [0.05, 0.2]", "ratios = [0.05, -0.2]", "`damping.ratios[1]`"),
        ("span_m = 0.30", "span_m = 0.0", "`geometry.span_m`"),
        ("poisson_ratio = 0.334", "poisson_ratio = 0.7", "`material.poisson_ratio`"),
        (
            "friction_coefficient = 0.364",
            "friction_coefficient = -1",
            "`contact.friction_coefficient`",
        ),
        ("[mesh]", "[mesh]\nsupports = 2", "unknown key `mesh.supports`"),
    ],
)
def test_bad_beam_files(tmp_path, old, new, fragment):
    text = specimens.loader._bundled()["beam_mudric2024"].read_text()
    assert old in text
    path = tmp_path / "beam.toml"
    path.write_text(text.replace(old, new))
    with pytest.raises(SpecimenError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        specimens.load(path)
