"""The overload warning names a named grid value by its name, as the nominal-cycle warning
does, not by its raw mapping."""

from cell.experiments.sweep import load_sweep
from cell.experiments.sweep.spec import overload_warning
from tests.prose import in_order

FAST = {"c": 4.906771344455348, "loc": 5.0, "scale": 5.4342}  # mean ~10 s: overloaded
THESIS = {"c": 4.906771344455348, "loc": 17.6019, "scale": 5.4342}


def test_overload_warning_names_a_named_value(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path, policies=["adaptive"],
                                    grid={"arrivals.params": {"thesis": THESIS, "rush": FAST}},
                                    set={"run.parts": 20}))
    line = overload_warning(sweep)
    assert line is not None and line.startswith("1 of 2 points ")
    assert in_order(line, "offered load 1 or more", "at arrivals.params rush)")
    assert "at arrivals.params rush)" in line
    assert "loc" not in line and "{" not in line
