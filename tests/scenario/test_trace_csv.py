"""A trace CSV read without pandas (cell.scenario.arrivals.read_trace): the floats written, the
columns and rows a spreadsheet saves, and one line on what cannot be used."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import read_trace


def _trace(tmp_path: Path, text: str, name: str = "trace.csv") -> Path:
    path = tmp_path / name
    path.write_bytes(text.encode("utf-8"))
    return path


def test_values_are_the_decimal_numbers_written(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    written = [repr(float(v)) for v in rng.uniform(1e-3, 1e5, 200)] + ["1e3", ".5", "5.", "+7", "0.1"]
    times = read_trace(_trace(tmp_path, "interarrival_s\n" + "\n".join(written) + "\n"))
    assert times.tolist() == [float(w) for w in written]  # correctly rounded, as Python reads them
    assert not times.flags.writeable


def test_other_columns_quotes_spaces_blank_lines_bom_and_crlf(tmp_path: Path) -> None:
    text = '\ufeff\r\npart,interarrival_s\r\nA, 20.5 \r\nB,"23.25"\r\nC,21\r\n\r\n   \r\n,\r\n'
    assert read_trace(_trace(tmp_path, text)).tolist() == [20.5, 23.25, 21.0]


@pytest.mark.parametrize("text, line", [
    ("interarrival_s\n20\n\n25\n\n", 3),
    ("interarrival_s\n\n20\n25\n", 2),
    ("part,interarrival_s\r\n1,20\r\n2,21\r\n,\r\n   \r\n4,25\r\n", 4),
])
def test_a_blank_line_between_readings_is_a_missing_reading(tmp_path: Path, text: str, line: int) -> None:
    """Skipping it would shift every later gap by one part: refused, naming its line."""
    with pytest.raises(ScenarioError) as info:
        read_trace(_trace(tmp_path, text))
    assert info.value.why.startswith(f"line {line} is blank") and "a missing reading" in info.value.why
    assert "remove the line or fill it" in info.value.why


@pytest.mark.parametrize("text, words", [
    ("", "not a readable CSV"),
    ("time\n20\n", "needs a column named interarrival_s (found 'time')"),
    ("a,b,c,d,e,f\n1,2,3,4,5,6\n", "(found 'a', 'b', 'c', 'd', 'e', ...)"),
    ("interarrival_s\n", "has no inter-arrival times"),
    ("interarrival_s\n20\n1_000\n", "line 3 has inter-arrival time '1_000'"),
    ("interarrival_s\n20\n0x10\n", "line 3 has inter-arrival time '0x10'"),
    ("interarrival_s\n20\nnan\n", "line 3 has inter-arrival time 'nan'"),
    ("interarrival_s\n20\n\u0661\u0662\n", "line 3 has inter-arrival time '\u0661\u0662'"),
    ("interarrival_s\n20\n\uff12\uff10\n", "line 3 has inter-arrival time '\uff12\uff10'"),
    ("interarrival_s\n20\n-0.5\n", "line 3 has inter-arrival time '-0.5'; times must be 0 or positive"),
    ("interarrival_s\n0\n0.0\n0e3\n", "all 3 inter-arrival times are 0; their mean must be positive"),
    ("interarrival_s\n2e6\n", "line 2 has inter-arrival time '2e6'"),
    ("a,interarrival_s\nx,20\ny\n", "line 3 has inter-arrival time ''"),
    ("interarrival_s\n20\n21,22\n", "not a readable CSV: line 3 has 2 fields, the header 1"),
    ("interarrival_s,interarrival_s\n20,30\n", "two columns are named interarrival_s: keep one"),
    ("interarrival_s, interarrival_s \n20,30\n", "two columns are named interarrival_s: keep one"),
    ("part;interarrival_s\n1;20,5\n", "the columns are separated by ';'"),
])
def test_unusable_traces_are_one_line_naming_file_and_key(tmp_path: Path, text: str, words: str) -> None:
    path = _trace(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        read_trace(path)
    message = str(info.value)
    assert message.startswith(f"{path}: arrivals.trace_csv = ") and words in message, message
    assert "\n" not in message


@pytest.mark.parametrize("text, line", [
    ("interarrival_s\n20\n-5\n25\n", 3),
    ("\ufeffinterarrival_s\r\n20\r\n-5\r\n", 3),
    ("\n\ninterarrival_s\n20\n21\n-5\n", 6),
    ('note,interarrival_s\n"two\nlines",20\nc,-5\n', 4),
])
def test_a_bad_value_is_named_by_its_line_in_the_file(tmp_path: Path, text: str, line: int) -> None:
    """The line a text editor shows, and the row number a spreadsheet shows: the header is
    line 1 (blank lines before it counted), and a quoted field across lines counts them all."""
    with pytest.raises(ScenarioError) as info:
        read_trace(_trace(tmp_path, text))
    assert f"line {line} has inter-arrival time '-5'" in info.value.why


def test_zero_gaps_are_parts_stamped_in_the_same_second(tmp_path: Path) -> None:
    """A line's log stamped to the second has 0 between two parts of the same second."""
    assert read_trace(_trace(tmp_path, "interarrival_s\n0\n21\n0.0\n-0\n19\n")).tolist() == \
        [0.0, 21.0, 0.0, 0.0, 19.0]


def test_a_header_name_with_spaces_around_it_is_the_column(tmp_path: Path) -> None:
    """Spreadsheets and hand-edited files leave a space after the comma: ' interarrival_s'."""
    assert read_trace(_trace(tmp_path, "part, interarrival_s \n1,20\n2,22.5\n")).tolist() == [20.0, 22.5]


def test_a_quoted_field_after_a_space_is_still_quoted(tmp_path: Path) -> None:
    """'part, "interarrival_s"': the quotes after the comma's space enclose the field."""
    text = 'part, "interarrival_s "\r\n1, "20"\r\n2, 22.5\r\n'
    assert read_trace(_trace(tmp_path, text)).tolist() == [20.0, 22.5]


def test_a_file_that_is_not_utf8_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "trace.csv"
    path.write_bytes(b"interarrival_s\n\xff\xfe20\n")
    with pytest.raises(ScenarioError, match="not a readable CSV"):
        read_trace(path)


def test_reading_a_trace_does_not_import_pandas(tmp_path: Path) -> None:
    path = _trace(tmp_path, "interarrival_s\n20.5\n21\n")
    code = ("import sys; from pathlib import Path; from cell.scenario.arrivals import read_trace; "
            f"print(read_trace(Path({str(path)!r})).tolist(), 'pandas' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          env={"CELL_NO_CACHE": "1", "PATH": ""})
    assert done.stdout.split() == ["[20.5,", "21.0]", "False"]
