"""A sequence of nearby sparse linear systems solved with a kept factorisation.

Imports numpy, scipy and cholespy only; ``ddfv`` and ``baselines`` import it
(they may not import each other), see :mod:`kept_factor.nearby_systems`. What else
both share lives here too, imported by its module path: :mod:`kept_factor.threads`
(numba), the threads of the compiled kernels, theirs and the harness solver's.
"""

from .nearby_systems import (KeptFactorSolver, as_csr, cholesky_solve, factorise, family_blocks,
                             pinned)

__all__ = ["KeptFactorSolver", "as_csr", "cholesky_solve", "factorise", "family_blocks",
           "pinned"]
