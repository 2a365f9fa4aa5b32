"""The ``cell`` command: one module a subcommand."""
