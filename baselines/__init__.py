"""Schemes compared with the DDFV scheme, on the mesh vertices only.

Every scheme is one class following the contract of ``mcfbench.running.flow.SchemeFlow``
(constructor ``(vertices, faces, tau, **options)``, ``step(solve)``,
``defects()``, ``frame()``, ...) and is registered in
``mcfbench/running/schemes.py``; this package imports nothing from ``ddfv`` or
``mcfbench`` (see ``baselines/README.md``).

cotan (:class:`baselines.cotan.CotanFlow`)
    The cotangent scheme (Dziuk 1991), barycentric or Voronoi lumped mass;
    ``redistribution="area"`` adds the area-oriented tangential velocity of
    :mod:`baselines.redistribution` (Mikula, Remesikova, Sarkoci, Sevcovic
    2014; registry entry ``cotan-redistribute``).
cmcf (:class:`baselines.cmcf.CMCFFlow`)
    Conformalized mean curvature flow (Kazhdan, Solomon, Ben-Chen 2012).
bgn (:class:`baselines.bgn.BGNFlow`)
    Barrett, Garcke, Nuernberg (2008), mass-lumped vertex normals.
bgn-bdf2, bgn-bdf3 (:class:`baselines.bgn_bdf.BGNBDFFlow`)
    BGN with BDF-k on predictor surfaces (Jiang, Su, Zhang 2024); it integrates
    in time itself (several solves a step).
mdr (:class:`baselines.mdr.MDRFlow`)
    The minimal deformation rate velocity of Hu and Li (2022), eliminated
    into BGN's system with unit normals.
deturck (:class:`baselines.deturck.DeTurckFlow`)
    The DeTurck trick of Elliott and Fritz (2017): reparametrised by the
    harmonic map heat flow onto the initial mesh, ``alpha`` its time scale.
kll (:class:`baselines.kll.KLLFlow`)
    Kovacs, Li and Lubich (2019): the normal and the mean curvature evolved by
    Huisken's equations with the position, velocity ``-H nu``; P1, closed
    surfaces or with their boundary held fixed.

Shared: :mod:`baselines.mesh` (edge topology, CSR pattern),
:mod:`baselines.laplacian` (the cotangent stiffness and the lumped mass),
:mod:`baselines.vertex_flow` (the state and checks of every vertex scheme) and
:mod:`baselines.kernels` (the compiled assembly) and
:mod:`baselines.tangential_kernels` (the tangential motions' compiled loops).
"""
