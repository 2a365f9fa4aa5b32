"""Bad layouts (docs/layout.md) are refused in one line naming the file, the key and the value,
with exit code 2 and nothing written; a station's keys are named by the station's name, in the
file and on the command line (``--set stations.NAME.KEY``)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from cell.cli.main import main
from cell.scenario.schema import load_scenario

LINE = {"name": "line", "run": {"parts": 20},
        "stations": [{"name": "catcher", "placement": "downstream", "offset_in": 40.0},
                     {"name": "next", "placement": "series", "transfer_in": 60.0}]}


def _file(tmp_path: Path, **changes: object) -> Path:
    doc = {**LINE, **changes}
    path = tmp_path / "line.yaml"
    path.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return path


def _station(i: int, **keys: object) -> list[dict]:
    stations = [dict(s) for s in LINE["stations"]]
    stations[i].update(keys)
    return stations


CASES = {  # what is wrong -> (the file's changes, the key named, the value named)
    "negative places": ({"buffer": {"places": -1}}, "buffer.places", "-1"),
    "pitch shorter than the part": ({"buffer": {"places": 2, "pitch_in": 1.5}},
                                    "buffer.pitch_in", "1.5"),
    "downstream before the first": ({"stations": _station(0, offset_in=-5.0)},
                                    "stations.catcher.offset_in", "-5.0"),
    "arms would collide": ({"stations": _station(0, offset_in=1.0)},
                           "stations.catcher.offset_in", "1.0"),
    "transfer of zero length": ({"stations": _station(1, transfer_in=0.0)},
                                "stations.next.transfer_in", "0.0"),
    "a series pitch the part does not fit": (
        {"stations": _station(1, buffer={"places": 2, "pitch_in": 1.0})},
        "stations.next.buffer.pitch_in", "1.0"),
    "a series belt the part does not fit": ({"stations": _station(1, cell={"belt_width_in": 1.0})},
                                            "stations.next.cell.belt_width_in", "1.0"),
    "a station's own bad value": ({"stations": _station(0, controller={"ideal_cycle_s": -3.0})},
                                  "stations.catcher.controller.ideal_cycle_s", "-3.0"),
    "two stations of one name": ({"stations": _station(1, name="catcher")},
                                 "stations.catcher.name", "'catcher'"),
    "the first station's name": ({"stations": _station(0, name="first")},
                                 "stations.first.name", "'first'"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_bad_layout_is_one_line_naming_file_key_and_value(capsys, tmp_path, case):
    changes, key, value = CASES[case]
    path, out = _file(tmp_path, **changes), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert str(path) in err and f"{key} = {value}:" in err
    assert not out.exists() or not any(out.iterdir())


def test_set_addresses_a_station_by_its_name(capsys, tmp_path):
    path = _file(tmp_path)
    s = load_scenario(path, {"stations.catcher.controller.ideal_cycle_s": 21.0,
                             "stations.catcher.controller.policy": "non-adaptive"})
    assert s.get("stations.catcher.controller.ideal_cycle_s") == 21.0
    assert s.get("stations.next.controller.ideal_cycle_s") is None
    assert s.line[0][1].controller.policy == "non-adaptive"
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--set",
                 "stations.nobody.controller.ideal_cycle_s=21"]) == 2
    err = capsys.readouterr().err.strip()
    assert "stations.nobody.controller.ideal_cycle_s = 21" in err and "(--set)" in err
    assert not out.exists() or not any(out.iterdir())


def test_animate_refuses_both_policies_for_a_line(capsys, tmp_path):
    """cell animate draws a line's stations beside the first under one policy: --policy both
    with stations is refused in one line, exit 2, no file written (docs/layout.md)."""
    path = tmp_path / "line.yaml"
    path.write_text(yaml.safe_dump(LINE), encoding="utf-8")
    out = tmp_path / "line.gif"
    assert main(["animate", str(path), "--policy", "both", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--policy both" in err
    assert not out.exists()
