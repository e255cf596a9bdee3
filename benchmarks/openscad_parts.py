"""Closed genus-0 CAD parts as OpenSCAD renders them, for ``corpus.py``.

CAD parts as a modelling program's own triangulation leaves them: unions, differences
and hulls of boxes, cylinders and spheres, extrusions and revolutions, with
fan-triangulated caps and needle triangles where two solids meet.  Two sources: the
programs of :data:`PROGRAMS`, written here (Apache-2.0, this project's), and the examples
that ship with Debian's ``openscad`` package (``/usr/share/openscad/examples``,
CC0-1.0).  Each is rendered with ``openscad -o NAME.off`` (the OFF file keeps the shared
vertices), read and kept as :func:`pypi_meshes.closed_genus0` keeps a mesh (coincident
vertices merged: OpenSCAD writes some solids with them), at any size from 4 vertices.
Programs whose solid has holes, or whose triangles repeat a vertex (a revolution that
touches its axis), are left out, and listed with the reason.  OpenSCAD's own triangulation of
a planar polygon can differ from run to run (the same vertices, another diagonal in a few
quads: 6 of the 37 files differed between two renders here), so a rerun maps nearly, not
exactly, the same meshes; ``tests/data/stepped_shaft.obj`` keeps one render.

Usage::

    apt-get install openscad                              # Debian bookworm: 2021.01
    python benchmarks/openscad_parts.py --out /tmp/openscad_parts
    python benchmarks/corpus.py /tmp/openscad_parts --shapes --out DIR
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import igl

from pypi_meshes import closed_genus0

#: The parts written here: name -> OpenSCAD program.
PROGRAMS = {
    "l_bracket": "union(){cube([40,5,30]); cube([40,25,5]);}",
    "boss_plate": "$fn=64; union(){cube([50,30,4]); translate([25,15,0]) cylinder(r=8,h=20);}",
    "hull_spheres": "hull(){sphere(r=5,$fn=24); translate([40,0,0]) sphere(r=2,$fn=12); "
                    "translate([10,20,5]) sphere(r=3,$fn=40);}",
    "stepped_shaft": "union(){cylinder(r=10,h=5,$fn=96); cylinder(r=6,h=40,$fn=48); "
                     "translate([0,0,40]) cylinder(r=3,h=30,$fn=24);}",
    "pocket_cube": "difference(){cube(30); translate([30,30,30]) sphere(r=15,$fn=48);}",
    "rounded_box": "minkowski(){cube([30,20,10]); sphere(r=2,$fn=12);}",
    "star_prism": "linear_extrude(height=8) "
                  "polygon([for(i=[0:19]) (i%2==0?20:6)*[cos(i*18),sin(i*18)]]);",
    "twisted_bar": "linear_extrude(height=60,twist=180,slices=40) square([10,4],center=true);",
    "vase": "rotate_extrude($fn=72) polygon([[0,0],[15,0],[18,10],[10,30],[12,45],[0,45]]);",
    "staircase": "union(){for(i=[0:9]) translate([i*6,0,0]) cube([6,20,(i+1)*4]);}",
    "gear": "linear_extrude(height=6) union(){circle(r=20,$fn=120); "
            "for(i=[0:23]) rotate(i*15) translate([20,0]) square([4,3],center=true);}",
    "pencil": "union(){cylinder(r=3,h=80,$fn=6); "
              "translate([0,0,80]) cylinder(r1=3,r2=0.01,h=12,$fn=6);}",
    "long_rod": "hull(){sphere(r=1,$fn=16); translate([100,0,0]) sphere(r=1,$fn=16);}",
    "drill": "linear_extrude(height=50,twist=720,slices=120) translate([1.5,0]) circle(r=3,$fn=20);",
    "cross_block": "union(){cube([60,8,8],center=true); cube([8,60,8],center=true); "
                   "cube([8,8,60],center=true);}",
    "hex_nut_blank": "cylinder(r=10,h=8,$fn=6);",
    "knob": "union(){cylinder(r=15,h=10,$fn=30); translate([0,0,10]) cylinder(r=4,h=25,$fn=30); "
            "for(i=[0:5]) rotate(i*60) translate([15,0,0]) cylinder(r=2,h=10,$fn=12);}",
    "sphere_cut": "intersection(){sphere(r=20,$fn=60); cube([30,30,12],center=true);}",
    "tee": "union(){cube([50,10,5]); translate([20,0,0]) cube([10,10,40]);}",
    "spring_plate": "union(){cube([60,20,2]); for(i=[0:11]) translate([i*5,0,2]) cube([1,20,15]);}",
    "bolt_head": "union(){cylinder(r=8,h=5,$fn=6); cylinder(r=4,h=40,$fn=40); "
                 "translate([0,0,40]) sphere(r=4,$fn=40);}",
    "thin_fin": "union(){cube([40,40,3]); translate([19.9,0,3]) cube([0.2,40,30]);}",
    "letters": "union(){cube([70,25,2]); translate([2,2,2]) linear_extrude(height=3) "
               "text(\"LTEXY\",size=18,font=\"Liberation Sans\");}",
    "mushroom": "union(){cylinder(r=2,h=20,$fn=32); "
                "translate([0,0,20]) scale([1,1,0.3]) sphere(r=15,$fn=64);}",
    "chamfer_box": "hull(){translate([1,1,0]) cube([28,18,10]); translate([0,0,1]) cube([30,20,8]);}",
}

#: Where Debian's ``openscad`` package puts its examples.
EXAMPLES = Path("/usr/share/openscad/examples")


def programs(examples=True):
    """``{name: OpenSCAD source (str) or .scad file (Path)}``: :data:`PROGRAMS`, then with
    ``examples`` the package's examples found under :data:`EXAMPLES` (``Folder_file``)."""
    found = dict(PROGRAMS)
    if examples and EXAMPLES.is_dir():
        found.update((f"{p.parent.name}_{p.stem}", p) for p in sorted(EXAMPLES.glob("*/*.scad")))
    return found


def render(name, program, out, timeout=300.0):
    """``out/name.obj`` from ``program`` (source or .scad file); the reason it is left out,
    or None."""
    with tempfile.TemporaryDirectory() as tmp:
        scad, off = Path(tmp) / f"{name}.scad", Path(tmp) / f"{name}.off"
        if isinstance(program, Path):
            scad = program  # an example: run where it is (it may read files beside it)
        else:
            scad.write_text(program + "\n")
        try:
            proc = subprocess.run(["openscad", "-o", str(off), str(scad)], capture_output=True,
                                  text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return f"not rendered in {timeout:g} s"
        if proc.returncode or not off.is_file():
            return "not rendered: " + (proc.stderr.strip().splitlines() or ["no output"])[-1]
        mesh = closed_genus0(off, sizes=(4, 60_000))
        if mesh is None:
            return "not a closed, manifold, genus-0 mesh once coincident vertices are merged"
        igl.write_triangle_mesh(str(out / f"{name}.obj"), *mesh)
    return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="folder of the kept meshes")
    parser.add_argument("--no-examples", action="store_true",
                        help="only the programs written here, not the package's examples")
    args = parser.parse_args(argv)
    if shutil.which("openscad") is None:
        sys.exit("openscad not found: apt-get install openscad")
    args.out.mkdir(parents=True, exist_ok=True)
    found = programs(examples=not args.no_examples)
    kept = 0
    for name, program in found.items():
        reason = render(name, program, args.out)
        kept += reason is None
        print(f"{name:>28}: {reason or 'kept'}", flush=True)
    print(f"{kept} of {len(found)} programs give closed genus-0 meshes, written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
