"""``python -m ddfv``: the harness's command line (``python -m mcfbench``), kept as an alias.

The one place where the scheme package reaches the harness: run only as a
program, never by ``import ddfv``.
"""

import sys

from mcfbench.cli import main

sys.exit(main())
