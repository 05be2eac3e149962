"""Running mprog from Blender: finding the binary, exporting the armature's skeleton as
the rig, checking a program, and the `mprog gen` / `mprog run` child process."""

import json
import os
import shutil
import subprocess
import tempfile
import time

import bpy


class MprogError(Exception):
    """A failure to report in Blender (one line per problem)."""


def find_binary(configured=""):
    """The mprog executable: `configured` (the add-on preferences), else $MPROG_BIN, else
    `mprog` on PATH; None if none is there."""
    for candidate in (configured, os.environ.get("MPROG_BIN", "")):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("mprog")


def export_rig(arm, path):
    """Writes the armature's hierarchy and rest pose as BVH (Blender's exporter; mprog reads
    the hierarchy only, so the frame written does not matter)."""
    frame = bpy.context.scene.frame_current
    with bpy.context.temp_override(object=arm, active_object=arm, selected_objects=[arm]):
        result = bpy.ops.export_anim.bvh(
            filepath=path, check_existing=False, frame_start=frame, frame_end=frame,
            global_scale=1.0, rotate_mode="NATIVE", root_transform_only=False)
    if result != {"FINISHED"}:
        raise MprogError(f"cannot export {arm.name} as BVH: {result}")


def check_program(binary, path):
    """Runs `mprog check --format json`; raises with one `file:line:column: message` per
    error."""
    out = subprocess.run([binary, "check", path, "--format", "json"],
                         capture_output=True, text=True)
    try:
        report = json.loads(out.stdout)
    except ValueError:
        raise MprogError((out.stderr or out.stdout or "mprog check failed").strip()) from None
    if report.get("ok", False):
        return
    lines = []
    for d in report.get("diagnostics", []):
        if d.get("severity") != "error":
            continue
        hint = f" ({d['hint']})" if d.get("hint") else ""
        lines.append(f"{report.get('file', path)}:{d.get('line')}:{d.get('column')}: "
                     f"{d.get('message')}{hint}")
    raise MprogError("\n".join(lines) or "the program does not check")


class Job:
    """One generation: the rig exported, the program checked, the child process."""

    def __init__(self, binary, armature, text="", program_path=None, program_source=None,
                 seconds=4.0, seed=1, fps=20.0):
        self.binary, self.armature = binary, armature
        self.dir = tempfile.mkdtemp(prefix="mprog_blender_")
        self.rig = os.path.join(self.dir, "rig.bvh")
        self.output = os.path.join(self.dir, "motion.bvh")
        export_rig(armature, self.rig)
        common = ["--rig", self.rig, "--bvh-fps", f"{fps:g}", "-o", self.output]
        if program_source is not None:
            program_path = os.path.join(self.dir, "program.mprog")
            with open(program_path, "w", encoding="utf-8") as f:
                f.write(program_source)
        if program_path:
            if not os.path.isfile(program_path):
                raise MprogError(f"no program file {program_path}")
            check_program(binary, program_path)
            self.cmd = [binary, "run", program_path, "--seed", str(seed), "--no-baseline"]
        else:
            self.cmd = [binary, "gen", "--text", text, "--seconds", f"{seconds:g}",
                        "--seed", str(seed)]
        self.cmd += common
        self.proc = None
        self.started = 0.0
        self.last_line = "starting"
        self.log = os.path.join(self.dir, "mprog.log")

    def start(self):
        env = dict(os.environ, NO_COLOR="1")
        self._log = open(self.log, "w+", encoding="utf-8", errors="replace")
        self.proc = subprocess.Popen(self.cmd, stdout=self._log, stderr=subprocess.STDOUT,
                                     env=env)
        self.started = time.monotonic()

    @property
    def progress(self):
        """A guess in [0, 1): mprog prints no progress when not on a terminal."""
        return 1.0 - 0.5 ** ((time.monotonic() - self.started) / 10.0)

    def poll(self):
        """The exit status, or None while it runs; updates `last_line`."""
        status = self.proc.poll()
        try:
            with open(self.log, encoding="utf-8", errors="replace") as f:
                lines = [l.strip() for l in f.read().splitlines() if l.strip()]
            if lines:
                self.last_line = lines[-1][:120]
        except OSError:
            pass
        return status

    def cancel(self):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait()

    def check(self):
        """Raises with mprog's message when it failed."""
        if self.proc.returncode != 0 or not os.path.isfile(self.output):
            with open(self.log, encoding="utf-8", errors="replace") as f:
                text = f.read()
            lines = [l.rstrip() for l in text.splitlines() if l.strip()]
            raise MprogError("\n".join(lines[-12:]) or f"mprog exited with {self.proc.returncode}")

    def run_to_end(self):
        self.start()
        self.proc.wait()
        self.poll()
        self.check()
