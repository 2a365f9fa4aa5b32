"""The commands' tests here share the reporting tests' figure stand-ins."""

from tests.reporting.conftest import unlaid  # noqa: F401 (a fixture, found by pytest here)
