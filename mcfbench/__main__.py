"""``python -m mcfbench``: see :mod:`mcfbench.cli`."""

import sys

from mcfbench.cli import main

sys.exit(main())
