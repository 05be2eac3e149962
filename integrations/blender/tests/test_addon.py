"""Headless test of the mprog add-on with Blender's own Python.

    MPROG_BIN=target/release/mprog blender -b --factory-startup \
        --python integrations/blender/tests/test_addon.py -- tests/fixtures/rigs/mixamo_tall.bvh

Installs the add-on from a zip of `integrations/blender/mprog_blender/` and enables it;
makes the active armature by importing the rig with Blender's BVH importer (centimetres
to metres, Z up), dropping its action, and placing, turning and scaling its object; sets the scene to 24 fps; runs
`bpy.ops.mprog.generate(text="a person walks forward", seconds=4, seed=1)` and checks the
armature got a new action of at least 70 frames in which the hips move; then checks that a
program with a typo is refused with its diagnostic at its line. Prints
"mprog_blender_test: OK …" or "mprog_blender_test: FAIL …" and exits non-zero on failure.
(Set BLENDER_USER_SCRIPTS to a temporary folder to keep the install out of your profile.)
"""

import os
import sys
import tempfile
import zipfile

import addon_utils
import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def install():
    package = os.path.join(HERE, "..", "mprog_blender")
    zpath = os.path.join(tempfile.mkdtemp(), "mprog_blender.zip")
    with zipfile.ZipFile(zpath, "w") as z:
        for name in sorted(os.listdir(package)):
            if name.endswith(".py"):
                z.write(os.path.join(package, name), f"mprog_blender/{name}")
    result = bpy.ops.preferences.addon_install(filepath=zpath, overwrite=True)
    assert result == {"FINISHED"}, f"install: {result}"
    addon_utils.enable("mprog_blender", default_set=True)
    assert hasattr(bpy.ops.mprog, "generate"), "the operator is registered"


def armature(rig):
    from mprog_blender.transfer import without_u_mode

    with without_u_mode():
        bpy.ops.import_anim.bvh(filepath=rig, global_scale=0.01)
    arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"][0]
    old = arm.animation_data.action
    arm.animation_data.action = None
    bpy.data.actions.remove(old)
    bpy.context.view_layer.objects.active = arm
    return arm


def hips_at(arm, frame):
    bpy.context.scene.frame_set(frame)
    return arm.matrix_world @ arm.pose.bones["Hips"].head


def same_as_blenders_import(arm, first, last):
    """Makes the same motion with mprog directly, imports it with Blender's BVH importer
    as an armature of its own, and returns the largest distance between a bone head of
    that armature and of `arm` over the frames (the action must reproduce it)."""
    import subprocess

    from mprog_blender import runner, transfer

    work = tempfile.mkdtemp()
    rig, out = os.path.join(work, "rig.bvh"), os.path.join(work, "ref.bvh")
    runner.export_rig(arm, rig)
    subprocess.run([os.environ["MPROG_BIN"], "gen", "--text", "a person walks forward",
                    "--seconds", "4", "--seed", "1", "--rig", rig, "--bvh-fps", "24",
                    "-o", out], check=True, capture_output=True)
    ref = transfer._import(bpy.context, out, first)
    bpy.context.view_layer.objects.active = arm
    worst = 0.0
    for f in range(first, last + 1):
        bpy.context.scene.frame_set(f)
        for pb in arm.pose.bones:
            if pb.name in ref.pose.bones:
                # In armature space: the character keeps its object's placement.
                worst = max(worst, (pb.head - ref.pose.bones[pb.name].head).length)
    bpy.data.objects.remove(ref)
    assert worst < 1e-3, f"the action puts bones {worst} m from Blender's own import"
    return worst


def main():
    rig = sys.argv[sys.argv.index("--") + 1]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 24, 1.0
    scene.frame_set(1)
    install()
    arm = armature(rig)
    # Placed, turned and scaled as imported characters often are.
    arm.location, arm.rotation_euler, arm.scale = (1.0, 2.0, 0.0), (0.0, 0.0, 0.7), (2.0, 2.0, 2.0)
    result = bpy.ops.mprog.generate(text="a person walks forward", seconds=4.0, seed=1)
    assert result == {"FINISHED"}, f"generate: {result}"
    action = arm.animation_data.action
    assert action is not None and action.name.startswith("mprog"), "a new action"
    first, last = (int(round(v)) for v in action.frame_range)
    frames = last - first + 1
    assert frames >= 70, f"{frames} frames"
    a, b = hips_at(arm, first), hips_at(arm, last)
    travel = ((b.x - a.x) ** 2 + (b.y - a.y) ** 2) ** 0.5 / arm.scale.x
    assert travel > 1.0, f"the hips moved {travel:.2f} m"
    fingers = [fc for fc in action.fcurves if "LeftHandIndex2" in fc.data_path]
    assert fingers, "every bone is keyed"
    lowest = min(hips_at(arm, f).z for f in range(first, last + 1)) / arm.scale.z
    worst = same_as_blenders_import(arm, first, last)
    # A program with a typo: refused, nothing added.
    text = bpy.data.texts.new("walk_typo")
    text.write('prompt "a person walks"\nlength 2s\nalways {\n    dist(l_hand, hed) < 1 m\n}\n')
    actions = len(bpy.data.actions)
    try:
        result = bpy.ops.mprog.generate(program="walk_typo", seed=1)
    except RuntimeError as e:  # background mode raises the operator's error reports
        result = {"CANCELLED"}
        assert ":4:" in str(e) and "hed" in str(e), f"the diagnostic: {e}"
    assert result == {"CANCELLED"}, f"a bad program: {result}"
    assert len(bpy.data.actions) == actions, "nothing added for a bad program"
    print(f"mprog_blender_test: OK action '{action.name}' of {frames} frames at 24 fps, "
          f"hips travel {travel:.2f} m, lowest hips {lowest:.2f} m, every bone within "
          f"{worst:.1e} m of Blender's own import of the same motion")


if __name__ == "__main__":
    try:
        main()
    except Exception as e:
        print(f"mprog_blender_test: FAIL {type(e).__name__}: {e}")
        sys.exit(1)
