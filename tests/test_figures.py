"""The thesis's figures (issue 5): every file is drawn, is a real PNG, and the
one-transfer timing behind Fig. 15-21 keeps the thesis's nominal split (SPEC §6)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from cell.assembly import motors_of, step_table
from cell.cli import main
from cell.figures import FILES, make_figures
from cell.figures.motion import nominal_timeline
from cell.motors import max_rates
from cell.scenario import default_scenario, load_scenario

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the IHDR chunk (PNG spec §11.2.2)."""
    head = path.read_bytes()[:24]
    assert head[:8] == PNG_SIGNATURE, f"{path.name} is not a PNG"
    assert head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


@pytest.fixture(scope="module")
def drawn(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("figures")
    make_figures(default_scenario(), out, parts=60)
    return out


@pytest.mark.parametrize("number", sorted(FILES))
def test_every_figure_is_a_readable_png(drawn: Path, number: int) -> None:
    path = drawn / f"{FILES[number]}.png"
    assert path.exists(), f"Fig. {number} missing"
    width, height = png_size(path)
    assert width >= 600 and height >= 400          # readable on screen
    assert width <= 1400 and height <= 1200        # modest (dpi ~110)
    assert 15_000 < path.stat().st_size < 600_000  # drawn, not blank; not huge


def test_names_follow_the_thesis_numbering() -> None:
    expected = {8, 9, *range(12, 31)}
    assert set(FILES) == expected
    for n, stem in FILES.items():
        assert stem.startswith(f"fig{n:02d}_")


def test_no_temporary_files_left(drawn: Path) -> None:
    assert sorted(p.name for p in drawn.iterdir() if not p.name.endswith(".png")) == []


def test_nominal_transfer_keeps_the_thesis_split() -> None:
    """The ideal 22.5872 s cycle split as in SPEC §6: R I and R III at belt pace
    (8/3 s and 4 s, plus what the motors add after LO/TD), R IV at the base's
    nominal rate (thesis 9.9855 s), R II the rest (thesis 5.935 s at R I = 8/3 s)."""
    s = load_scenario("baseline")
    table = step_table(s)
    tl = nominal_timeline(table, s)
    assert tl.t_s[-1] == pytest.approx(22.5872, abs=1e-9)
    assert sum(tl.regime_s.values()) == pytest.approx(22.5872, abs=1e-9)
    assert tl.regime_s[4] == pytest.approx(9.9855, abs=2e-3)
    assert 8 / 3 <= tl.regime_s[1] < 8 / 3 + 0.1      # §4.3 c: the loaded shoulder after LO
    assert 4.0 <= tl.regime_s[3] < 4.0 + 0.1
    r2_thesis = 22.5872 - 8 / 3 - 4 - 9.9855
    excess = (tl.regime_s[1] - 8 / 3) + (tl.regime_s[3] - 4) + (tl.regime_s[4] - 9.9855)
    assert tl.regime_s[2] == pytest.approx(r2_thesis - excess, abs=1e-9)
    # Up to LO the tool centre moves with the belt: x advances at 3 in/s (the
    # move onto LO also closes the hand, eq. 6.2, and may take longer).
    lo = table.path.lo
    dx = np.diff(table.path.xyz_in[:lo, 0])
    np.testing.assert_allclose(tl.dt_s[1:lo], dx / 3.0, rtol=1e-12)
    # R II runs at one tip velocity: every move the same ℓ/dt.
    r2 = table.regime_rows(2)
    v = table.move_in[r2] / tl.dt_s[r2]
    assert np.ptp(v) < 1e-9 and v[0] == pytest.approx(12.5663 / tl.regime_s[2], rel=1e-4)


def test_no_joint_beyond_its_maximum_rate() -> None:
    """Fig. 17-21: every drawn rate is within the motor's rate at the move's load (§6.1)."""
    s = default_scenario()
    table = step_table(s)
    tl = nominal_timeline(table, s)
    rate = np.abs(table.steps[1:]) / tl.dt_s[1:, None]
    limit = max_rates(table.path.load_oz[1:], motors_of(s))
    assert np.all(rate <= limit * (1 + 1e-9))


def test_bad_scenario_is_one_line_and_writes_nothing(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("belts:\n  input_nominal_in_s: -3\n")
    out = tmp_path / "figs"
    assert main(["figures", "--scenario", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "input_nominal_in_s" in err and len(err.splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


def test_out_that_is_a_file_is_one_line(tmp_path: Path, capsys) -> None:
    blocker = tmp_path / "figs"
    blocker.write_text("not a folder")
    assert main(["figures", "--out", str(blocker / "sub")]) == 2
    assert capsys.readouterr().err.count("\n") == 1
