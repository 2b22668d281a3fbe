"""Shaded pictures of the diamond mesh (Figs. 2.2 and 3.1-3.8).

The surface drawn is the diamond mesh: every primal triangle cut into three
by its T-vertex, i.e. the triangles ``(F_a, F_b, T_t)`` of the diamonds.
Primal F-edges (``F_a F_b``) and diamond edges (``F T`` segments, and the
boundary edges, which belong to the diamond mesh too, Fig. 2.3) are drawn
in different colours and widths, blue and red as in the paper's Fig. 2.2.

Rendering is an orthographic projection with the painter's algorithm in a
2-D matplotlib axes: the faces are sorted back to front and each face is
followed by its own edges in one :class:`~matplotlib.collections.PolyCollection`,
so edges on the far side are hidden by the faces in front of them. (mplot3d
sorts each collection separately and would show far edges through the
surface.) The view ``(elev, azim)`` in degrees has the meaning of mplot3d's
``view_init``; shading is Lambertian from a light above-left of the viewer,
with the back side of the surface tinted.

Typical use::

    panels = [Panel(F, T, faces, label="n = 0"), ...]
    fig = panel_row(panels, view=(20, -60))
    save_figure(fig, "results/figures/fig_3_2.png", "results/figures/fig_3_2.pdf")
"""

from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from ddfv.topology import diamond_mesh  # noqa: E402

PRIMAL_COLOR = "#1f4fd8"     # F-edges (blue, as in Fig. 2.2)
DIAMOND_COLOR = "#d62020"    # F-T edges and boundary edges (red)
FRONT_COLOR = "#e9e4da"      # outer side of the surface
BACK_COLOR = "#b9c7d9"       # inner side (seen through openings)
DPI = 150
AMBIENT = 0.4                # share of the light that does not depend on the normal


@dataclass
class Panel:
    """One picture of a surface.

    Attributes
    ----------
    F : (n_f, 3) float array
    T : (n_t, 3) float array or None
        ``None`` draws the primal mesh only (e.g. the cotangent scheme).
    faces : (n_t, 3) int array
    label : str
        Printed under the picture, e.g. ``"n = 12"``.
    zoom : tuple (centre, half_width), optional
        Show only the square of ``half_width`` around the projection of
        the 3-D point ``centre``.
    zoom_box : tuple (centre, half_width), optional
        Outline that square (the region of a detail shown elsewhere).
    note : str
        Printed in small italics inside the panel (e.g. a missing frame).
    """

    F: np.ndarray
    T: np.ndarray | None
    faces: np.ndarray
    label: str = ""
    zoom: tuple | None = None
    zoom_box: tuple | None = None
    note: str = ""
    options: dict = field(default_factory=dict)


def view_frame(view):
    """Orthonormal camera frame of the view ``(elev, azim)`` in degrees.

    Returns
    -------
    right, up, towards : (3,) float arrays
        Screen x, screen y, and the direction to the viewer.
    """
    elev, azim = np.radians(view[0]), np.radians(view[1])
    towards = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])
    right = np.array([-np.sin(azim), np.cos(azim), 0.0])
    up = np.cross(towards, right)
    return right, up, towards


def project(points, view):
    """Screen coordinates ``(n, 2)`` and depth ``(n,)`` (larger is nearer)."""
    right, up, towards = view_frame(view)
    P = np.asarray(points, dtype=float)
    return np.column_stack([P @ right, P @ up]), P @ towards


def diamond_faces(F, T, faces):
    """The triangles ``(F_a, F_b, T_t)`` of the diamond mesh, oriented as ``faces``.

    Parameters
    ----------
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    faces : (n_t, 3) int array

    Returns
    -------
    points : (n_f + n_t, 3) float array
        ``F`` then ``T``.
    triangles : (3 n_t, 3) int array
        Rows ``(a, b, n_f + t)`` for each half-edge ``a -> b`` of triangle ``t``.
    """
    n_f, n_t = len(F), len(faces)
    a = faces.ravel()
    b = faces[:, [1, 2, 0]].ravel()
    t = n_f + np.repeat(np.arange(n_t), 3)
    return np.concatenate([F, T]), np.column_stack([a, b, t])


def draw_mesh(ax, F, T, faces, *, view=(20.0, -60.0), primal_width=None,
              diamond_width=None, primal_color=PRIMAL_COLOR, diamond_color=DIAMOND_COLOR,
              front_color=FRONT_COLOR, back_color=BACK_COLOR, edges=True, smooth=True,
              light=(-0.4, 0.6, 0.7), points_per_unit=100.0):
    """Draw one shaded surface into a 2-D axes (see module docstring).

    Parameters
    ----------
    ax : matplotlib Axes
    F : (n_f, 3) float array
    T : (n_t, 3) float array or None
        ``None``: the primal triangles only, with F-edges.
    faces : (n_t, 3) int array
    view : (elev, azim) in degrees
    primal_width, diamond_width : float, optional
        Line widths in points; by default :func:`line_width` of the median
        projected edge length, and 0.6 of that.
    edges : bool
        Draw the edges at all.
    smooth : bool
        Shade with vertex-averaged normals (a smooth look) instead of the
        normals of the individual (flat) triangles. The side (front or
        back) is always that of the flat triangle.
    light : (3,) float
        Light direction in the camera frame (right, up, towards viewer).
    points_per_unit : float
        Scale of the picture (typographic points per length unit), for the
        default line widths.

    Returns
    -------
    (n, 2) float array
        Projected points (for limits).
    """
    faces = np.asarray(faces)
    n_f = len(F)
    boundary_edge = _boundary_halfedges(faces, n_f)
    if T is None:
        points, tri = np.asarray(F, float), faces
        primal = None
    else:
        points, tri = diamond_faces(F, T, faces)
        primal = tri[:, :2]
    xy, depth = project(points, view)
    right, up, towards = view_frame(view)
    P = points[tri]
    normal = _unit(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]))
    facing = normal @ towards
    if smooth:  # shade with the mean of the corners' area-weighted vertex normals
        area_normal = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
        at_vertex = np.zeros_like(points)
        for k in range(3):
            np.add.at(at_vertex, tri[:, k], area_normal)
        normal = _unit(_unit(at_vertex)[tri].sum(axis=1))
    L = np.asarray(light, float)
    L = (L[0] * right + L[1] * up + L[2] * towards) / np.linalg.norm(L)
    seen = normal * np.where(facing >= 0, 1.0, -1.0)[:, None]  # two-sided lighting
    lambert = np.maximum(0.0, seen @ L)
    halfway = (L + towards) / np.linalg.norm(L + towards)
    specular = 0.25 * np.maximum(0.0, seen @ halfway) ** 24
    shade = AMBIENT + (1.0 - AMBIENT) * lambert
    base = np.where((facing >= 0)[:, None], to_rgba(front_color)[:3], to_rgba(back_color)[:3])
    rgb = np.clip(base * shade[:, None] + specular[:, None], 0.0, 1.0)
    fill = np.column_stack([rgb, np.ones(len(tri))])

    if primal_width is None:
        edge = np.median(np.linalg.norm(xy[faces[:, 1]] - xy[faces[:, 0]], axis=1))
        primal_width = line_width(edge * points_per_unit)
    if diamond_width is None:
        diamond_width = 0.6 * primal_width
    order = np.argsort(depth[tri].mean(axis=1), kind="stable")
    if T is None:
        # the triangle, closed, stroked in the primal colour
        verts = xy[tri[order]]
        coll = PolyCollection(list(verts), closed=True, facecolors=fill[order],
                              edgecolors=primal_color if edges else "none",
                              linewidths=primal_width if edges else 0)
        ax.add_collection(coll)
        return xy
    # each diamond-mesh triangle (F_a, F_b, T) as the open path F_b -> T -> F_a
    # (its fill is the triangle, its stroke the two F-T edges), then the
    # primal edge F_a -> F_b as a two-point path
    k = len(order)
    paths = np.empty(2 * k, dtype=object)
    tri_o = tri[order]
    paths[0::2] = list(xy[tri_o[:, [1, 2, 0]]])
    paths[1::2] = list(xy[primal[order]])
    face_rgba = np.zeros((2 * k, 4))
    face_rgba[0::2] = fill[order]
    edge_rgba = np.zeros((2 * k, 4))
    widths = np.zeros(2 * k)
    if edges:
        bnd = boundary_edge[order]
        edge_rgba[0::2] = to_rgba(diamond_color)
        edge_rgba[1::2] = np.where(bnd[:, None], to_rgba(diamond_color), to_rgba(primal_color))
        widths[0::2] = diamond_width
        widths[1::2] = np.where(bnd, 1.6 * diamond_width, primal_width)
    coll = PolyCollection(list(paths), closed=False, facecolors=face_rgba,
                          edgecolors=edge_rgba, linewidths=widths,
                          joinstyle="round", capstyle="round")
    ax.add_collection(coll)
    return xy


def line_width(edge_points):
    """Default F-edge width (points) for edges ``edge_points`` long on paper.

    About 1/25 of the edge, between 0.15 and 1 point: thin enough that a
    dense mesh does not turn into a solid colour, thick enough to see.
    """
    return float(np.clip(0.04 * edge_points, 0.15, 1.0))


WORST_MEASURES = ("angle", "barycentric")


def worst_element(F, T, faces, view=None, by="angle", max_tilt=60.0):
    """The worst diamond cell or T-vertex, for centring a detail.

    Parameters
    ----------
    F, T, faces
        The surface; ``T = None`` for the primal mesh only (then T-vertices
        are taken at the barycentres).
    view : (elev, azim), optional
        Only elements whose triangle faces the viewer (normal within
        ``max_tilt`` degrees of the view direction) count, so that a detail
        shows the front of the surface.
    by : {"angle", "barycentric"}
        ``"angle"``: the diamond with the smallest angle
        (:func:`ddfv.diagnostics.diamond_min_angles`); ``"barycentric"``:
        the T-vertex with the smallest barycentric coordinate in its
        triangle (the first to leave it).

    Returns
    -------
    int
        Diamond index (``"angle"``) or triangle index (``"barycentric"``);
        see :func:`element_centre`.
    """
    from .quality import diamond_min_angles
    from .geometry import t_barycentric

    if by not in WORST_MEASURES:
        raise ValueError(f"unknown measure {by!r}; choose one of {', '.join(WORST_MEASURES)}")
    mesh = diamond_mesh(faces, len(F))
    if T is None:
        T = F[mesh.faces].mean(axis=1)
    if by == "angle":
        score, tri = diamond_min_angles(mesh, F, T), mesh.diamonds[:, 2]
    else:
        score, tri = t_barycentric(F, T, mesh.faces).min(axis=1), np.arange(mesh.n_t)
    if view is not None:
        p = F[mesh.faces]
        normal = _unit(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))[tri]
        facing = normal @ view_frame(view)[2] > np.cos(np.radians(max_tilt))
        score = np.where(facing, score, np.inf)
    return int(np.argmin(score))


def element_centre(F, T, faces, index, by="angle"):
    """Centre of a :func:`worst_element`: the diamond centre ``S`` (the edge
    midpoint without T-vertices or on the boundary) or the T-vertex
    (the barycentre without T-vertices)."""
    mesh = diamond_mesh(faces, len(F))
    if by == "barycentric":
        return F[mesh.faces[index]].mean(axis=0) if T is None else T[index]
    a, b, t1, t2 = mesh.diamonds[index]
    if T is None or t2 < 0:
        return 0.5 * (F[a] + F[b])
    return 0.25 * (F[a] + F[b] + T[t1] + T[t2])


def _unit(x):
    return x / np.maximum(np.linalg.norm(x, axis=1, keepdims=True), 1e-300)


def _boundary_halfedges(faces, n_f):
    """(3 n_t,) bool: the half-edge ``faces[t, k] -> faces[t, k+1]`` is a boundary edge."""
    mesh = diamond_mesh(faces, n_f)
    return mesh.boundary[mesh.halfedges.ravel()]


def panel_row(panels, *, view=(20.0, -60.0), size=2.6, aspect=1.0, rows=1,
              share_scale=True, margin=0.04, title=None, label_size=10):
    """Lay out panels in a grid (one row by default), each labelled below.

    Parameters
    ----------
    panels : sequence of Panel
    view : (elev, azim) in degrees, the same for all panels
    size : float
        Width of a panel in inches.
    aspect : float
        Height / width of a panel (zoom squares become rectangles too).
    rows : int
    share_scale : bool
        Show all full (non-zoom) panels with the same length scale and
        centre, so that a shrinking surface looks smaller and a fixed
        boundary stays in place.
    margin : float
        Empty border around the surface, relative to its extent.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    cols = int(np.ceil(len(panels) / rows))
    height = size * aspect
    fig, axes = plt.subplots(rows, cols, figsize=(size * cols, (height + 0.3) * rows),
                             squeeze=False)
    boxes = []
    for panel in panels:
        xy = project(panel.F if panel.T is None else np.concatenate([panel.F, panel.T]),
                     view)[0]
        boxes.append((xy.min(axis=0), xy.max(axis=0)))
    full = [i for i, p in enumerate(panels) if p.zoom is None]
    if full:
        lo = np.min([boxes[i][0] for i in full], axis=0)
        hi = np.max([boxes[i][1] for i in full], axis=0)
        common = 0.5 * (1 + 2 * margin) * max((hi - lo)[0], (hi - lo)[1] / aspect)
        common_centre = 0.5 * (lo + hi)
    for i, (panel, ax) in enumerate(zip(panels, axes.ravel())):
        if panel.zoom is not None:
            centre, half = panel.zoom
            c = project(np.asarray(centre, float)[None], view)[0][0]
        else:
            lo_i, hi_i = boxes[i]
            c, half = (common_centre, common) if share_scale else \
                (0.5 * (lo_i + hi_i),
                 0.5 * (1 + 2 * margin) * max((hi_i - lo_i)[0], (hi_i - lo_i)[1] / aspect))
        options = {"points_per_unit": 72.0 * size / (2 * half), **panel.options}
        draw_mesh(ax, panel.F, panel.T, panel.faces, view=view, **options)
        ax.set_xlim(c[0] - half, c[0] + half)
        ax.set_ylim(c[1] - half * aspect, c[1] + half * aspect)
        ax.set_aspect("equal")
        ax.set_axis_off()
        if panel.zoom is not None:  # a frame marks a detail
            ax.add_patch(Rectangle((0, 0), 1, 1, transform=ax.transAxes, fill=False,
                                   lw=1.2, ec="0.2", clip_on=False))
        if panel.zoom_box is not None:
            zc, zh = panel.zoom_box
            z = project(np.asarray(zc, float)[None], view)[0][0]
            ax.add_patch(Rectangle((z[0] - zh, z[1] - zh * aspect), 2 * zh, 2 * zh * aspect,
                                   fill=False, lw=1.0, ec="0.15", ls="--", zorder=5))
        ax.set_title(panel.label, y=-0.03 if panel.zoom is None else -0.06, va="top",
                     fontsize=label_size)
        if panel.note:
            ax.text(0.5, 0.98, panel.note, transform=ax.transAxes, ha="center", va="top",
                    fontsize=7, style="italic", color="0.1", zorder=10,
                    bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.85})
    for ax in axes.ravel()[len(panels):]:
        ax.set_axis_off()
    if title:
        fig.suptitle(title, fontsize=label_size + 1)
    fig.subplots_adjust(left=0.01, right=0.99, top=0.92 if title else 0.98,
                        bottom=0.3 / (height + 0.3) / rows, wspace=0.05,
                        hspace=0.3 / height)
    return fig


def save_figure(fig, png, pdf=None, dpi=DPI):
    """Write the figure as PNG (``dpi``) and optionally PDF, and close it.

    The meshes are rasterised (at ``2 dpi``) inside the PDF to keep it
    small; labels and frames stay vector.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    png : str or Path
        The PNG file; if it has no suffix it is a stem and both
        ``stem.png`` and ``stem.pdf`` are written.
    pdf : str or Path, optional

    Returns
    -------
    list of Path
        The files written.
    """
    png = Path(png)
    if not png.suffix:
        png, pdf = png.with_name(png.name + ".png"), png.with_name(png.name + ".pdf")
    paths = [png] + ([Path(pdf)] if pdf is not None else [])
    for ax in fig.axes:
        for coll in ax.collections:
            coll.set_rasterized(True)
    for path in paths:
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=dpi if path.suffix == ".png" else 2 * dpi)
    plt.close(fig)
    return paths
