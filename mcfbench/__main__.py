"""``python -m mcfbench``: see :mod:`mcfbench.cli`."""

import sys

from .cli import main

sys.exit(main())
