"""Renders one frame of an mprog .glb (skinned) with Blender's glTF importer and Cycles on
the CPU, for the book's pictures.

Usage:
    blender -b --factory-startup --python scripts/blender_render_glb.py -- IN.glb OUT.png FRAME

The camera looks at the hips from the front left, a sun lights the scene, a floor plane
lies at height 0. 480×480 pixels, 12 samples, no denoiser (Debian's Blender 3.4 is built
without one): a few seconds on two cores.
"""
import sys
import bpy, numpy
if "bool" not in numpy.__dict__:
    numpy.bool = bool
from mathutils import Vector
argv = sys.argv[sys.argv.index("--") + 1:]
glb, out, frame = argv[0], argv[1], int(argv[2])
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 20
bpy.ops.import_scene.gltf(filepath=glb)
scene.frame_set(frame)
arm = [o for o in scene.objects if o.type == "ARMATURE"][0]
hips = arm.matrix_world @ arm.pose.bones[0].head
bpy.ops.object.camera_add(location=hips + Vector((3.2, -3.2, 0.6)))
cam = bpy.context.object
direction = hips - cam.location
cam.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
scene.camera = cam
bpy.ops.object.light_add(type='SUN', location=(0, 0, 5))
bpy.context.object.data.energy = 3
bpy.ops.object.light_add(type='SUN', location=(0, 0, 5), rotation=(1.0, 0.3, 2.5))
bpy.context.object.data.energy = 1.5
bpy.ops.mesh.primitive_plane_add(size=20, location=(hips.x, hips.y, 0))
world = bpy.data.worlds.new("w"); scene.world = world
world.color = (0.8, 0.82, 0.85)
scene.render.engine = 'CYCLES'
scene.cycles.samples = 12
scene.cycles.use_denoising = False
scene.cycles.device = 'CPU'
scene.render.resolution_x, scene.render.resolution_y = 480, 480
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
