"""The float32 repairs: a fold-free map whose faces are not all above their float32
rounding margin (:func:`igl_spheremap.sphere.folds.rounding_margin`) after
Algorithm 2 is repaired by :func:`.repair.make_representable`, which tries cluster
inflation (:mod:`.inflation`), a rerun on a compressed metric
(:mod:`.compressed_metric`) and a start from the central projection.
"""
