"""Makes a skinned glTF character (.glb) from a BVH rig with Blender, as an artist's export.

Usage:
    blender -b --factory-startup --python scripts/blender_make_glb_rig.py -- IN.bvh OUT.glb [--prefix mixamorig:] [--scale 0.01]

Imports IN.bvh's rest pose (--scale: metres per file unit), renames every bone with
--prefix, gives each bone a box of its own length bound to it with weight 1 (one mesh,
an Armature modifier, a vertex group per bone), and exports OUT.glb with Blender's glTF
exporter: an armature node, joint nodes with Blender's bone rest rotations (each bone's Y
axis along the bone, as Blender makes them), the skin and the mesh, no animation. This is
how `tests/fixtures/rigs/mixamo_tall.glb` was made (the `--rig character.glb` tests).
"""

import builtins
import sys

import bpy
import bmesh
from mathutils import Matrix, Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) < 2:
        sys.exit(__doc__)
    opts = {"prefix": "", "scale": 1.0}
    rest = argv[2:]
    while rest:
        key = rest.pop(0)
        if key == "--prefix":
            opts["prefix"] = rest.pop(0)
        elif key == "--scale":
            opts["scale"] = float(rest.pop(0))
        else:
            sys.exit(f"unknown option {key}")
    return argv[0], argv[1], opts


def main():
    src, out, opts = parse_args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    # Blender 3.4's BVH importer opens with mode 'rU', which Python 3.11 rejects.
    real_open = builtins.open
    builtins.open = lambda file, mode="r", *a, **k: real_open(file, mode.replace("U", ""), *a, **k)
    try:
        bpy.ops.import_anim.bvh(filepath=src, global_scale=opts["scale"], rotate_mode="NATIVE")
    finally:
        builtins.open = real_open
    arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    arm.animation_data_clear()
    arm.name = "Armature"
    for b in arm.data.bones:
        b.name = opts["prefix"] + b.name

    mesh = bpy.data.meshes.new("Body")
    bm = bmesh.new()
    groups = []
    for bone in arm.data.bones:
        head, tail = bone.head_local, bone.tail_local
        length = (tail - head).length
        if length < 1e-6:
            continue
        width = min(0.04, 0.2 * length)
        # A box along the bone's Y axis, in the bone's rest frame.
        frame = bone.matrix_local.to_3x3()
        verts = []
        for y in (0.1 * length, 0.9 * length):
            for x, z in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                local = Vector((x * width, y, z * width))
                verts.append(bm.verts.new(head + frame @ local))
        for face in ((0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)):
            bm.faces.new([verts[i] for i in face])
        groups.append((bone.name, [v for v in verts]))
    bm.verts.index_update()
    index_groups = [(name, [v.index for v in vs]) for name, vs in groups]
    bm.to_mesh(mesh)
    bm.free()
    skin = bpy.data.materials.new("Skin")
    skin.use_nodes = True
    skin.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.2, 0.45, 0.8, 1)
    mesh.materials.append(skin)
    body = bpy.data.objects.new("Body", mesh)
    bpy.context.scene.collection.objects.link(body)
    for name, indices in index_groups:
        vg = body.vertex_groups.new(name=name)
        vg.add(indices, 1.0, "REPLACE")
    body.parent = arm
    body.matrix_parent_inverse = Matrix.Identity(4)
    mod = body.modifiers.new("Armature", "ARMATURE")
    mod.object = arm

    bpy.context.scene.frame_set(1)
    bpy.ops.export_scene.gltf(
        filepath=out,
        export_format="GLB",
        export_animations=False,
        export_skins=True,
        export_apply=False,
        export_yup=True,
    )
    print(f"blender_make_glb_rig: wrote {out} ({len(arm.data.bones)} bones, {len(index_groups)} boxes)")


main()
