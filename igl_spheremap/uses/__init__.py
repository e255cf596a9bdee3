"""What spherical maps are for: landmark-matched maps (:mod:`.landmarks`, with the
thin-plate spline deformation of :mod:`.spline`), correspondence between two
surfaces (:mod:`.registration`), resampling onto template spheres
(:mod:`.resampling`), p-harmonic maps (:mod:`.p_harmonic`) and the area-correcting
Möbius transformation (:mod:`.area_correction`).
"""
