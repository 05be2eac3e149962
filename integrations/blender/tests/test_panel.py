"""The mprog add-on's panel and its background run, in Blender's interface (not -b).

    MPROG_BIN=target/release/mprog xvfb-run -a -s "-screen 0 1280x720x24" \
        blender --factory-startup --enable-event-simulate \
        --python integrations/blender/tests/test_panel.py -- tests/fixtures/rigs/mixamo_tall.bvh

With a window (a virtual X server is enough), the add-on installed from a zip and the test
rig as the active armature, driven by timers as a user would drive it:
1. the sidebar is opened and the mprog panel drawn (its tab set to the default one, so no
   click is needed); its draw must run without an error;
2. *Generate motion* is invoked as the panel's button invokes it (`INVOKE_DEFAULT`): the
   run goes on in the background while the interface keeps drawing, and ends with a new
   action on the armature;
3. a second, longer run is cancelled with Esc (a simulated key press): the child process
   is stopped and no action is added.
Prints "mprog_blender_panel: OK …" or "mprog_blender_panel: FAIL …" and exits non-zero on
failure.
"""

import os
import subprocess
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from test_addon import armature, install  # noqa: E402

TIMEOUT = 300.0
state = {"draws": 0, "draw_errors": [], "step": "start", "t0": 0.0, "redraws": 0}


def finish(ok, message):
    print(f"mprog_blender_panel: {'OK' if ok else 'FAIL'} {message}", flush=True)
    os._exit(0 if ok else 1)


def view3d():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return win, area, region


def redraw():
    win, area, region = view3d()
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
    state["redraws"] += 1


def watch_panel():
    """Counts the panel's draws and keeps their errors (Blender only prints them)."""
    import mprog_blender

    panel = mprog_blender.MPROG_PT_panel
    bpy.utils.unregister_class(panel)
    panel.bl_category = "Item"
    original = panel.draw

    def draw(self, context):
        state["draws"] += 1
        try:
            original(self, context)
        except Exception as e:  # noqa: BLE001 - recorded, then reported as a failure
            state["draw_errors"].append(f"{type(e).__name__}: {e}")
            raise

    panel.draw = draw
    bpy.utils.register_class(panel)


def mprog_children(text):
    out = subprocess.run(["pgrep", "-f", text], capture_output=True, text=True)
    return [p for p in out.stdout.split() if p.strip()]


def invoke(text, seconds):
    win, area, region = view3d()
    with bpy.context.temp_override(window=win, area=area, region=region):
        return bpy.ops.mprog.generate("INVOKE_DEFAULT", text=text, seconds=seconds, seed=1)


def step():
    """One tick of the test; returns the delay to the next tick."""
    try:
        return run_step()
    except Exception as e:  # noqa: BLE001
        finish(False, f"{state['step']}: {type(e).__name__}: {e}")


def run_step():
    arm = bpy.data.objects[state["arm"]]
    s = state["step"]
    if s == "start":
        _, area, _ = view3d()
        area.spaces.active.show_region_ui = True
        redraw()
        if state["draw_errors"] or state["draws"] == 0:
            finish(False, f"the panel drew {state['draws']} times: {state['draw_errors']}")
        state["actions"] = len(bpy.data.actions)
        result = invoke("a person walks forward", 2.0)
        if result != {"RUNNING_MODAL"}:
            finish(False, f"invoke: {result}")
        state.update(step="running", t0=time.monotonic(), redraws=0)
        return 0.25
    if s == "running":
        redraw()
        action = arm.animation_data.action if arm.animation_data else None
        if action is not None and action.name.startswith("mprog"):
            first, last = (int(round(v)) for v in action.frame_range)
            state["first"] = (action.name, last - first + 1, time.monotonic() - state["t0"],
                              state["redraws"])
            result = invoke("a person waves with both hands", 60.0)
            if result != {"RUNNING_MODAL"}:
                finish(False, f"second invoke: {result}")
            state.update(step="cancelling", t0=time.monotonic(), actions=len(bpy.data.actions))
            return 1.0
        if time.monotonic() - state["t0"] > TIMEOUT:
            finish(False, "no action after the run")
        return 0.25
    if s == "cancelling":
        if not mprog_children("a person waves with both hands"):
            finish(False, "the second run did not start a child process")
        win = bpy.context.window_manager.windows[0]
        win.event_simulate(type="ESC", value="PRESS")
        win.event_simulate(type="ESC", value="RELEASE")
        state.update(step="cancelled", t0=time.monotonic())
        return 0.5
    if s == "cancelled":
        redraw()
        if time.monotonic() - state["t0"] < 3.0:
            return 0.5
        left = mprog_children("a person waves with both hands")
        if left:
            finish(False, f"Esc left the child running: {left}")
        if len(bpy.data.actions) != state["actions"]:
            finish(False, "a cancelled run added an action")
        name, frames, seconds, redraws = state["first"]
        finish(True, f"panel drawn {state['draws']} times without an error; a run in the "
                     f"background made '{name}' ({frames} frames) in {seconds:.1f} s while "
                     f"the window redrew {redraws} times; Esc stopped the second run, no "
                     f"action added")
    return None


def main():
    if bpy.app.background:
        finish(False, "run with a window (xvfb-run blender …), not -b")
    rig = sys.argv[sys.argv.index("--") + 1]
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 24, 1.0
    install()
    watch_panel()
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    arm = armature(rig)
    arm.select_set(True)
    state["arm"] = arm.name
    bpy.app.timers.register(step, first_interval=1.0)


try:
    main()
except Exception as e:  # noqa: BLE001
    finish(False, f"setup: {type(e).__name__}: {e}")
