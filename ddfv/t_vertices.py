"""Initial positions of the T-vertices (Section 3, first paragraph).

``paper``
    "Projection of the barycenter to the sphere with mean curvature vector
    equal to (h1 + h2 + h3)/3": ``h`` at the F-vertices from the cotangent
    formula ``h_i = (1/A_i) sum_j (cot a_ij + cot b_ij)/2 (F_j - F_i)``
    (``A_i`` barycentric area), averaged over the triangle; the sphere of
    radius ``R = 2/|h|`` through the triangle's three vertices whose centre
    lies on the side ``h`` points to; the barycentre projected radially
    from that centre onto it. Flat triangles (``|h| rho < 1e-8``, ``rho``
    the circumradius) keep the barycentre; where ``R < rho`` no such sphere
    exists and ``R = rho`` is used. On open surfaces the cotangent formula
    does not give the curvature at boundary vertices: ``h`` is averaged
    over the triangle's interior vertices only, and a triangle with all
    three vertices on the boundary keeps its barycentre. Safe on real
    meshes: where the projected point's projection onto the triangle's plane
    would lie outside the triangle (the osculating sphere of a coarse or
    sharp-featured mesh is far from the surface; Section 2.2.2 requires the
    projection to lie in the triangle), or is not finite, the barycentre is
    kept instead (see ``ddfv/README.md``; on the icosphere no triangle falls
    back, so Table 3.1 is unchanged).
``barycenter``
    The barycentre of the triangle.
``exact``
    For spheres only: the barycentre projected radially onto the sphere
    centred at the mean of the F-vertices, of their mean distance to it.
"""

import igl
import numpy as np
import scipy.sparse as sp

from .geometry import t_barycentric

METHODS = ("paper", "barycenter", "exact")


def initial_t_vertices(F, mesh, method="paper"):
    """T-vertices for the mesh with F-vertices ``F``.

    Parameters
    ----------
    F : (n_f, 3) float array
    mesh : DiamondMesh
    method : {"paper", "barycenter", "exact"}

    Returns
    -------
    (n_t, 3) float array
    """
    faces = mesh.faces
    tri = F[faces]
    g = tri.mean(axis=1)
    if method == "barycenter":
        return g
    if method == "exact":
        centre = F.mean(axis=0)
        radius = np.linalg.norm(F - centre, axis=1).mean()
        d = g - centre
        return centre + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    if method != "paper":
        raise ValueError(f"unknown T-vertex initialisation {method!r}; "
                         f"choose one of {', '.join(METHODS)}")
    interior = ~mesh.boundary_vertices[faces]                  # (n_t, 3)
    h_corners = cotangent_mean_curvature_vector(F, faces)[faces]
    count = interior.sum(axis=1)
    h = (h_corners * interior[..., None]).sum(axis=1) / np.maximum(count, 1)[:, None]
    p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]
    a, b = p1 - p0, p2 - p0
    n = np.cross(a, b)
    nn = np.einsum("ij,ij->i", n, n)
    # circumcentre and circumradius of each triangle
    cc = p0 + np.cross(np.einsum("ij,ij->i", a, a)[:, None] * b
                       - np.einsum("ij,ij->i", b, b)[:, None] * a, n) / (2 * nn[:, None])
    rho = np.linalg.norm(cc - p0, axis=1)
    hnorm = np.linalg.norm(h, axis=1)
    curved = (hnorm * rho >= 1e-8) & (count > 0)
    R = np.where(curved, 2.0 / np.where(curved, hnorm, 1.0), 0.0)
    R = np.maximum(R, rho)
    side = np.sign(np.einsum("ij,ij->i", h, n))[:, None]
    centre = cc + side * np.sqrt(R**2 - rho**2)[:, None] * n / np.sqrt(nn)[:, None]
    d = g - centre
    projected = centre + R[:, None] * d / np.linalg.norm(d, axis=1, keepdims=True)
    inside = (t_barycentric(F, projected, faces).min(axis=1) >= 0.0) \
        & np.isfinite(projected).all(axis=1)
    return np.where((curved & inside)[:, None], projected, g)


def cotangent_mean_curvature_vector(F, faces):
    """Mean curvature vector ``h = M^{-1} L F`` at the F-vertices.

    ``L`` is the cotangent Laplacian (``igl.cotmatrix``) and ``M`` the
    barycentric lumped mass matrix; on a unit sphere ``h ~ -2 x``.

    Returns
    -------
    (n_f, 3) float array
    """
    L = igl.cotmatrix(F, faces)
    M = igl.massmatrix(F, faces, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    return sp.diags(1.0 / M.diagonal()) @ (L @ F)
