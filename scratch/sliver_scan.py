"""Scan t for both split constructions: validation verdict, faces with triangle-inequality slack <= 0, libigl-port flips (capped)."""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import igl_spheremap
from idt_port import idt
from sliver_mesh import split_icosphere
from sliver_seeds import orig_variant, slack

level = int(sys.argv[1]) if len(sys.argv) > 1 else 3
for t in (1e-2, 1e-3, 1e-4, 1e-5, 3e-6, 1e-6, 1e-7, 1e-9, 1e-11):
    for name, make in (("disjoint", lambda s: split_icosphere(level, 200, t, s)),
                       ("shared", lambda s: orig_variant(level, 200, t, s))):
        for seed in range(3):
            V, F = make(seed)
            try:
                igl_spheremap.validate_mesh(V, F); valid = "valid"
            except igl_spheremap.MeshError as err:
                valid = f"{err.problem}:{err.count}"
            s = slack(V, F)
            r = idt(V, F, max_flips=3000)
            print(f"L{level} t={t:<6g} {name:8s} seed={seed} {valid:16s} slack<=0 faces: {int((s <= 0).sum()):2d} "
                  f"idt {'done' if r['done'] else 'CAPPED'} flips={r['flips']} nan={int(np.isnan(r['l']).sum())}", flush=True)
