"""What spherical maps are for: landmark-matched maps (:mod:`.landmarks`, with the
thin-plate spline deformation of :mod:`.spline`), correspondence between two
surfaces (:mod:`.registration`), atlas registration by features (:mod:`.atlas`, with
:mod:`.features`, :mod:`.rigid` and :mod:`.atlas_multires`), resampling onto template
spheres and through registrations (:mod:`.resampling`), p-harmonic maps (:mod:`.p_harmonic`) and the area-correcting
Möbius transformation (:mod:`.area_correction`).
"""
