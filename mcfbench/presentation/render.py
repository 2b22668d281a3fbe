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

Tracked diamond cells (:attr:`Panel.highlight`, diamond indices of
:func:`ddfv.topology.diamond_mesh`) are filled in an amber highlight colour
instead of the surface colour, so that the same cells can be found in every
panel of a figure (Fig. 3.4). :func:`panel_row` adds a small legend of what
is drawn (primal and diamond edges, tracked cells, detail region) so that a
picture read alone can be understood.

Typical use::

    panels = [Panel(F, T, faces, label="n = 0"), ...]
    fig = panel_row(panels, view=(20, -60))
    write_files({"fig_3_2.png": (fig, {"dpi": DPI}),
                 "fig_3_2.pdf": (rasterize_meshes(fig), {"dpi": 2 * DPI})})  # mcfbench.storage.atomic
"""

from dataclasses import dataclass, field

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402

from ddfv.topology import diamond_mesh  # noqa: E402

PRIMAL_COLOR = "#1f4fd8"     # F-edges (blue, as in Fig. 2.2)
DIAMOND_COLOR = "#d62020"    # F-T edges and boundary edges (red)
FRONT_COLOR = "#e9e4da"      # outer side of the surface
BACK_COLOR = "#b9c7d9"       # inner side (seen through openings)
HIGHLIGHT_COLOR = "#ffb000"  # tracked diamond cells (amber)
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
        Printed under the picture, e.g. ``"n = 12"``; may have several lines.
    zoom : tuple (centre, half_width), optional
        Show only the square of ``half_width`` around the projection of
        the 3-D point ``centre``.
    zoom_box : tuple (centre, half_width), optional
        Outline that square (the region of a detail shown elsewhere).
    note : str
        Printed in small italics inside the panel (e.g. a missing frame).
    highlight : (k,) int array, optional
        Diamond cells (indices of :func:`ddfv.topology.diamond_mesh`) filled
        in :data:`HIGHLIGHT_COLOR`; with ``T = None`` the primal triangles
        on either side of their edges are filled.
    options : dict
        More keyword arguments of :func:`draw_mesh`.
    """

    F: np.ndarray
    T: np.ndarray | None
    faces: np.ndarray
    label: str = ""
    zoom: tuple | None = None
    zoom_box: tuple | None = None
    note: str = ""
    highlight: np.ndarray | None = None
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
              light=(-0.4, 0.6, 0.7), points_per_unit=100.0, highlight=None,
              highlight_color=HIGHLIGHT_COLOR):
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
    highlight : sequence of int, optional
        Diamond cells filled in ``highlight_color`` (shaded like the rest):
        their triangles ``(F_a, F_b, T)``, or with ``T = None`` the primal
        triangles on either side of their edges.

    Returns
    -------
    (n, 2) float array
        Projected points (for limits).
    """
    faces = np.asarray(faces)
    n_f = len(F)
    mesh = diamond_mesh(faces, n_f)
    boundary_edge = mesh.boundary[mesh.halfedges.ravel()]
    marked = np.zeros(len(mesh.diamonds), bool)
    if highlight is not None:
        marked[np.asarray(highlight, dtype=int)] = True
    if T is None:
        points, tri = np.asarray(F, float), faces
        primal = None
        lit = marked[mesh.halfedges].any(axis=1)     # a triangle with a tracked edge
    else:
        points, tri = diamond_faces(F, T, faces)
        primal = tri[:, :2]
        lit = marked[mesh.halfedges.ravel()]          # row 3 t + k: half-edge k of t
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
    base[lit] = to_rgba(highlight_color)[:3]
    shade = np.where(lit, 0.6 + 0.4 * shade, shade)   # tracked cells stay bright in shadow
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
        # an (m, 3, 2) array: matplotlib's fast path, one template path for all
        coll = PolyCollection(xy[tri[order]], closed=True, facecolors=fill[order],
                              edgecolors=primal_color if edges else "none",
                              linewidths=primal_width if edges else 0)
        ax.add_collection(coll, autolim=False)        # the caller sets the limits
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
    ax.add_collection(coll, autolim=False)
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
        (:func:`mcfbench.geometry.quality.diamond_min_angles`); ``"barycentric"``:
        the T-vertex with the smallest barycentric coordinate in its
        triangle (the first to leave it).

    Returns
    -------
    int
        Diamond index (``"angle"``) or triangle index (``"barycentric"``);
        see :func:`element_centre`.
    """
    from ddfv.geometry import t_barycentric
    from mcfbench.geometry.quality import diamond_min_angles

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


def tracked_cells(faces, diamond, n_vertices=None):
    """The diamond cells around ``diamond``: those of its two triangles.

    The diamond itself and the other diamonds of the triangles ``t1``,
    ``t2`` on either side of its edge (5 cells for an inner diamond, 3 on
    the boundary), sorted: a small patch that is easy to find again.

    Parameters
    ----------
    faces : (n_t, 3) int array
    diamond : int
        Index of :func:`ddfv.topology.diamond_mesh`.
    n_vertices : int, optional

    Returns
    -------
    (k,) int array
    """
    mesh = diamond_mesh(faces, n_vertices)
    tri = mesh.diamonds[diamond, 2:]
    return np.unique(mesh.halfedges[tri[tri >= 0]].ravel())


def cells_centre(F, T, faces, cells):
    """Mean of the centres (:func:`element_centre`) of the diamond ``cells``."""
    mesh = diamond_mesh(faces, len(F))
    a, b, t1, t2 = np.asarray(mesh.diamonds[np.asarray(cells, dtype=int)]).T
    if T is None:
        centre = 0.5 * (F[a] + F[b])
    else:
        inner = t2 >= 0
        centre = np.where(inner[:, None], 0.25 * (F[a] + F[b] + T[t1] + T[np.maximum(t2, 0)]),
                          0.5 * (F[a] + F[b]))
    return centre.mean(axis=0)


def cells_points(F, T, faces, cells):
    """(m, 3) corners of the diamond ``cells``: their F-vertices and T-vertices
    (with ``T = None`` the corners of the primal triangles on either side)."""
    mesh = diamond_mesh(faces, len(F))
    d = mesh.diamonds[np.asarray(cells, dtype=int)]
    tri = d[:, 2:][d[:, 2:] >= 0]
    if T is None:
        return F[np.unique(mesh.faces[tri].ravel())]
    return np.concatenate([F[np.unique(d[:, :2].ravel())], T[np.unique(tri)]])


def legend_handles(panels):
    """Legend entries for what ``panels`` show (see :func:`panel_row`)."""
    diamond = any(p.T is not None for p in panels)
    handles = [Line2D([], [], color=PRIMAL_COLOR, lw=1.6,
                      label="primal edges (F\u2013F)")]
    if diamond:
        handles.append(Line2D([], [], color=DIAMOND_COLOR, lw=1.0,
                              label="diamond edges (F\u2013T, boundary)"))
    if any(p.highlight is not None and len(p.highlight) for p in panels):
        handles.append(Patch(fc=HIGHLIGHT_COLOR, ec="0.3", lw=0.5,
                             label="tracked diamond cells (ringed in a full view)"))
    if any(p.zoom_box is not None for p in panels):
        handles.append(Patch(fill=False, ec="0.15", ls="--", lw=1.0,
                             label="region of the details"))
    return handles


def panel_row(panels, *, view=(20.0, -60.0), size=2.6, aspect=1.0, rows=1,
              share_scale=True, margin=0.04, title=None, label_size=10, legend=True):
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
        boundary stays in place. (Details have the scale of their own
        half-width.)
    margin : float
        Empty border around the surface, relative to its extent.
    title : str, optional
        Figure title.
    label_size : float
        Font size of the panel labels (points); the title is one larger.
    legend : bool
        A legend of what is drawn (:func:`legend_handles`) below the panels.

    Returns
    -------
    matplotlib.figure.Figure
    """
    cols = int(np.ceil(len(panels) / rows))
    height = size * aspect
    lines = max([p.label.count("\n") + 1 if p.label else 0 for p in panels] + [1])
    label_h = 0.06 + lines * label_size * 1.25 / 72.0     # inches under each panel
    handles = legend_handles(panels) if legend else []
    legend_cols = min(len(handles), max(1, int(size * cols // 2.4)))
    legend_h = 0.12 + 0.19 * np.ceil(len(handles) / max(legend_cols, 1)) if handles else 0.0
    title_h = 0.35 if title else 0.05
    fig_h = (height + label_h) * rows + legend_h + title_h
    fig, axes = plt.subplots(rows, cols, figsize=(size * cols, fig_h), squeeze=False)
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
        if panel.highlight is not None:
            options.setdefault("highlight", panel.highlight)
        draw_mesh(ax, panel.F, panel.T, panel.faces, view=view, **options)
        ax.set_xlim(c[0] - half, c[0] + half)
        ax.set_ylim(c[1] - half * aspect, c[1] + half * aspect)
        ax.set_aspect("equal")
        ax.set_axis_off()
        if panel.zoom is not None:  # a frame marks a detail
            ax.add_patch(Rectangle((0, 0), 1, 1, transform=ax.transAxes, fill=False,
                                   lw=1.2, ec="0.2", clip_on=False))
        if panel.highlight is not None and len(panel.highlight) and panel.zoom is None:
            # in a full view the tracked cells are small: a ring around them too
            hc = project(cells_centre(panel.F, panel.T, panel.faces, panel.highlight)[None],
                         view)[0][0]
            ax.plot([hc[0]], [hc[1]], "o", ms=9, mfc="none", mec=HIGHLIGHT_COLOR, mew=1.6,
                    zorder=6)
        if panel.zoom_box is not None:
            zc, zh = panel.zoom_box
            z = project(np.asarray(zc, float)[None], view)[0][0]
            ax.add_patch(Rectangle((z[0] - zh, z[1] - zh * aspect), 2 * zh, 2 * zh * aspect,
                                   fill=False, lw=1.0, ec="0.15", ls="--", zorder=5))
        ax.set_title(panel.label, y=-0.02 if panel.zoom is None else -0.05, va="top",
                     fontsize=label_size, linespacing=1.15)
        if panel.note:
            ax.text(0.5, 0.98, panel.note, transform=ax.transAxes, ha="center", va="top",
                    fontsize=7, style="italic", color="0.1", zorder=10,
                    bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.85})
    for ax in axes.ravel()[len(panels):]:
        ax.set_axis_off()
    if title:
        fig.suptitle(title, fontsize=label_size + 1, y=1 - 0.08 / fig_h, va="top")
    if handles:
        fig.legend(handles=handles, loc="lower center", ncol=legend_cols, frameon=False,
                   fontsize=label_size - 2, handlelength=1.8, columnspacing=1.5,
                   bbox_to_anchor=(0.5, 0.02 / fig_h))
    fig.subplots_adjust(left=0.01, right=0.99, top=1 - title_h / fig_h,
                        bottom=(label_h + legend_h) / fig_h, wspace=0.05,
                        hspace=label_h / height)
    return fig


def rasterize_meshes(fig):
    """Draw the meshes of ``fig`` as images inside a PDF (labels and frames stay
    vector), which keeps a figure of thousands of cells small; returns ``fig``."""
    for ax in fig.axes:
        for coll in ax.collections:
            coll.set_rasterized(True)
    return fig
