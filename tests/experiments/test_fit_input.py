"""``cell fit`` on files as a spreadsheet exports them, and its options' refusals: what
``cell fit`` reads agrees with what a run's trace reader (cell.scenario.arrivals.read_trace) reads."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.cli.fit import DESCRIPTION, add_arguments
from cell.cli.fit import main as cmd_fit
from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import MAX_INTERARRIVAL_S, read_trace


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args(list(argv))


def gaps(n: int = 60, seed: int = 5) -> np.ndarray:
    """Shifted-Weibull gaps (thesis eq. 6.9) by their own inverse cdf."""
    u = np.random.default_rng(seed).random(n)
    return 17.6019 + 5.4342 * (-np.log1p(-u)) ** 0.2038


def write(path: Path, text: str, encoding: str = "utf-8") -> Path:
    path.write_bytes(text.encode(encoding))
    return path


def fitted(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert cmd_fit(parse(*argv)) == 0
    return yaml.safe_load(capsys.readouterr().out)


def test_rows_of_empty_cells_are_skipped_as_the_trace_reader_skips_them(tmp_path: Path, capsys):
    """A spreadsheet saves its empty trailing rows as bare separators (',,'), with a BOM and
    CRLF: a run reads the same times as without them, and so does ``cell fit``."""
    x = gaps()
    rows = "".join(f"{i},{float(v)!r}\r\n" for i, v in enumerate(x, 1))
    plain = write(tmp_path / "plain.csv", "part,interarrival_s\n" + rows)
    excel = write(tmp_path / "excel.csv", "\ufeffpart,interarrival_s\r\n" + rows + ",\r\n , \r\n,\r\n",
                  "utf-8")
    assert read_trace(excel).tolist() == read_trace(plain).tolist() == x.tolist()
    assert fitted(capsys, str(excel)) == fitted(capsys, str(plain))


def test_rows_of_empty_cells_before_the_header_are_skipped_by_both_readers(tmp_path: Path, capsys):
    """Empty rows (',,') above the header: a run reads the times under it, and so does
    ``cell fit``, which takes the same row for the header (it took the first line)."""
    x = gaps()
    rows = "".join(f"{i},{float(v)!r}\n" for i, v in enumerate(x, 1))
    plain = write(tmp_path / "plain.csv", "part,interarrival_s\n" + rows)
    padded = write(tmp_path / "padded.csv", ",\n , \npart,interarrival_s\n" + rows)
    assert read_trace(padded).tolist() == x.tolist()
    assert fitted(capsys, str(padded)) == fitted(capsys, str(plain))


@pytest.mark.parametrize("rows", [
    "".join(f"{i};{v:.3f}\n" for i, v in enumerate(gaps(), 1)),
    "".join(f"{i};{v:.3f}\n".replace(".", ",") for i, v in enumerate(gaps(), 1)),
], ids=["decimal point", "decimal comma"])
def test_semicolon_separated_files_are_named_as_such(tmp_path: Path, rows: str):
    """A CSV saved with ';' between columns (a European spreadsheet's default) is refused by
    both readers with one line saying so, not pandas' complaint about field counts."""
    path = write(tmp_path / "semi.csv", "part;interarrival_s\n" + rows)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(tmp_path / "a.yaml")))
    assert err.value.file == str(path) and "';'" in err.value.why and "comma" in err.value.why
    assert "\n" not in str(err.value)
    with pytest.raises(ScenarioError) as err:
        read_trace(path)
    assert "';'" in err.value.why and "comma" in err.value.why
    assert sorted(p.name for p in tmp_path.iterdir()) == ["semi.csv"]


def test_a_decimal_comma_is_named(tmp_path: Path):
    values = [f"{v:.3f}" for v in gaps()]
    values[4] = '"21,5"'
    path = write(tmp_path / "t.csv", "interarrival_s\n" + "\n".join(values) + "\n")
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path)))
    assert (err.value.key, err.value.value) == ("interarrival_s[line 6]", "21,5")
    assert "decimal point" in err.value.why


def test_times_that_are_neither_seconds_nor_iso_say_what_is_accepted(tmp_path: Path):
    """--times takes seconds or ISO 8601 date-times; a log's '02.03.2026 08:15:04' is neither,
    and the message says so rather than 'not a number'."""
    t = np.cumsum(gaps())
    start = np.datetime64("2026-03-02T08:15:00", "s")
    stamps = [start + np.timedelta64(int(s), "s") for s in t]
    german = [f"{str(s)[8:10]}.{str(s)[5:7]}.{str(s)[:4]} {str(s)[11:]}" for s in stamps]
    path = write(tmp_path / "t.csv", "stamp\n" + "\n".join(german) + "\n")
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--column", "stamp", "--times"))
    assert (err.value.key, err.value.value) == ("stamp[line 2]", german[0])
    assert "ISO" in err.value.why and "seconds" in err.value.why


@pytest.mark.parametrize("times", [False, True], ids=["gaps", "arrival times"])
def test_gaps_a_run_would_refuse_are_refused(tmp_path: Path, times: bool):
    """A run refuses a trace gap over MAX_INTERARRIVAL_S; ``cell fit`` refuses it too, naming
    the row, instead of writing an arrivals block whose mean no scenario accepts."""
    x = gaps()
    x[6] = 2.0 * MAX_INTERARRIVAL_S
    column = np.concatenate([[0.0], np.cumsum(x)]) if times else x
    path = write(tmp_path / "t.csv", "interarrival_s\n" + "".join(f"{float(v)!r}\n" for v in column))
    out = tmp_path / "a.yaml"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(out), *(["--times"] if times else [])))
    assert err.value.key == ("interarrival_s[line 9]" if times else "interarrival_s[line 8]")
    assert f"{MAX_INTERARRIVAL_S:g}" in err.value.why
    assert not out.exists()


def test_figure_must_be_a_png(tmp_path: Path):
    """The figure is a PNG whatever its name; a .pdf or .svg name is refused, not filled with PNG."""
    path = write(tmp_path / "t.csv", "interarrival_s\n" + "".join(f"{float(v)!r}\n" for v in gaps()))
    for name in ("fit.pdf", "fit.svg", "fit"):
        with pytest.raises(ScenarioError) as err:
            cmd_fit(parse(str(path), "--figure", str(tmp_path / name)))
        assert (err.value.key, err.value.value) == ("--figure", str(tmp_path / name))
        assert ".png" in err.value.why
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_out_named_png_names_out(tmp_path: Path):
    """--out fit.png puts the figure (fit.png, beside --out) on --out itself: the message names
    --out, which the user gave, and says how to get out of it."""
    path = write(tmp_path / "t.csv", "interarrival_s\n" + "".join(f"{float(v)!r}\n" for v in gaps()))
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(tmp_path / "fit.png")))
    assert err.value.key == "--out" and "--figure" in err.value.why
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_help_describes_the_command_in_whole_sentences():
    assert DESCRIPTION.endswith(".") and DESCRIPTION[0].isupper()
    done = subprocess.run([sys.executable, "-m", "cell", "fit", "--help"], capture_output=True,
                          text=True, check=True)
    assert " ".join(DESCRIPTION.split()) in " ".join(done.stdout.split())


def test_a_header_name_with_spaces_around_it_is_the_column(tmp_path):
    """As a run's trace reader takes it: ' interarrival_s' (a space after the comma) is the
    column; two columns of that name are refused rather than one chosen, by both readers (pandas
    would have read a second 'interarrival_s' as 'interarrival_s.1' and fitted the first)."""
    from cell.experiments.fit.column import read_column

    gaps = [20.0 + 0.5 * (i * 7 % 11) for i in range(30)]  # not sorted: gaps, not times
    path = tmp_path / "log.csv"
    path.write_text("part, interarrival_s \n" + "".join(f"{i},{g}\n" for i, g in enumerate(gaps)))
    assert read_column(path).tolist() == gaps
    for header in ("interarrival_s, interarrival_s", "interarrival_s,interarrival_s"):
        path.write_text(f"{header}\n" + "".join(f"{g},{g + 1}\n" for g in gaps))
        with pytest.raises(ScenarioError, match="two columns are named interarrival_s"):
            read_column(path)
        with pytest.raises(ScenarioError, match="two columns are named interarrival_s"):
            read_trace(path)


@pytest.mark.parametrize("times", [False, True], ids=["gaps", "arrival times"])
def test_zero_gaps_are_refused_with_their_count(tmp_path: Path, times: bool):
    """A log stamped to the second has zero gaps, which a run replays but no continuous family
    fits (Weibull, gamma and lognorm have no likelihood there; dropping them would lengthen
    the mean): ``cell fit`` refuses them in one line, counting them and naming the first."""
    stamps = np.floor(np.cumsum(np.concatenate([gaps(60), [0.4, 0.3, 0.2]])))
    stamps = np.sort(np.concatenate([stamps, stamps[[10, 40]]]))  # two more parts in a second
    step = np.diff(stamps, prepend=0.0)
    zeros = int((step == 0).sum())
    assert zeros >= 3
    column = stamps if times else step
    path = write(tmp_path / "log.csv", "interarrival_s\n" + "".join(f"{v:.0f}\n" for v in column))
    out = tmp_path / "a.yaml"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(out), *(["--times"] if times else [])))
    first = int(np.flatnonzero(step == 0)[0])
    assert err.value.key == f"interarrival_s[line {first + 2}]"
    assert f"{zeros} of {column.size - times} gaps are 0" in err.value.why
    assert ("the same time as line" in err.value.why) == times
    assert "more finely" in err.value.why and "arrivals.trace_csv" in err.value.why
    assert "\n" not in str(err.value) and not out.exists()
    if not times:
        assert read_trace(path).tolist() == column.tolist()  # a run replays them as they are


def test_both_readers_name_the_same_file_line(tmp_path: Path):
    """A bad value is named by its line in the file (the header's is 1, as a spreadsheet numbers
    rows; blank lines before it counted), by ``cell fit`` and by a run's trace reader alike, and
    both read a quoted field after a space ('1, "20"') as the number."""
    values = [f'"{v:.3f}"' for v in gaps()]
    values[9] = "-2.5"
    path = write(tmp_path / "t.csv", "\n\npart, interarrival_s\n" +
                 "".join(f"{i}, {v}\n" for i, v in enumerate(values, 1)))
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path)))
    assert (err.value.key, err.value.value) == ("interarrival_s[line 13]", "-2.5")
    with pytest.raises(ScenarioError, match="line 13 has inter-arrival time '-2.5'"):
        read_trace(path)
    write(path, path.read_text().replace("-2.5", "21.5"))
    from cell.experiments.fit.column import read_column

    assert read_column(path).tolist() == read_trace(path).tolist()


def test_a_blank_line_between_readings_is_refused_as_by_the_trace_reader(tmp_path: Path):
    """A PLC export's empty line is a missing reading: ``cell fit`` refuses it as a run does,
    naming its line, rather than fit gaps shifted by one part from there on."""
    rows = [f"{i},{float(v)!r}\n" for i, v in enumerate(gaps(), 1)]
    rows.insert(30, ",\n")
    path = write(tmp_path / "t.csv", "part,interarrival_s\n" + "".join(rows))
    out = tmp_path / "a.yaml"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(out)))
    assert err.value.key == "(file)" and err.value.why.startswith("line 32 is blank and readings follow")
    with pytest.raises(ScenarioError) as err:
        read_trace(path)
    assert err.value.why.startswith("line 32 is blank and readings follow")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]
