"""The file jobs behind the command line: map one file (:mod:`.map_file`, with the
storage policy of :mod:`.storage` and the report of :mod:`.report`),
register files by landmarks (:mod:`.surface_files`), register spheres by features
(:mod:`.sphere_registration`), resample files onto templates and through registrations
(:mod:`.resampling`), and many files on Dask (:mod:`.batch`).
"""
