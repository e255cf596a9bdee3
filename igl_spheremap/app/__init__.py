"""The file jobs behind the command line: map one file (:mod:`.map_file`, with the
storage policy of :mod:`.storage` and the report of :mod:`.report`), register or
resample files (:mod:`.surface_files`), and many files on Dask (:mod:`.batch`).
"""
