"""The cotangent stiffness and the lumped mass of a triangulated surface.

The operators of the vertex-based baselines: the cotangent stiffness ``L``
(``-igl.cotmatrix``), symmetric and positive semi-definite (Pinkall and
Polthier 1993, the cotangent formula, (C2) of :mod:`baselines.cotan`)::

    (L X)_i = 1/2 sum_j (cot alpha_ij + cot beta_ij) (X_i - X_j)      (C2)

and the lumped mass ``M``: barycentric, ``M_ii = 1/3 sum_{T ni i} |T|``, or
Voronoi/mixed (Meyer, Desbrun, Schroeder, Barr 2003, Section 3.3;
``igl.MASSMATRIX_TYPE_VORONOI``); libigl's functions
(:func:`cotangent_laplacian`, :func:`lumped_mass`) are the reference, and
:class:`CotanAssembler` writes both with one compiled loop over the
triangles (:func:`baselines.kernels.cotan_geometry`) into a CSR pattern
built once (:func:`baselines.mesh.laplacian_pattern`), with the row-scaled
system (C3) ``I + tau diag(1/M) L`` (:func:`row_scaled_matrix`) and its
Dirichlet rows (:func:`dirichlet_rows`).
"""

import copy
from dataclasses import dataclass
from functools import cached_property

import igl
import numpy as np
import scipy.sparse as sp

from kept_factor.threads import for_threads

from .kernels import (cotan_geometry, gather_geometry, gather_normals, row_scaled_system,
                      triangle_terms, vertex_normals)
from .mesh import laplacian_pattern

MASS_TYPES = {"barycentric": igl.MASSMATRIX_TYPE_BARYCENTRIC,
              "voronoi": igl.MASSMATRIX_TYPE_VORONOI}


def cotangent_laplacian(vertices, faces):
    """Cotangent stiffness matrix ``L = -igl.cotmatrix`` (pos. semi-def.), (C2).

    The libigl reference of :meth:`CotanAssembler.laplacian`.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
        Symmetric, zero row sums, positive diagonal.
    """
    V, F = _igl_arrays(vertices, faces)
    return (-igl.cotmatrix(V, F)).tocsr()


def lumped_mass(vertices, faces, mass="barycentric"):
    """Diagonal of the lumped mass matrix ``igl.massmatrix``.

    The libigl reference of :meth:`CotanAssembler.geometry`.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    mass : {"barycentric", "voronoi"}
        Barycentric: ``M_ii = 1/3 sum_{T ni i} |T|``; Voronoi: mixed
        Voronoi areas (Meyer et al. 2003). Both sum to the surface area.

    Returns
    -------
    (n,) float array
    """
    V, F = _igl_arrays(vertices, faces)
    return np.asarray(igl.massmatrix(V, F, MASS_TYPES[_mass_type(mass)]).diagonal())


def _igl_arrays(vertices, faces):
    return (np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(faces, dtype=np.int64))


def _mass_type(mass):
    if mass not in MASS_TYPES:
        raise ValueError(f"unknown mass {mass!r}; choose one of {', '.join(MASS_TYPES)}")
    return mass


@dataclass(frozen=True)
class SurfaceGeometry:
    """What one state of a surface contributes to a step.

    Attributes
    ----------
    L_data : (nnz,) float array or None
        Values of the stiffness ``L`` (C2) in the pattern of the assembler
        (None when not computed).
    mass : (n,) float array
        Lumped mass ``M_ii``.
    area_vectors : (m, 3) float array
        ``(x_1 - x_0) x (x_2 - x_0)`` per triangle (twice the area times
        the unit normal).
    degenerate : int
        Triangles of zero (or non-finite) area, left out of ``L`` and the
        mass by the kernel instead of dividing by zero.
    first_degenerate : int
        The first of them, ``-1`` if none.
    """

    L_data: np.ndarray
    mass: np.ndarray
    area_vectors: np.ndarray
    degenerate: int = 0
    first_degenerate: int = -1


class CotanAssembler:
    """``L`` (C2), ``M`` and the system matrix (C3) on a fixed mesh, compiled.

    The CSR pattern of ``L`` (edges and diagonal) is built once; every call
    runs :func:`baselines.kernels.cotan_geometry` (one loop over the
    triangles) and writes into fresh arrays laid out by that pattern.

    Parameters
    ----------
    mesh : baselines.mesh.EdgeMesh
    mass : {"barycentric", "voronoi"}

    Examples
    --------
    >>> from baselines.mesh import edge_mesh
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> F = np.array([[0, 1, 2]])
    >>> asm = CotanAssembler(edge_mesh(F, 3))
    >>> g = asm.geometry(V)
    >>> asm.laplacian(g.L_data).toarray().round(3).tolist()
    [[1.0, -0.5, -0.5], [-0.5, 0.5, 0.0], [-0.5, 0.0, 0.5]]
    >>> g.mass.round(4).tolist()
    [0.1667, 0.1667, 0.1667]
    """

    def __init__(self, mesh, mass="barycentric"):
        self.mesh = mesh
        self.mass_type = _mass_type(mass)
        self.pattern = laplacian_pattern(mesh)
        p = self.pattern
        self._matrix = sp.csr_matrix((np.zeros(p.nnz), p.indices, p.indptr), shape=p.shape)

    @property
    def shape(self):
        return self.pattern.shape

    @cached_property
    def corners(self):
        """``(corners_ptr, corners)``: the corners ``3 t + c`` of the triangles at each
        vertex, ``t`` increasing, as CSR ((n + 1,) and (3 m,) int64 arrays): the
        threaded assembly's gathers (:func:`baselines.kernels.gather_geometry`)."""
        faces = self.mesh.faces.ravel()
        counts = np.bincount(faces, minlength=self.mesh.n_vertices)
        return (np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
                np.argsort(faces, kind="stable").astype(np.int64))

    def geometry(self, vertices, with_laplacian=True, threads=1):
        """Stiffness, lumped mass and area vectors of ``vertices``.

        Parameters
        ----------
        vertices : (n, 3) float array
        with_laplacian : bool
            Compute ``L`` (False: ``L_data`` is None).
        threads : int
            One: :func:`baselines.kernels.cotan_geometry`'s scatter over the
            triangles. More: its two passes split over the threads, the triangles'
            terms then each vertex's sums (:func:`baselines.kernels.triangle_terms`,
            :func:`baselines.kernels.gather_geometry`), bitwise the same numbers.

        Returns
        -------
        SurfaceGeometry
        """
        p, mesh = self.pattern, self.mesh
        L_data = np.empty(p.nnz) if with_laplacian else np.empty(0)
        mass = np.empty(mesh.n_vertices)
        area_vectors = np.empty((mesh.n_faces, 3))
        # Fortran order: the flows' (n, 3) views of their (3, n) states as they are (a
        # C-ordered copy of them took 15 us of a 110 us pass at 3 000 vertices), one
        # compiled version for every caller
        V = np.asfortranarray(vertices, dtype=np.float64)
        voronoi = self.mass_type == "voronoi"
        if threads == 1:
            degenerate, first = cotan_geometry(V, mesh.faces, p.corner_slots, p.diag_slots,
                                               voronoi, with_laplacian, L_data, mass,
                                               area_vectors)
        else:
            m = mesh.n_faces
            half_cot, corner_mass, live = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, bool)
            degenerate, first = for_threads(triangle_terms, threads)(
                V, mesh.faces, voronoi, half_cot, corner_mass, area_vectors, live)
            first = -1 if first == m else first
            for_threads(gather_geometry, threads)(
                *self.corners, p.corner_slots, p.indptr, p.diag_slots, half_cot,
                corner_mass, live, with_laplacian, L_data, mass)
        return SurfaceGeometry(L_data if with_laplacian else None, mass, area_vectors,
                               int(degenerate), int(first))

    def normals(self, area_vectors, threads=1):
        """(n, 3) mass-lumped vertex normals ``sum N_t / sum |N_t|`` of the triangles'
        ``area_vectors`` (:func:`baselines.kernels.vertex_normals`; with more than one
        thread :func:`baselines.kernels.gather_normals`, bitwise the same)."""
        omega = np.empty((self.mesh.n_vertices, 3))
        if threads == 1:
            vertex_normals(self.mesh.faces, area_vectors, self.mesh.n_vertices, omega)
        else:
            for_threads(gather_normals, threads)(*self.corners, area_vectors, omega)
        return omega

    def csr(self, data):
        """A CSR matrix with the pattern of ``L`` and values ``data`` (not copied):
        :func:`with_values` of a matrix of the pattern built once."""
        return with_values(self._matrix, data)

    def laplacian(self, L_data):
        """``L`` (C2) as CSR from :attr:`SurfaceGeometry.L_data`."""
        return self.csr(L_data)

    def row_scaled(self, L_data, mass, tau, fixed, threads=1):
        """``I + tau diag(1/M) L`` (C3) as CSR; rows ``fixed`` = identity.

        Parameters
        ----------
        L_data : (nnz,) float array
        mass : (n,) float array
        tau : float
        fixed : (n,) bool array
        threads : int
            The rows split over them (bitwise the same values).
        """
        p = self.pattern
        data = np.empty(p.nnz)
        for_threads(row_scaled_system, threads)(L_data, p.indptr, p.diag_slots, mass,
                                                float(tau), fixed, data)
        return self.csr(data)


def with_values(matrix, data):
    """A shallow copy of the CSR ``matrix`` with the values ``data`` (not copied).

    The pattern's arrays are shared, as scipy's constructor with ``copy=False`` shares
    them, without its checks of the pattern (about 30 us a step for the (n, n)
    systems, 40 us for BGN's (3n, 3n), at 3 000 vertices: a few per cent of a step on
    the small meshes of a steady-state problem).
    """
    A = copy.copy(matrix)
    A.data = data
    return A


def row_scaled_matrix(L, mass, dt, fixed):
    """``I + dt diag(1/M) L`` (C3) of any sparsity, CSR, rows ``fixed`` = identity.

    Parameters
    ----------
    L : (n, n) scipy.sparse matrix
        A stiffness (not changed).
    mass : (n,) float array
        Its lumped mass, positive.
    dt : float
    fixed : (n,) bool array

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
    """
    L = sp.csr_matrix(L, copy=True)
    L.data *= np.repeat(dt / mass, np.diff(L.indptr))
    A = (L + sp.identity(L.shape[0], format="csr")).tocsr()
    return dirichlet_rows(A, fixed) if fixed.any() else A


def dirichlet_rows(A, fixed):
    """Replace the rows ``fixed`` of a CSR matrix by rows of the identity, in place.

    Parameters
    ----------
    A : (n, n) scipy.sparse.csr_matrix
        Must store its diagonal entries.
    fixed : (n,) bool array

    Returns
    -------
    A
    """
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    slots = np.flatnonzero(fixed[rows])
    A.data[slots] = (A.indices[slots] == rows[slots]).astype(A.dtype)
    return A
