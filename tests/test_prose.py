"""The suite asserts what a message is for, not its sentence (issue 31): at most 4 % of the test
functions hold a phrase of more than 40 characters in their assertions (tests/prose.py counts)."""

from __future__ import annotations

from pathlib import Path

from tests.prose import error_parts, in_order, prose_tests

#: The share of test functions that may assert a phrase: wording that is the contract (a column
#: name, a line a user pastes) and little else.
MOST = 0.04

LONG = "a phrase of well over forty characters, spaced"
SOURCE = f'''
import pytest

def helper():
    assert "{LONG}"  # not a test function: not counted

def test_constant():
    assert x == "{LONG}"

def test_fstring(n):
    assert f"{{n}} {LONG[:30]}{{n}}{LONG[30:]}" in x  # its literal parts, put together

def test_message_only():
    assert x, "{LONG}"

def test_outside_assert():
    y = "{LONG}"
    assert x == y

def test_no_space():
    assert x == "{"a" * 60}"

@pytest.mark.parametrize("v", [1, 2, 3])
def test_short(v):
    assert f"{{v}} short" in x

class TestGroup:
    def test_method(self):
        assert "{LONG}" in x

class Helper:
    def test_not_collected(self):
        assert "{LONG}" in x
'''


def test_few_test_functions_assert_a_phrase():
    offenders, total = prose_tests()
    assert total > 100 and len(offenders) <= MOST * total, "\n".join(offenders)


def test_the_count_is_of_test_functions_whose_assertions_hold_a_phrase(tmp_path: Path):
    (tmp_path / "test_sample.py").write_text(SOURCE)
    (tmp_path / "sample.py").write_text(SOURCE.replace("import pytest", "import os"))  # no test module
    offenders, total = prose_tests(tmp_path)
    assert total == 7  # a parametrised function is one; Helper is no test class
    assert [name.split("::")[1] for name in offenders] == ["test_constant", "test_fstring", "test_method"]


def test_in_order_and_the_parts_of_an_error_line():
    assert in_order("run.parts = -3: must be positive", "run.parts", "-3", "positive")
    assert not in_order("run.parts = -3: must be positive", "-3", "run.parts")
    line = error_parts("cell: error: my dir/s.yaml: run.parts = -3: must be a whole number > 0")
    assert line == ("my dir/s.yaml", "run.parts", "-3", "must be a whole number > 0")
