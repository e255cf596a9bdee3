"""Spherical maps as such, whatever made them: folds, degree and rounding margins
(:mod:`.folds`), quality measures (:mod:`.quality`), Möbius transformations
(:mod:`.mobius`), geodesics (:mod:`.geodesics`), spherical coordinates
(:mod:`.coordinates`), point location and barycentric transfer (:mod:`.locate`,
:mod:`.transfer`), the gnomonic chart with the Tutte patch (:mod:`.chart`), and the
lift of isolated slivers above their rounding margin (:mod:`.sliver_lift`).
"""
