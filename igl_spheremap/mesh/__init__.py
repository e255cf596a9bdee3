"""Triangle meshes: validation (:mod:`.validate`, :mod:`.topology`), array checks
(:mod:`.arrays`), discrete operators from libigl (:mod:`.operators`,
:mod:`.intrinsic_delaunay`), intrinsically mollified edge lengths (:mod:`.mollify`) and
meshes built from scratch (:mod:`.shapes`).

The first layer of the package: it imports nothing else of it but ``errors``.
"""
