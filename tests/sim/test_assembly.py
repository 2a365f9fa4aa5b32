"""cell.sim.assembly: importing it reads no scenario file and builds no scenario (the thesis's cell,
against which a changed key is blamed, is taken when first needed)."""

from __future__ import annotations

import subprocess
import sys

AUDIT = """
import sys
opened = []
sys.addaudithook(lambda event, args: opened.append(str(args[0])) if event == "open" else None)
import cell.sim.assembly
print([p for p in opened if p.endswith((".yaml", ".yml"))])
from cell.scenario import catalog
from cell.scenario.schema import load_scenario
load_scenario(catalog.path("baseline"))
print([p for p in opened if p.endswith((".yaml", ".yml"))][:1])
"""


def test_importing_assembly_reads_no_yaml_file():
    out = subprocess.run([sys.executable, "-c", AUDIT], capture_output=True, text=True, check=True).stdout
    at_import, after_first_use = out.splitlines()
    assert at_import == "[]"
    assert "baseline.yaml" in after_first_use      # the audit sees a read when there is one
