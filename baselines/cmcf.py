"""Conformalized mean curvature flow (Kazhdan, Solomon, Ben-Chen 2012).

M. Kazhdan, J. Solomon, M. Ben-Chen, "Can mean-curvature flow be modified
to be non-singular?", Comput. Graph. Forum 31(5) (2012) 1745-1754,
Section 4: the cotangent scheme of :mod:`baselines.cotan` with the
stiffness matrix of the INITIAL surface kept and only the lumped mass
rebuilt::

    (M^{n-1} + tau L^0) X^n = M^{n-1} X^{n-1}                          (K1)

solved, like the cotangent scheme, in the row-scaled form

    (I + tau diag(1 / M^{n-1}) L^0) X^n = X^{n-1}                       (K2)

with Dirichlet identity rows for the boundary vertices. No rescaling or
re-centring: libigl's tutorial 205, pmp's ``implicit_smoothing`` and CGAL's
``smooth_shape`` add one (area or volume normalisation) after each step,
which is not part of the flow.

On a sphere the flow is again the shrinking sphere ``r(t)^2 = R^2 - 4 t``:
the cotangent weights are invariant under scaling, so for a uniformly
scaled copy ``X = s X^0`` one has ``L(X) = L^0`` and (K1) coincides with
(C1) of :mod:`baselines.cotan`; the two schemes differ only through the
departure of the discrete surface from a scaled copy of the initial mesh.
With a fixed boundary the steady state is the discrete harmonic map of the
initial surface (``L^0 X = 0`` at interior vertices), not a minimal
surface: a cylinder ``r = 1, |z| <= h`` (flat, parametrised by arc length)
tends to ``r(z) = cosh(z) / cosh(h)``, not to the catenoid.
"""

from .cotan import CotanFlow
from .laplacian import cotangent_laplacian


class CMCFFlow(CotanFlow):
    """Conformalized mean curvature flow (K1) of one triangulated surface.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``; its cotangent stiffness ``L^0`` is kept.
    faces : (m, 3) int array
    tau : float
    mass : {"barycentric", "voronoi"}
        Lumped mass, rebuilt every step (see :func:`baselines.laplacian.lumped_mass`).
    assembly : {"cached", "igl"}
        As in :class:`baselines.cotan.CotanFlow`.
    """

    def __init__(self, vertices, faces, tau, *, mass="barycentric", assembly="cached"):
        super().__init__(vertices, faces, tau, mass=mass, assembly=assembly)
        if assembly == "igl":
            self._L0 = cotangent_laplacian(self._X.T, self.faces)
        else:
            self._L0_data = self.assembler.geometry(self._X.T).L_data
            self._L0_data.flags.writeable = False

    def _needs_laplacian(self):
        return False  # only the mass changes from step to step

    def laplacian(self, at=None):
        """``L^0`` (C2) of the initial surface, CSR (a fresh copy), whatever the state."""
        if self.assembly == "igl":
            return self._L0.copy()
        return self.assembler.laplacian(self._L0_data.copy())

    def _laplacian_data(self, geometry):
        return self._L0_data
