"""Checks an mprog glTF export (.glb) with Blender's own glTF importer.

Usage:
    blender -b --factory-startup --python scripts/blender_gltf_check.py -- IN.glb EXPECTED.npy [--tol 0.01] [--names N0,N1,…,N21]

IN.glb is a file written by mprog's glTF writer for one person; EXPECTED.npy holds the joint
positions it was written from, float32 [frames, 22, 3], metres, Y up (mprog's convention,
and glTF's). The script sets the scene to 20 fps, imports the file with Blender's glTF
importer (which converts Y up to Blender's Z up: (x, y, z) -> (x, -z, y)), evaluates every
frame from the start of the imported action, reads the world-space position of the 22
joints, and compares them with EXPECTED in Blender's axes. mprog's .glb is skinned, so the
importer makes an armature (its pose bones' heads are the joints) with an action, and the
body mesh deformed by it; a skin-less file (older mprog) gives one empty per node, which
is read instead. --names gives the 22 node names in HumanML3D order for a file written
with --rig (default: the HumanML3D names). It prints one line
"blender_gltf_check: OK|FAIL max error E m (frames F, joints 22, armature yes|no)" and exits
non-zero on failure, or when a skinned file does not import as an armature with an action.

Blender 3.4's glTF importer reads meshes with `np.bool`, which NumPy 1.24 (Debian 12's)
removed; the alias is put back before the import.
"""

import array
import ast
import struct
import sys

import bpy
import numpy
from mathutils import Vector

if "bool" not in numpy.__dict__:
    numpy.bool = bool

JOINT_NAMES = [
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
    "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar",
    "right_collar", "head", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
    "left_wrist", "right_wrist",
]


def load_npy_f32(path):
    """Reads a little-endian float32 C-order .npy file: returns (shape, flat floats)."""
    with open(path, "rb") as f:
        if f.read(6) != b"\x93NUMPY":
            raise ValueError(f"{path} is not a .npy file")
        major = f.read(2)[0]
        size = struct.unpack("<H" if major == 1 else "<I", f.read(2 if major == 1 else 4))[0]
        header = ast.literal_eval(f.read(size).decode("latin1"))
        if header["descr"] not in ("<f4", "=f4") or header["fortran_order"]:
            raise ValueError(f"{path}: expected little-endian float32 C order, got {header}")
        data = array.array("f")
        data.frombytes(f.read())
    return tuple(header["shape"]), data.tolist()


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) < 2:
        print(__doc__)
        sys.exit(2)
    tol = float(argv[argv.index("--tol") + 1]) if "--tol" in argv else 0.01
    names = argv[argv.index("--names") + 1].split(",") if "--names" in argv else JOINT_NAMES
    if len(names) != len(JOINT_NAMES):
        raise ValueError(f"--names needs 22 names, got {len(names)}")
    return argv[0], argv[1], tol, names


def main():
    glb_path, npy_path, tol, names = parse_args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 20, 1.0
    (frames, joints, dims), flat = load_npy_f32(npy_path)
    if joints != len(JOINT_NAMES) or dims != 3:
        raise ValueError(f"expected [frames, 22, 3] positions, got {(frames, joints, dims)}")
    result = bpy.ops.import_scene.gltf(filepath=glb_path)
    if result != {"FINISHED"}:
        raise RuntimeError(f"glTF import failed: {result}")
    objects = {o.name: o for o in scene.objects}
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    if armatures:
        arm = armatures[0]
        missing = [n for n in names if n not in arm.pose.bones]
        if not (arm.animation_data and arm.animation_data.action):
            raise RuntimeError("the armature has no action")
        meshes = [o for o in scene.objects if o.type == "MESH"
                  and any(m.type == "ARMATURE" for m in o.modifiers)]
        if not meshes:
            raise RuntimeError("no mesh is deformed by the armature")

        def joint_at(name):
            return arm.matrix_world @ arm.pose.bones[name].head
    else:
        missing = [n for n in names if n not in objects]

        def joint_at(name):
            return objects[name].matrix_world.translation
    if missing:
        raise RuntimeError(f"joints missing from the import: {missing}")
    actions = [o.animation_data.action for o in scene.objects
               if o.animation_data and o.animation_data.action]
    if not actions:
        raise RuntimeError("the import has no animation")
    start = int(round(min(a.frame_range[0] for a in actions)))

    def want(f, j):
        x, y, z = flat[(f * joints + j) * 3:(f * joints + j) * 3 + 3]
        return Vector((x, -z, y))
    worst = 0.0
    for f in range(frames):
        scene.frame_set(start + f)
        for j, name in enumerate(names):
            worst = max(worst, (joint_at(name) - want(f, j)).length)
    status = "OK" if worst < tol else "FAIL"
    print(f"blender_gltf_check: {status} max error {worst:.3e} m (frames {frames}, joints {joints}, "
          f"armature {'yes' if armatures else 'no'})")
    sys.exit(0 if status == "OK" else 1)


try:
    main()
except Exception as e:  # report and fail instead of leaving Blender's prompt
    print(f"blender_gltf_check: FAIL {type(e).__name__}: {e}")
    sys.exit(1)
