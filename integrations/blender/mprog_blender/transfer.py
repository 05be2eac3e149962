"""Putting a BVH that mprog wrote on an armature's rig onto that armature as a new action.

The BVH has the armature's bones, names and rest offsets (it was made with `--rig` the
armature's own export), but Blender's importer builds bones of its own (their rolls, so
their local axes, differ), so actions cannot simply be swapped. Instead each frame, for
every bone, the imported bone's turn away from its rest pose (in armature space) is given
to the armature's bone with the same name: posed = turn · rest, then written as the pose
bone's location and rotation relative to its parent, keyed at every frame.
"""

import builtins
import contextlib

import bpy


def _frames(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.strip().startswith("Frames:"):
                return int(line.split(":", 1)[1])
    raise ValueError(f"{path}: no Frames: line")


@contextlib.contextmanager
def without_u_mode():
    """Blender 3.4's BVH importer opens files with mode 'rU', which Python 3.11 (Debian's
    Blender) rejects: drop the 'U' while it runs."""
    real_open = builtins.open

    def open_without_u(file, mode="r", *args, **kwargs):
        return real_open(file, mode.replace("U", ""), *args, **kwargs)

    builtins.open = open_without_u
    try:
        yield
    finally:
        builtins.open = real_open


def _import(context, path, start):
    before = set(bpy.data.objects)
    with without_u_mode():
        result = _import_bvh(path, start)
    if result != {"FINISHED"}:
        raise RuntimeError(f"BVH import failed: {result}")
    new = [o for o in bpy.data.objects if o not in before and o.type == "ARMATURE"]
    if len(new) != 1:
        raise RuntimeError("the BVH import made no armature")
    return new[0]


def _import_bvh(path, start):
    return bpy.ops.import_anim.bvh(
        filepath=path, target="ARMATURE", global_scale=1.0, frame_start=start,
        use_fps_scale=False, update_scene_fps=False, update_scene_duration=False,
        rotate_mode="NATIVE", axis_forward="Y", axis_up="Z")


def _ordered(bones):
    """Bones, parents first."""
    out, stack = [], [b for b in bones if b.parent is None]
    while stack:
        b = stack.pop()
        out.append(b)
        stack.extend(b.children)
    return out


def import_onto(context, path, arm, name, start):
    """Puts the BVH at `path` on `arm` as a new action called `name`, from frame `start`;
    returns (action, frames)."""
    count = _frames(path)
    previous_active = context.view_layer.objects.active
    imp = _import(context, path, start)
    bones = _ordered(arm.data.bones)
    rest = {b.name: b.matrix_local.copy() for b in bones}
    imp_rest = {b.name: b.matrix_local.copy() for b in imp.data.bones}
    keys = {b.name: ([], []) for b in bones}  # locations, rotations per frame
    scene = context.scene
    for f in range(count):
        scene.frame_set(start + f)
        posed = {}
        for b in bones:
            n = b.name
            if n in imp.pose.bones:
                turn = imp.pose.bones[n].matrix @ imp_rest[n].inverted()
                posed[n] = turn @ rest[n]
            elif b.parent is not None:
                p = b.parent.name
                posed[n] = posed[p] @ rest[p].inverted() @ rest[n]
            else:
                posed[n] = rest[n]
            if b.parent is not None:
                p = b.parent.name
                base = posed[p] @ rest[p].inverted() @ rest[n]
            else:
                base = rest[n]
            basis = base.inverted() @ posed[n]
            loc, rot, _ = basis.decompose()
            keys[n][0].append(loc)
            keys[n][1].append(rot)
    action = bpy.data.actions.new(name)
    if arm.animation_data is None:
        arm.animation_data_create()
    arm.animation_data.action = action
    for b in bones:
        pb = arm.pose.bones[b.name]
        locs, rots = keys[b.name]
        _curves(action, pb, "location", [tuple(v) for v in locs], start)
        mode = pb.rotation_mode
        if mode == "QUATERNION":
            values, prev = [], None
            for q in rots:
                if prev is not None and q.dot(prev) < 0:
                    q = -q
                values.append(tuple(q))
                prev = q
            _curves(action, pb, "rotation_quaternion", values, start)
        elif mode == "AXIS_ANGLE":
            values = []
            for q in rots:
                axis, angle = q.to_axis_angle()
                values.append((angle, axis.x, axis.y, axis.z))
            _curves(action, pb, "rotation_axis_angle", values, start)
        else:
            values, prev = [], None
            for q in rots:
                e = q.to_euler(mode, prev) if prev is not None else q.to_euler(mode)
                values.append(tuple(e))
                prev = e
            _curves(action, pb, "rotation_euler", values, start)
    imp_action = imp.animation_data.action if imp.animation_data else None
    data = imp.data
    bpy.data.objects.remove(imp)
    bpy.data.armatures.remove(data)
    if imp_action is not None:
        bpy.data.actions.remove(imp_action)
    context.view_layer.objects.active = previous_active or arm
    scene.frame_set(start)
    return action, count


def _curves(action, pb, prop, values, start):
    """One F-curve per component of `prop`, a key per frame."""
    path = f'pose.bones["{bpy.utils.escape_identifier(pb.name)}"].{prop}'
    for i in range(len(values[0])):
        fc = action.fcurves.new(path, index=i, action_group=pb.name)
        fc.keyframe_points.add(len(values))
        co = []
        for f, v in enumerate(values):
            co += [start + f, v[i]]
        fc.keyframe_points.foreach_set("co", co)
        fc.update()

