"""Checks an mprog glTF export (.glb) with Blender's own glTF importer.

Usage:
    blender -b --factory-startup --python scripts/blender_gltf_check.py -- IN.glb EXPECTED.npy [--tol 0.01]

IN.glb is a file written by mprog's glTF writer for one person; EXPECTED.npy holds the joint
positions it was written from, float32 [frames, 22, 3], metres, Y up (mprog's convention,
and glTF's). The script sets the scene to 20 fps, imports the file with Blender's glTF
importer (which converts Y up to Blender's Z up: (x, y, z) -> (x, -z, y)), evaluates every
frame from the start of the imported action, reads the world-space location of the objects
named after the 22 HumanML3D joints (the importer makes each skin-less node an empty), and
compares them with EXPECTED in Blender's axes. It prints one line
"blender_gltf_check: OK|FAIL max error E m (frames F, joints 22)" and exits non-zero on
failure.
"""

import array
import ast
import struct
import sys

import bpy
from mathutils import Vector

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
    return argv[0], argv[1], tol


def main():
    glb_path, npy_path, tol = parse_args()
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
    missing = [n for n in JOINT_NAMES if n not in objects]
    if missing:
        raise RuntimeError(f"nodes missing from the import: {missing}")
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
        for j, name in enumerate(JOINT_NAMES):
            at = objects[name].matrix_world.translation
            worst = max(worst, (at - want(f, j)).length)
    status = "OK" if worst < tol else "FAIL"
    print(f"blender_gltf_check: {status} max error {worst:.3e} m (frames {frames}, joints {joints})")
    sys.exit(0 if status == "OK" else 1)


try:
    main()
except Exception as e:  # report and fail instead of leaving Blender's prompt
    print(f"blender_gltf_check: FAIL {type(e).__name__}: {e}")
    sys.exit(1)
