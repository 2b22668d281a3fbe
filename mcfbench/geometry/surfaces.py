"""Initial surfaces: every mesh of the experiments and of the benchmark problems.

The generators live in :mod:`mcfbench.geometry.spheres`,
:mod:`mcfbench.geometry.shapes` and :mod:`mcfbench.geometry.implicit`, built from
:mod:`mcfbench.geometry.construction`. Every generator returns ``(vertices, faces)``: a ``(n, 3)`` float64 array and
an ``(m, 3)`` int64 array of triangles, consistently oriented, with normals
pointing outwards (away from the enclosed volume of a closed surface, away
from the axis of a cylinder, away from the centre of a hemisphere, ``+z`` for
a flat patch). Generators are deterministic; the random ones take a ``seed``.
:data:`SURFACES` maps a name to its generator and :func:`make_surface` calls
it with keyword arguments, so problems and the command line refer to a
surface by name.

Counts at the default parameters (``n_F`` vertices, ``n_T`` triangles):

======================== ====== ====== ========= ======================================
name                     n_F    n_T    boundary  what
======================== ====== ====== ========= ======================================
``sphere``               642    1280   none      icosphere level 3 (Table 3.1)
``bumpy_sphere``         642    1280   none      Gaussian bumps (Fig. 3.2)
``random_bumpy_sphere``  162    320    none      random smooth bumps (unit tests)
``cymling``              642    1280   none      flat scalloped lens (Figs. 3.3, 3.4)
``perturbed_sphere``     642    1280   none      icosphere, vertices moved on the sphere
``remeshed_sphere``      642    1280   none      hull of random points on the sphere
``anisotropic_sphere``   450    896    none      UV sphere, 8 x 64, thin triangles
``cylinder``             216    384    2 loops   24 x 8, alternating (catenoid problem)
``hemisphere``           331    600    1 loop    10 rings (Fig. 3.8)
``flat_patch``           376    687    1 loop    jittered Delaunay unit disk, z = 0
``flat_lattice``         42     60     1 loop    6 x 5 unit squares, z = 0 (unit tests)
``torus``                256    512    none      R = 2, r = 0.5, 32 x 8 (genus 1)
``dumbbell``             2546   5088   none      two unit spheres, neck 0.25 (level 1)
``blobby``               2646   5288   none      marching cubes of metaballs, 40^3
``implicit_torus``       4476   8952   none      marching cubes of a tilted torus, 48^3
``angenent_torus``       1152   2304   none      Angenent's self-shrinking torus, 48 x 24
``enneper_patch``        376    687    1 loop    Enneper patch R = 0.8, interior lifted 0.2 (defaults)
``real_mesh``            523    1046   none      a committed real mesh (``nut``), Loop limit, level 0
======================== ====== ====== ========= ======================================

Refinement: the icosphere family (``sphere``, ``bumpy_sphere``,
``cymling``, ``perturbed_sphere``) halves ``h`` per ``level``; so do
``anisotropic_sphere``, ``dumbbell`` and ``flat_patch`` (``level``),
``cylinder`` and ``torus`` (double both counts), ``hemisphere`` (double
``rings``), ``remeshed_sphere`` (4x ``n_points``) and the marching-cubes
surfaces (double ``resolution``); ``real_mesh`` (``mesh``, ``level``) is
level ``level`` of the Loop-limit series of a mesh of
:mod:`mcfbench.geometry.committed_meshes` (:mod:`mcfbench.geometry.subdivision`).
"""

from mcfbench.geometry.angenent import angenent_torus
from mcfbench.geometry.committed_meshes import real_mesh
from mcfbench.geometry.implicit import blobby, implicit_torus
from mcfbench.geometry.minimal import enneper_patch
from mcfbench.geometry.shapes import (
    cylinder,
    dumbbell,
    flat_lattice,
    flat_patch,
    hemisphere,
    torus,
)
from mcfbench.geometry.spheres import (
    anisotropic_sphere,
    bumpy_sphere,
    cymling,
    perturbed_sphere,
    random_bumpy_sphere,
    remeshed_sphere,
    sphere,
)

SURFACES = {
    "sphere": sphere,
    "bumpy_sphere": bumpy_sphere,
    "random_bumpy_sphere": random_bumpy_sphere,
    "cymling": cymling,
    "perturbed_sphere": perturbed_sphere,
    "remeshed_sphere": remeshed_sphere,
    "anisotropic_sphere": anisotropic_sphere,
    "cylinder": cylinder,
    "hemisphere": hemisphere,
    "flat_patch": flat_patch,
    "flat_lattice": flat_lattice,
    "torus": torus,
    "dumbbell": dumbbell,
    "blobby": blobby,
    "implicit_torus": implicit_torus,
    "angenent_torus": angenent_torus,
    "enneper_patch": enneper_patch,
    "real_mesh": real_mesh,
}
"""Name -> generator of the initial surfaces; ``SURFACES[name](**params)``."""


def make_surface(name, **params):
    """``SURFACES[name](**params)``, with a helpful error for unknown names.

    Examples
    --------
    >>> V, F = make_surface("torus", n_major=16, n_minor=4)
    >>> V.shape, F.shape
    ((64, 3), (128, 3))
    """
    try:
        generator = SURFACES[name]
    except KeyError:
        raise ValueError(f"unknown surface {name!r}; choose one of {', '.join(SURFACES)}") from None
    return generator(**params)


