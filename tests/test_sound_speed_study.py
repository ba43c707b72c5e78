"""The sound-speed study's bookkeeping (validate/sound_speed.py) on points whose figures are
constructed: the error against the c = 20 U run is the median over shared looks, a frame's
jump (ejecta taken for the crown's foot) does not set it, and --record replaces only its own
section of VALIDATION.md."""
import pytest

from crowndemo.validate import sound_speed as study


def point(factor, base, rim, outcome="ran to the end"):
    """A 2D point at D/l0 = 100 with looks every 0.1 ms from 0.1 to 2 ms."""
    looks = [{"time": k * 1e-4, "crown": {"base_radius": base(k * 1e-4),
                                          "rim_height": rim(k * 1e-4)},
              "density": {"local": 0.1, "bulk": 0.01}} for k in range(1, 21)]
    return {"dim": 2, "l0": 1e-4, "D_l0": 100.0, "factor": factor, "U": 8.0, "drop": 1e-2,
            "film": 1e-3, "t_contact": 1.25e-4, "outcome": outcome, "t_reached": 2e-3,
            "base_radius": base(2e-3), "rim_height": rim(2e-3), "sheet_coherence": 0.9,
            "peak_local_excess": 0.2, "peak_bulk_excess": 0.03, "energy_loss": 0.2,
            "peak_mach": 0.6, "steps": 1000, "particle_steps": 1e7, "wall_s": 10.0,
            "first_step_s": 1.0, "look_s": 1.0, "looks": looks}


def test_error_is_the_median_over_shared_looks_from_0_4_ms():
    ref = point(20.0, lambda t: 0.01 + t, lambda t: 0.005)
    # 2 % larger everywhere, and one frame 50 % off: the median is 2 %
    other = point(10.0, lambda t: (0.01 + t) * (1.5 if abs(t - 1.8e-3) < 1e-9 else 1.02),
                  lambda t: 0.005 * 0.9)
    assert study.error_against(other, ref, "base_radius") == pytest.approx(0.02)
    assert study.error_against(other, ref, "rim_height") == pytest.approx(0.1)
    # looks before ERROR_FROM do not count: a point 100 % off there and exact after reads 0
    early = point(10.0, lambda t: (0.01 + t) * (2.0 if t < study.ERROR_FROM - 1e-9 else 1.0),
                  lambda t: 0.005)
    assert study.error_against(early, ref, "base_radius") == 0.0
    rows = study.table([ref, other]).splitlines()
    assert "| 10 |" in rows[2] and "2.0%, 10.0%" in rows[2]          # sorted by c / U
    assert "| 20 |" in rows[3] and "(reference)" in rows[3]


def test_yarin_weiss_ratio_of_a_base_on_the_law_is_one():
    from crowndemo.scenes.crown import crown_base_radius
    p = point(20.0, lambda t: crown_base_radius(t - 1.25e-4, 8.0, 1e-2, 1e-3), lambda t: 0.005)
    assert study.yarin_weiss_ratio(p) == pytest.approx(1.0, rel=1e-12)


def test_record_replaces_only_its_own_section(tmp_path):
    md = tmp_path / "V.md"
    md.write_text("# Validation\n\n## Before\n\nkept\n\n## Sound speed\n\nold\n\n## After\n\nkept "
                  "too\n")
    pts = [point(20.0, lambda t: 0.01, lambda t: 0.005)]
    study.record_section(md, pts, "a machine")
    text = md.read_text()
    assert text.count("## Sound speed") == 1 and "old" not in text
    assert text.index("## Before") < text.index("## Sound speed") < text.index("## After")
    assert "kept too" in text and "a machine" in text and "| 2 | 100 | 20 |" in text
    study.record_section(tmp_path / "new.md", pts, "a machine")      # a new file: appended
    assert "## Sound speed" in (tmp_path / "new.md").read_text()
