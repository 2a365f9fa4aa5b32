"""The ``cell`` command's subcommands: each a thin shell that reads its input,
calls the package and writes its output whole or not at all.  Nothing below
this layer imports it."""
