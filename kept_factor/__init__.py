"""A sequence of nearby sparse linear systems solved with a kept factorisation.

Imports numpy, scipy and cholespy only; ``ddfv`` and ``baselines`` import it
(they may not import each other), see :mod:`kept_factor.nearby_systems`.
"""

from .nearby_systems import (KeptFactorSolver, as_csr, cholesky_solve, factorise, family_blocks,
                             pinned)

__all__ = ["KeptFactorSolver", "as_csr", "cholesky_solve", "factorise", "family_blocks",
           "pinned"]
