"""Fields of the saved frames of a run, for viewing them (ParaView, animations).

Per frame ``k`` of a trajectory (frame 0 the initial surface):

``displacement``
    ``X^k - X^{k-1}`` per point, (n, 3); zero at frame 0. With frames kept
    every ``K`` steps it is the motion over those ``K`` steps.
``vertex_area`` (the vertex schemes)
    Barycentric vertex area, a third of each triangle at the vertex
    (:func:`mcfbench.geometry.metrics.lumped_mass`; the cotangent scheme's
    ``barycentric`` mass).
``covolume`` (DDFV, F- and T-vertices)
    ``chi(V_i^F)``, ``chi(V_j^T)``: the covolume areas of Section 2.2.4, by
    the scheme's own function (:func:`ddfv.geometry.covolume_areas`).
``t_monitor`` (DDFV, per triangle and per T-vertex)
    The smallest barycentric coordinate of the T-vertex projected into its
    triangle (:func:`ddfv.geometry.t_barycentric`): ``1/3`` at the
    barycentre, negative once it has left the triangle (status
    ``t_escaped``, Section 3.2).

The DDFV functions compile on first use (numba's cache afterwards).
"""

import numpy as np

from mcfbench.geometry.metrics import lumped_mass


def displacements(frames):
    """``X^k - X^{k-1}`` of stacked frames, zero for frame 0.

    Parameters
    ----------
    frames : (frames, n, 3) float array

    Returns
    -------
    (frames, n, 3) float array
    """
    frames = np.asarray(frames, dtype=np.float64)
    if frames.ndim != 3 or frames.shape[2] != 3:
        raise ValueError(f"frames must be a (frames, n, 3) array, got shape {frames.shape}")
    out = np.zeros_like(frames)
    out[1:] = np.diff(frames, axis=0)
    return out


def vertex_frame_fields(V, faces):
    """Point fields of each frame of a vertex scheme.

    Parameters
    ----------
    V : (frames, n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    list of dict
        Per frame ``{"displacement": (n, 3), "vertex_area": (n,)}``.
    """
    moved = displacements(V)
    return [{"displacement": moved[k], "vertex_area": lumped_mass(V[k], faces)}
            for k in range(len(V))]


def ddfv_frame_fields(F, T, faces):
    """Fields of each frame of a DDFV scheme.

    Parameters
    ----------
    F : (frames, n_f, 3) float array
        F-vertices (the mesh vertices).
    T : (frames, n_t, 3) float array
        T-vertices, one per triangle.
    faces : (n_t, 3) int array

    Returns
    -------
    list of dict
        Per frame ``{"vertices": {"displacement", "covolume"}, "extra_points":
        {"displacement", "covolume", "t_monitor"}, "triangles": {"t_monitor"}}``:
        point fields of the F-vertices (the mesh's) and of the T-vertices (the
        frame's ``extra_points``), and the cell field of the triangles.
    """
    from ddfv.geometry import covolume_areas, diamond_geometry, t_barycentric
    from ddfv.topology import diamond_mesh

    F, T, faces = np.asarray(F, dtype=np.float64), np.asarray(T, dtype=np.float64), \
        np.asarray(faces, dtype=np.int64)
    if T.shape[:2] != (len(F), len(faces)):
        raise ValueError(f"T must hold one point per triangle ({len(faces)}) in each of the "
                         f"{len(F)} frames, got shape {T.shape}")
    mesh = diamond_mesh(faces, F.shape[1])
    moved_f, moved_t = displacements(F), displacements(T)
    out = []
    for k in range(len(F)):
        chi_f, chi_t = covolume_areas(mesh, diamond_geometry(mesh, F[k], T[k]))
        monitor = t_barycentric(F[k], T[k], faces).min(axis=1)
        out.append({"vertices": {"displacement": moved_f[k], "covolume": chi_f.copy()},
                    "extra_points": {"displacement": moved_t[k], "covolume": chi_t.copy(),
                          "t_monitor": monitor},
                    "triangles": {"t_monitor": monitor}})
    return out
