"""The thesis's figures: every file is drawn, is a real PNG, and says nothing a
reader cannot look up; the one-transfer timing behind Fig. 15-21 keeps the
thesis's nominal split (docs/model.md, "The nominal cycle"); Fig. 22 draws no
speed the motors cannot give; no name or label is drawn over by a curve."""

from __future__ import annotations

import re
import struct
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text

from cell.arm.motors import max_rates
from cell.cli.main import main
from cell.reporting.figures.motion import nominal_timeline
from cell.reporting.figures.thesis_figures import FILES, make_figures
from cell.scenario.schema import default_scenario, load_scenario
from cell.sim.physics_checks import step_table
from cell.sim.scenario_values import motors_of

# One worker draws every figure once (``make test`` runs ``--dist loadgroup``): the module's
# fixtures would otherwise draw them on each worker.
pytestmark = pytest.mark.xdist_group("figures")

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the IHDR chunk (PNG spec §11.2.2)."""
    head = path.read_bytes()[:24]
    assert head[:8] == PNG_SIGNATURE, f"{path.name} is not a PNG"
    assert head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


#: The committed figures' scenario (``cell figures``'s default), at 60 parts a run.
SCENARIO = load_scenario("baseline").with_overrides({"run.parts": 60})
#: The figures drawn to pixels: one of each drawing function.  Fig. 18-21 are Fig. 17's
#: function for another joint, Fig. 24 Fig. 23's for running means, Fig. 26-30 Fig. 25's for
#: another cycle: those are laid out (their texts read here), not rasterised.
RASTERISED = (8, 9, 12, 13, 14, 15, 16, 17, 22, 23, 25)


@pytest.fixture(scope="module")
def captured(tmp_path_factory: pytest.TempPathFactory) -> SimpleNamespace:
    """Every figure drawn once (:data:`RASTERISED`'s to pixels), for every test here: the
    folder (``out``), the texts of each as it was saved (``texts``), each figure as saved
    (``figures``), by file stem, and the runs Fig. 22-30 were drawn from (``runs``)."""
    from cell.reporting.figures import runs as run_figures
    from tests.reporting.conftest import unrendered_savefig

    out = tmp_path_factory.mktemp("figures")
    texts: dict[str, list[str]] = {}
    figures: dict[str, Figure] = {}
    simulated: list[Any] = []
    original, simulate_runs = Figure.savefig, run_figures.simulate_runs

    def savefig(fig: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
        stem = Path(fname).name.lstrip(".").split(".png")[0]
        texts[stem] = [t.get_text() for t in fig.findobj(Text) if t.get_visible() and t.get_text()]
        figures[stem] = fig
        save = original if stem in {FILES[n] for n in RASTERISED} else unrendered_savefig
        save(fig, fname, *args, **kwargs)

    def kept(*args: Any, **kwargs: Any) -> Any:
        simulated.append(simulate_runs(*args, **kwargs))
        return simulated[-1]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", savefig)
        mp.setattr(run_figures, "simulate_runs", kept)
        make_figures(SCENARIO, out)
    (runs,) = simulated
    return SimpleNamespace(out=out, texts=texts, figures=figures, runs=runs)


@pytest.fixture(scope="module")
def drawn(captured: SimpleNamespace) -> Path:
    return captured.out


def test_every_figure_is_written(drawn: Path) -> None:
    assert sorted(p.name for p in drawn.iterdir()) == sorted(f"{stem}.png" for stem in FILES.values())


@pytest.mark.parametrize("number", RASTERISED)
def test_every_figure_is_a_readable_png(drawn: Path, number: int) -> None:
    path = drawn / f"{FILES[number]}.png"
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
    """The ideal 22.5872 s cycle split as in docs/model.md: R I and R III at belt pace
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


def test_no_joint_travel_beyond_its_maximum_rate() -> None:
    """Fig. 17-21's black traces: each move's joint travel |Δθ|·k over its drawn time is
    within the motor's rate at the move's load, the rate linear in the load (§6.1).
    Over the whole-step times the loaded shoulder's travel would exceed it by 8 %."""
    from cell.reporting.figures.motion import joint_travel_min_times

    s = default_scenario()
    m = s.robot.motors
    table = step_table(s)
    tl = nominal_timeline(table, s, joint_travel_min_times(table))
    k = np.array(m.steps_per_rad)
    travel = np.abs(np.diff(table.path.q_rad, axis=0)) * k
    load = table.path.load_oz[1:, None]
    no_load, full = np.array(m.max_rate_no_load_rad_s), np.array(m.max_rate_full_load_rad_s)
    limit = k * (no_load + (full - no_load) * load / m.full_load_oz)
    assert np.all(travel / tl.dt_s[1:, None] <= limit * (1 + 1e-9))
    steps_tl = nominal_timeline(table, s)
    assert np.max(travel / steps_tl.dt_s[1:, None] / limit) > 1.05
    np.testing.assert_allclose(tl.t_s[[table.path.lo, table.path.td, -1]],
                               steps_tl.t_s[[table.path.lo, table.path.td, -1]], atol=1e-9)


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


# --------------------------------------------------------------------------- what a reader sees
def github_anchor(heading: str) -> str:
    """GitHub's anchor of a Markdown heading: lower case, punctuation dropped, spaces to '-'."""
    kept = "".join(c for c in heading.strip().lower() if c.isalnum() or c in " -_")
    return kept.replace(" ", "-")


def anchors(doc: Path) -> set[str]:
    return {github_anchor(line.lstrip("#")) for line in doc.read_text().splitlines()
            if line.startswith("#")}


REPO = Path(__file__).resolve().parents[2]


def test_no_figure_cites_what_a_reader_cannot_open(captured) -> None:
    """No SPEC, no files outside the repository, no issue numbers; every docs/ link
    names a page and a section that exist."""
    texts = captured.texts
    assert set(texts) == set(FILES.values())
    links = 0
    for name, words in texts.items():
        for text in words:
            assert "SPEC" not in text, (name, text)
            assert "shared/" not in text, (name, text)
            assert not re.search(r"issue|#\d", text, re.IGNORECASE), (name, text)
            for page, anchor in re.findall(r"(docs/[\w.-]+\.md)#([\w-]+)", text):
                assert (REPO / page).exists(), (name, page)
                assert anchor in anchors(REPO / page), (name, page, anchor)
                links += 1
    assert links >= 3 * 8   # Fig. 23-30 each point to the three accountings


def test_fig23_24_say_which_non_adaptive_mean_they_draw(captured) -> None:
    """The thesis panel's non-adaptive mean is over every part (lost ones booked D = T + C),
    the summary's actual cycle is the same Σ D over the parts delivered (docs/accounting.md)."""
    from cell.sim.simulation import simulate

    texts = captured.texts
    r = simulate(SCENARIO.with_overrides({"controller.policy": "non-adaptive"}))
    d, summary = r.parts, r.summary.as_dict()
    total = d["thesis_interval_s"].sum()
    delivered = len(d) - int(d["missed_thesis"].sum())
    for name in (FILES[23], FILES[24]):
        note = " ".join(t.replace("\n", " ") for t in texts[name] if "Σ D" in t)
        per_part = re.search(r"Σ D / (\d+) parts = ([\d.]+) s", note)
        per_delivery = re.search(r"by the (\d+) parts delivered: ([\d.]+) s", note)
        assert per_part and per_delivery, note
        assert int(per_part[1]) == len(d)
        assert float(per_part[2]) == pytest.approx(total / len(d), abs=5e-4)
        assert int(per_delivery[1]) == delivered
        assert float(per_delivery[2]) == pytest.approx(summary["actual_cycle_thesis_s"], abs=5e-4)
        assert float(per_delivery[2]) == pytest.approx(total / delivered, abs=5e-4)


# --------------------------------------------------------------------------- Fig. 22
@pytest.fixture(scope="module")
def fig22(captured: SimpleNamespace) -> tuple[Figure, Any, Any]:
    """Fig. 22 as saved, the record of the transfer it draws, and its scenario."""
    from cell.reporting.figures.tip import pick_transfer

    adaptive = captured.runs.adaptive
    return captured.figures[FILES[22]], adaptive.parts.iloc[pick_transfer(adaptive)], SCENARIO


def tip_curve(fig: Figure) -> tuple[np.ndarray, np.ndarray]:
    ax = fig.axes[0]
    (curve,) = [p for p in ax.patches if p.get_label() == "tool-centre speed along the path"]
    values, edges, _ = curve.get_data()
    return np.asarray(values), np.asarray(edges)


def motor_limited_speeds(s) -> np.ndarray:
    """Each move's fastest tool-centre speed: its length over the time its slowest joint
    needs for its travel |Δθ|·k at the maximum rate, linear in the load (§6.1)."""
    m = s.robot.motors
    table = step_table(s)
    k = np.array(m.steps_per_rad)
    travel = np.abs(np.diff(table.path.q_rad, axis=0)) * k
    load = table.path.load_oz[1:, None]
    no_load, full = np.array(m.max_rate_no_load_rad_s), np.array(m.max_rate_full_load_rad_s)
    rate = k * (no_load + (full - no_load) * load / m.full_load_oz)
    return table.path.move_in[1:] / np.max(travel / rate, axis=1)


def test_fig22_no_speed_beyond_what_the_motors_allow(fig22) -> None:
    fig, _, s = fig22
    speed, _ = tip_curve(fig)
    limit = motor_limited_speeds(s)
    assert len(speed) == len(limit)
    assert np.all(speed <= limit * (1 + 1e-3))   # whole steps round a regime by < 1 step


def test_fig22_keeps_the_records_instants_and_the_paths_lengths(fig22) -> None:
    """LO at 0, TD and the cycle's end where the record puts them, and each regime
    covers its path length: speed × time adds up to the inches of the path."""
    fig, row, s = fig22
    table = step_table(s)
    speed, t = tip_curve(fig)
    start, lo = row["at_bot_s"], row["pick_s"]
    p = table.path
    assert t[p.lo] == pytest.approx(0.0, abs=1e-9)
    assert t[0] == pytest.approx(start - lo, abs=1e-9)
    assert t[p.td] == pytest.approx(row["touchdown_s"] - lo, abs=1e-9)
    cycle = row["r1_s"] + row["r2_s"] + row["r3_s"] + row["r4_s"]
    assert t[-1] == pytest.approx(start + cycle - lo, abs=1e-9)
    covered = speed * np.diff(t)
    for r in (1, 2, 3, 4):
        rows = p.regime[1:] == r
        assert covered[rows].sum() == pytest.approx(p.move_in[1:][rows].sum(), rel=1e-9)


def test_fig22_only_the_hand_moves_stand_out(fig22) -> None:
    """No one-move spike: within a regime neighbouring moves differ by under 0.1 in/s,
    except the move onto LO where the fingers close and the one after TD where they
    open (eq. 6.2), each at its motors' limit.  Timed on whole steps, the loaded
    shoulder's 10- and 11-step moves after LO would differ by 0.3 in/s."""
    fig, _, s = fig22
    table = step_table(s)
    speed, _ = tip_curve(fig)
    limit = motor_limited_speeds(s)
    opening = table.path.opening_in
    hand = set(np.flatnonzero(np.diff(opening) != 0))       # move index (row - 1)
    assert len(hand) == 2
    regime = table.path.regime[1:]
    for i in range(1, len(speed)):
        if regime[i] != regime[i - 1] or i in hand or i - 1 in hand:
            continue
        assert abs(speed[i] - speed[i - 1]) < 0.1, i
    for i in hand:
        assert speed[i] == pytest.approx(limit[i], rel=1e-3)
        assert speed[i] < min(speed[i - 1], speed[i + 1]) - 0.1


def display_points(artist: Any, step_px: float = 0.5) -> np.ndarray:
    """Points every half pixel along an artist's curves, in display pixels."""
    from matplotlib.collections import Collection

    if isinstance(artist, Collection):
        paths = [artist.get_transform().transform_path(p) for p in artist.get_paths()]
    else:
        paths = [artist.get_transform().transform_path(artist.get_path())]
    out = []
    for path in paths:
        v = path.vertices
        for a, b in zip(v[:-1], v[1:]):
            n = max(int(np.hypot(*(b - a)) / step_px), 1)
            out.append(a + np.linspace(0.0, 1.0, n + 1)[:, None] * (b - a))
    return np.vstack(out)


def covered(fig: Figure, curves: list[Any]) -> list[tuple[str, str]]:
    """(text, curve) pairs where a curve passes through a text's box, and text pairs that overlap."""
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    boxes = [(t.get_text(), Text.get_window_extent(t, renderer)) for t in ax.texts
             if t.get_visible() and t.get_text()]
    points = [(c.get_label(), display_points(c)) for c in curves]
    bad = []
    for text, box in boxes:
        inner = box.padded(-0.5)
        for label, pts in points:
            inside = ((pts[:, 0] > inner.x0) & (pts[:, 0] < inner.x1) & (pts[:, 1] > inner.y0)
                      & (pts[:, 1] < inner.y1))
            if inside.any():
                bad.append((text, label))
    for i, (a, box_a) in enumerate(boxes):
        for b, box_b in boxes[i + 1:]:
            if box_a.padded(-0.5).overlaps(box_b.padded(-0.5)):
                bad.append((a, b))
    return bad


def test_fig22_no_label_is_drawn_over(fig22) -> None:
    """Regime labels, the hand's notes and the look-ahead note clear of the speed
    curves, the belt's, the regimes' averages and the LO/TD lines, and of each other."""
    from matplotlib.patches import StepPatch

    fig, _, _ = fig22
    ax = fig.axes[0]
    steps = [p for p in ax.patches if isinstance(p, StepPatch)]
    assert len(steps) == 2 and len(ax.collections) == 4 and len(ax.lines) == 2
    names = [t.get_text() for t in ax.texts]
    for r in ("R I ", "R II ", "R III ", "R IV "):
        assert any(n.startswith(r) and n[len(r):].replace(".", "").isdigit() for n in names), r
    assert any("fingers close" in n for n in names) and any("look-ahead lag" in n for n in names)
    assert covered(fig, [*steps, *ax.collections, *ax.lines]) == []


def test_fig09_no_name_is_drawn_over(captured: SimpleNamespace) -> None:
    fig = captured.figures[FILES[9]]
    ax = fig.axes[0]
    names = {t.get_text() for t in ax.texts}
    assert {"B", "F", "G", "K", "LO", "TD"} <= names
    assert covered(fig, list(ax.lines)) == []


@pytest.mark.parametrize("arrivals", [
    "{distribution: gamma, mean_s: 20, cv: 0.5}",
    "{distribution: weibull_min, mean_s: 20, cv: 0.5}",
    "{trace_csv: gaps.csv}"])
def test_figs_13_14_draw_the_arrivals_the_feeder_draws_from(tmp_path: Path, arrivals) -> None:
    """Fig. 13-14 for arrivals given by mean and cv (or a trace): the drawn curve is the
    distribution the run samples (its mean and cv as given), or none for a trace."""
    from cell.reporting.figures.interarrival import distribution, draws, fig13_pdf, fig14_cdf

    (tmp_path / "gaps.csv").write_text("interarrival_s\n" + "\n".join(["18.5", "24", "21"] * 20))
    f = tmp_path / "s.yaml"
    f.write_text(f"arrivals: {arrivals}\n")
    s = load_scenario(f)
    d = distribution(s)
    if "trace" in arrivals:
        assert d is None
    else:
        assert d.mean() == pytest.approx(20.0, rel=1e-9)
        assert d.std() / d.mean() == pytest.approx(0.5, rel=1e-6)
    x = draws(s, 400)
    for fig in (fig13_pdf, fig14_cdf):
        png = fig(s, x, tmp_path / f"{fig.__name__}.png")
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
