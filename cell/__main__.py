"""``python -m cell``: the same as the ``cell`` command."""

import sys

from cell.cli.main import main

sys.exit(main())
