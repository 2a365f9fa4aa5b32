"""``cell schema [--out FILE]``: the JSON Schema of scenario files, for editors.

With the YAML language server (VS Code's YAML extension and others), a first
line ``# yaml-language-server: $schema=scenario.schema.json`` gives completion,
hover documentation and checking of every key while a scenario is edited.
"""

from __future__ import annotations

import argparse

HELP = "print the JSON Schema of scenario files (for editor completion and checking)"
DESCRIPTION = ("The JSON Schema of scenario files, for a YAML editor's completion, documentation "
               "and checking of every key; with --out, also the first line that makes a "
               "scenario use it.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default=None, metavar="FILE", help="write it to this file (default: print it)")


def editor_line(schema_file: str) -> str:
    """The first line of a scenario beside ``schema_file`` that names it to the YAML language server."""
    from pathlib import Path

    return f"# yaml-language-server: $schema={Path(schema_file).name}"


def main(args: argparse.Namespace) -> int:
    import json

    from cell.plumbing.output.atomic import check_file, write_text
    from cell.scenario.schema import json_schema

    if args.out is not None:
        check_file(args.out)  # before any work
    text = json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"
    if args.out is not None:
        write_text(text, args.out)
        print(f"wrote {args.out}; a scenario in the same folder that starts with the line\n"
              f"{editor_line(args.out)}\ngets completion and checking in a YAML editor")
    else:
        print(text, end="")
    return 0
