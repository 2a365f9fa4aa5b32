"""``cell fit`` never writes a block ``cell run`` would refuse: each candidate block is read
back as a scenario file's text is (:func:`cell.scenario.yamlio.parse_value`) and validated as a
scenario holding it (:func:`cell.scenario.schema.validate`, with the defaults merged in as
:func:`cell.scenario.schema.load_scenario` merges them), before anything is written."""

from __future__ import annotations

import textwrap
from typing import Any

from cell.plumbing.errors import ScenarioError

#: The blocks ``cell fit --as`` writes, and where each goes in a scenario.
BLOCKS = ("arrivals", "time_to_failure", "time_to_repair")
#: The equipment a time to failure or repair is checked under (any would do: the rules are
#: the same for each).
CHECKED_UNDER = "robot"


def _scenario_text(block: str, key: str) -> str | None:
    """A scenario's text holding ``block`` (a ``key:`` block), or None when this build has no
    section to hold it (a ``failures:`` section: then :func:`scenario_refuses` has nothing
    to add to :func:`cell.experiments.fit.choice.unusable`)."""
    if key == "arrivals":
        return block
    from cell.scenario.schema import is_section

    if not is_section(("failures",)):
        return None
    body = "".join(line + "\n" for line in block.splitlines() if not line.startswith("#"))
    other = "time_to_repair" if key == "time_to_failure" else "time_to_failure"
    both = body + body.replace(f"{key}:", f"{other}:", 1)  # the other time as the same fit
    return f"failures:\n  {CHECKED_UNDER}:\n" + textwrap.indent(both, "    ")


def scenario_refuses(block: str, key: str, file: object) -> str:
    """Why a scenario holding ``block`` would be refused (the refusal's own words, naming
    the key), or "" when it is accepted; ``file`` names it in the error."""
    from cell.scenario.overrides import merge
    from cell.scenario.schema import default_scenario, is_section, validate
    from cell.scenario.yamlio import parse_value

    text = _scenario_text(block, key)
    if text is None:
        return ""
    try:
        given: Any = parse_value(text, str(file))
        validate(merge(default_scenario().to_dict(), given, (), is_section), file)
    except ScenarioError as exc:
        return f"{exc.key} refused: {exc.why}"
    return ""
