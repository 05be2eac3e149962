"""mprog for Blender: generate a motion from a text prompt or an mprog program onto the
active armature.

The operator `bpy.ops.mprog.generate(text=..., program=..., seconds=..., seed=...)`:

1. exports the active armature's skeleton as BVH (Blender's own exporter: only its
   hierarchy and rest pose are read by mprog);
2. runs the `mprog` binary (the add-on preferences, else `$MPROG_BIN`, else `PATH`):
   `mprog gen --text … --seconds … --seed …` for a prompt, `mprog run PROGRAM --seed …`
   for a program (a `.mprog` file or the name of a Blender text), with `--rig` that BVH and
   `--bvh-fps` the scene's frame rate, so the result comes back on the armature's own
   bones, names, rest offsets and units; a program is checked first (`mprog check
   --format json`) and its diagnostics are reported at their lines;
3. imports the result and puts it on the armature as a new action, bone by bone (each
   pose bone gets the imported bone's turn away from the rest pose), keyed at every
   frame from the scene's current frame.

From the panel (View3D › Sidebar › mprog) the command runs in the background with its
progress in the status bar, and can be cancelled with Esc; called from Python (or
headless, `blender -b`) it runs to the end before returning.
"""

bl_info = {
    "name": "mprog: programmable motion",
    "author": "mprog",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > mprog",
    "description": "Generate a motion from a prompt or an mprog program onto the active armature",
    "category": "Animation",
}

import bpy

from . import runner, transfer

ADDON = __name__


class MprogPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    binary: bpy.props.StringProperty(
        name="mprog binary",
        description="Path to the mprog executable (empty: $MPROG_BIN, else PATH)",
        subtype="FILE_PATH",
        default="",
    )

    def draw(self, context):
        self.layout.prop(self, "binary")


class MprogSettings(bpy.types.PropertyGroup):
    text: bpy.props.StringProperty(name="Prompt", default="a person walks forward")
    program: bpy.props.StringProperty(
        name="Program",
        description="An mprog program: a .mprog file or the name of a text in this file "
        "(empty: generate from the prompt)",
        default="",
    )
    seconds: bpy.props.FloatProperty(name="Seconds", default=4.0, min=0.5, max=200.0)
    seed: bpy.props.IntProperty(name="Seed", default=1, min=0)


def _binary(context):
    prefs = context.preferences.addons.get(ADDON)
    configured = prefs.preferences.binary if prefs else ""
    return runner.find_binary(bpy.path.abspath(configured) if configured else "")


def _program_source(program):
    """(path, None) for a .mprog file, (None, text) for a Blender text, (None, None)."""
    if not program:
        return None, None
    if program in bpy.data.texts:
        return None, bpy.data.texts[program].as_string()
    return bpy.path.abspath(program), None


class MPROG_OT_generate(bpy.types.Operator):
    """Generate a motion with mprog onto the active armature, as a new action"""

    bl_idname = "mprog.generate"
    bl_label = "Generate motion"
    bl_options = {"REGISTER", "UNDO"}

    text: bpy.props.StringProperty(name="Prompt", default="")
    program: bpy.props.StringProperty(name="Program", default="")
    seconds: bpy.props.FloatProperty(name="Seconds", default=4.0, min=0.5, max=200.0)
    seed: bpy.props.IntProperty(name="Seed", default=1, min=0)

    _job = None
    _timer = None

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "ARMATURE"

    def _start(self, context):
        arm = context.active_object
        binary = _binary(context)
        if binary is None:
            raise runner.MprogError(
                "cannot find the mprog binary: set it in the add-on preferences, "
                "or $MPROG_BIN, or put mprog on PATH")
        path, source = _program_source(self.program)
        if not (self.text or path or source):
            raise runner.MprogError("give a prompt or a program")
        scene = context.scene
        fps = scene.render.fps / scene.render.fps_base
        return runner.Job(binary, arm, text=self.text, program_path=path,
                          program_source=source, seconds=self.seconds, seed=self.seed,
                          fps=fps)

    def _finish(self, context, job):
        arm = job.armature
        name = "mprog: " + (self.program or self.text)[:48]
        action, frames = transfer.import_onto(context, job.output, arm, name,
                                              context.scene.frame_current)
        self.report({"INFO"}, f"mprog: {frames} frames on {arm.name} as action '{action.name}'")

    def execute(self, context):
        try:
            job = self._start(context)
            job.run_to_end()
            self._finish(context, job)
        except runner.MprogError as e:
            for line in str(e).splitlines() or ["mprog failed"]:
                self.report({"ERROR"}, line)
            return {"CANCELLED"}
        return {"FINISHED"}

    def invoke(self, context, event):
        try:
            self._job = self._start(context)
            self._job.start()
        except runner.MprogError as e:
            for line in str(e).splitlines():
                self.report({"ERROR"}, line)
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, 100)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            self._job.cancel()
            self._end(context)
            self.report({"WARNING"}, "mprog: cancelled")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        status = self._job.poll()
        context.workspace.status_text_set(f"mprog: {self._job.last_line}")
        wm.progress_update(int(self._job.progress * 100))
        if status is None:
            return {"RUNNING_MODAL"}
        self._end(context)
        try:
            self._job.check()
            self._finish(context, self._job)
        except runner.MprogError as e:
            for line in str(e).splitlines():
                self.report({"ERROR"}, line)
            return {"CANCELLED"}
        return {"FINISHED"}

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)


class MPROG_PT_panel(bpy.types.Panel):
    bl_label = "mprog"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "mprog"

    def draw(self, context):
        s = context.scene.mprog
        col = self.layout.column()
        col.prop(s, "text")
        col.prop_search(s, "program", bpy.data, "texts", text="Program text")
        col.prop(s, "program", text="or file")
        row = col.row()
        row.prop(s, "seconds")
        row.prop(s, "seed")
        obj = context.active_object
        if obj is None or obj.type != "ARMATURE":
            col.label(text="Select an armature", icon="ERROR")
        op = col.operator(MPROG_OT_generate.bl_idname, icon="ARMATURE_DATA")
        op.text, op.program, op.seconds, op.seed = s.text, s.program, s.seconds, s.seed


CLASSES = (MprogPreferences, MprogSettings, MPROG_OT_generate, MPROG_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.mprog = bpy.props.PointerProperty(type=MprogSettings)


def unregister():
    del bpy.types.Scene.mprog
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
