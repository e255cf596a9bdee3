#!/bin/sh
# Before (igl.intrinsic_delaunay_cotmatrix, which the old laplacian() called directly) vs after
# (operators.laplacian and spherical_conformal_map on this branch), each call in its own child
# under timeout 120 s and a 4 GB address-space limit.  Output: scratch/before_after.jsonl
cd "$(dirname "$0")/.." || exit 1
PY=${PY:-/work/main/.venv/bin/python}
M="$PY scratch/sliver_measure.py"
{
PYTHONPATH=. $M --family disjoint --seed 2 --ops idt,ours,map,map_cot --ts 1e-2,1e-4,1e-6,1e-7,1e-9,1e-11
PYTHONPATH=. $M --family disjoint --seed 0 --level 5 --edges 5120 --ops idt,ours,map --ts 1e-4,3e-5
PYTHONPATH=. $M --family shared --seed 0 --ops idt,ours,map --ts 1e-2,3e-6
PYTHONPATH=. $M --family cap --seed 0 --ops idt,ours,map --ts 1e-5,1e-9
} > scratch/before_after.jsonl
