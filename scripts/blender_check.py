"""Checks an mprog BVH export with Blender's own BVH importer.

Usage:
    blender -b --factory-startup --python scripts/blender_check.py -- IN.bvh EXPECTED.npy [--zup] [--tol 0.01] [--names N0,…,N21] [--scale S]

IN.bvh is a file written by mprog's BVH exporter; EXPECTED.npy holds the joint positions it
was written from, float32 [frames, 22, 3], metres, Y up (mprog's convention). The script
imports the BVH with Blender's importer (a Y-up file with Blender's default axis conversion,
forward -Z / up Y, which maps (x, y, z) to (x, -z, y); with --zup the file is already in
Blender's Z-up axes and is imported with forward Y / up Z, i.e. unchanged), evaluates every
frame, reads the world-space head of the bones named after the 22 HumanML3D joints, and
compares them with EXPECTED converted to Blender's axes. It prints one line
"blender_check: OK|FAIL max error E m (frames F, joints 22)" and exits non-zero on failure.

For a file written on a user's rig (`--rig`), --names gives the bones of the 22 joints in
HumanML3D order (e.g. Hips,LeftUpLeg,RightUpLeg,Spine,LeftLeg,…,RightHand), --scale the
importer's global scale (0.01 for a rig in centimetres), and EXPECTED.npy is what mprog's own
reader makes of IN.bvh (`mprog convert IN.bvh -o EXPECTED.npy`): the check is then that
Blender reads the file as mprog does. With --names it also prints one line
"blender_check: feet median lowest L m, hips travel D m": the median over frames of the
lowest of the ankles and toes, and the horizontal distance the hips travel (both in
Blender's Z-up metres).

Blender 3.4's importer opens files with mode 'rU', which Python 3.11 rejects; the builtin
open is wrapped to drop the 'U' during the import.
"""

import array
import ast
import builtins
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
    """Reads a little-endian float32 C-order .npy file (Blender's Python may lack numpy):
    returns (shape, flat list of floats)."""
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
    shape = tuple(header["shape"])
    count = 1
    for d in shape:
        count *= d
    if len(data) != count:
        raise ValueError(f"{path}: {len(data)} values for shape {shape}")
    return shape, data.tolist()


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) < 2:
        print(__doc__)
        sys.exit(2)
    tol = 0.01
    if "--tol" in argv:
        tol = float(argv[argv.index("--tol") + 1])
    names = argv[argv.index("--names") + 1].split(",") if "--names" in argv else None
    if names is not None and len(names) != len(JOINT_NAMES):
        raise ValueError(f"--names needs 22 names, got {len(names)}")
    scale = float(argv[argv.index("--scale") + 1]) if "--scale" in argv else 1.0
    return argv[0], argv[1], "--zup" in argv, tol, names, scale


def import_bvh(path, zup, scale):
    real_open = builtins.open

    def open_without_u(file, mode="r", *args, **kwargs):
        return real_open(file, mode.replace("U", ""), *args, **kwargs)

    builtins.open = open_without_u
    try:
        axes = {"axis_forward": "Y", "axis_up": "Z"} if zup else {"axis_forward": "-Z", "axis_up": "Y"}
        result = bpy.ops.import_anim.bvh(
            filepath=path, target="ARMATURE", global_scale=scale, frame_start=1,
            use_fps_scale=False, update_scene_fps=True, update_scene_duration=True,
            rotate_mode="NATIVE", **axes)
    finally:
        builtins.open = real_open
    if result != {"FINISHED"}:
        raise RuntimeError(f"BVH import failed: {result}")
    arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
    if len(arm) != 1:
        raise RuntimeError(f"expected one armature, found {len(arm)}")
    return arm[0]


def main():
    bvh_path, npy_path, zup, tol, names, scale = parse_args()
    report = names is not None
    names = names or JOINT_NAMES
    # Start from an empty scene (the factory scene has a cube, camera and light).
    bpy.ops.wm.read_factory_settings(use_empty=True)
    (frames, joints, dims), flat = load_npy_f32(npy_path)
    if joints != len(JOINT_NAMES) or dims != 3:
        raise ValueError(f"expected [frames, 22, 3] positions, got {(frames, joints, dims)}")

    def want(f, j):
        # mprog Y up -> Blender Z up: (x, y, z) -> (x, -z, y), as either import path gives.
        x, y, z = flat[(f * joints + j) * 3:(f * joints + j) * 3 + 3]
        return Vector((x, -z, y))
    arm = import_bvh(bvh_path, zup, scale)
    scene = bpy.context.scene
    missing = [n for n in names if n not in arm.pose.bones]
    if missing:
        raise RuntimeError(f"bones missing from the import: {missing}")
    worst = 0.0
    lows, hips = [], []
    for f in range(frames):
        scene.frame_set(1 + f)
        world = arm.matrix_world
        heads = [world @ arm.pose.bones[name].head for name in names]
        for j, head in enumerate(heads):
            worst = max(worst, (head - want(f, j)).length)
        lows.append(min(heads[j].z for j in (7, 8, 10, 11)))
        hips.append(heads[0].copy())
    if report:
        lows.sort()
        travel = sum(((b.x - a.x) ** 2 + (b.y - a.y) ** 2) ** 0.5 for a, b in zip(hips, hips[1:]))
        print(f"blender_check: feet median lowest {lows[len(lows) // 2]:.4f} m, hips travel {travel:.3f} m")
    status = "OK" if worst < tol else "FAIL"
    print(f"blender_check: {status} max error {worst:.3e} m (frames {frames}, joints {joints}, "
          f"fps {scene.render.fps}/{scene.render.fps_base})")
    sys.exit(0 if status == "OK" else 1)


try:
    main()
except Exception as e:  # report and fail instead of leaving Blender's prompt
    print(f"blender_check: FAIL {type(e).__name__}: {e}")
    sys.exit(1)
