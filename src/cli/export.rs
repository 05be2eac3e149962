//! Export flags shared by every subcommand that writes motion files (`convert`, and `gen` /
//! `run` through `#[command(flatten)]`): `--bvh-fps`, `--bvh-axes`, `--bvh-units`, and the
//! user's character, `--rig` / `--rig-map`.

use miette::{IntoDiagnostic, Result, miette};
use mprog::formats::Character;
use mprog::formats::bvh_export::{BvhAxes, BvhExportOptions, BvhUnits, MAX_EXPORT_FPS};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How BVH (and glTF) outputs are written.
#[derive(clap::Args, Clone, Debug, Default, PartialEq)]
pub struct ExportArgs {
    /// Frame rate of BVH outputs, e.g. 30 or 60 for animation tools (joint positions are
    /// resampled before rotations are solved; default: the motion's own, 20).
    #[arg(long, value_name = "FPS", value_parser = parse_fps)]
    pub bvh_fps: Option<f32>,
    /// Axes of BVH outputs: `y-up` (mprog's, Blender's importer defaults) or
    /// `blender-z-up` (import with forward Y, up Z).
    #[arg(long, value_enum, value_name = "AXES", default_value_t)]
    pub bvh_axes: AxesArg,
    /// Length unit of BVH outputs: `m` or `cm` (most mocap files).
    #[arg(long, value_enum, value_name = "UNIT", default_value_t)]
    pub bvh_units: UnitsArg,
    /// Put the motion on your character: a BVH of its skeleton (Mixamo, or any rig mprog
    /// reads) or the character as a skinned .glb. .bvh and .glb outputs take the rig's
    /// joints, names, offsets, channels, units and axes; joints mprog does not have
    /// (fingers, twist bones) keep their rest pose. On a .glb rig a .glb output is that
    /// file, its mesh and skin kept, animated.
    #[arg(long, value_name = "RIG.bvh|RIG.glb")]
    pub rig: Option<PathBuf>,
    /// Which rig joint is which HumanML3D joint, for names mprog does not recognise: a TOML
    /// file of lines such as `left_knee = "Knee_L"` (`mprog joints` lists the names).
    #[arg(long, value_name = "MAP.toml", requires = "rig")]
    pub rig_map: Option<PathBuf>,
    /// The rig, once read ([`ExportArgs::prepare`]).
    #[arg(skip)]
    pub character: Option<Arc<Character>>,
}

/// `--bvh-axes` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AxesArg {
    #[default]
    YUp,
    BlenderZUp,
}

/// `--bvh-units` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UnitsArg {
    #[default]
    M,
    Cm,
}

impl std::fmt::Display for AxesArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            AxesArg::YUp => "y-up",
            AxesArg::BlenderZUp => "blender-z-up",
        })
    }
}

impl std::fmt::Display for UnitsArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            UnitsArg::M => "m",
            UnitsArg::Cm => "cm",
        })
    }
}

impl ExportArgs {
    /// The library's BVH options.
    pub fn bvh_options(&self) -> BvhExportOptions {
        BvhExportOptions {
            units: match self.bvh_units {
                UnitsArg::M => BvhUnits::Metres,
                UnitsArg::Cm => BvhUnits::Centimetres,
            },
            axes: match self.bvh_axes {
                AxesArg::YUp => BvhAxes::YUp,
                AxesArg::BlenderZUp => BvhAxes::BlenderZUp,
            },
            fps: self.bvh_fps,
        }
    }

    /// Checks the flags against the outputs and reads the rig, printing how it was mapped:
    /// called before any work, so a bad rig or flag does not cost a generation.
    pub fn prepare(&mut self, outputs: &[PathBuf]) -> Result<()> {
        self.check_against(outputs)?;
        if self.character.is_none()
            && let Some(rig) = &self.rig
        {
            let ch = load_rig(rig, self.rig_map.as_deref())?;
            eprintln!("{}", ch.summary());
            for note in &ch.notes {
                eprintln!("  {note}");
            }
            self.character = Some(Arc::new(ch));
        }
        Ok(())
    }

    /// The rig, read by [`Self::prepare`] or now.
    pub fn character(&self) -> Result<Option<Arc<Character>>> {
        match (&self.character, &self.rig) {
            (Some(ch), _) => Ok(Some(ch.clone())),
            (None, Some(rig)) => Ok(Some(Arc::new(load_rig(rig, self.rig_map.as_deref())?))),
            (None, None) => Ok(None),
        }
    }

    /// Refuses BVH flags when no output is a `.bvh` file (they would silently do nothing),
    /// `--rig` when no output is a `.bvh` or `.glb`, and units or axes with a rig (it keeps
    /// its own).
    pub fn check_against(&self, outputs: &[PathBuf]) -> Result<()> {
        let has = |ext: &str| {
            outputs
                .iter()
                .any(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)))
        };
        let bvh_flags = self.bvh_fps.is_some()
            || self.bvh_axes != AxesArg::default()
            || self.bvh_units != UnitsArg::default();
        if bvh_flags && !has("bvh") {
            return Err(miette!(
                help = "add a .bvh output, or drop the --bvh-* flags",
                "--bvh-fps / --bvh-axes / --bvh-units only affect .bvh outputs, and there is none"
            ));
        }
        if self.rig.is_some() && !has("bvh") && !has("glb") {
            return Err(miette!(
                help = "add a .bvh or .glb output, or drop --rig",
                "--rig only affects .bvh and .glb outputs, and there is none"
            ));
        }
        if self.rig.is_some()
            && (self.bvh_axes != AxesArg::default() || self.bvh_units != UnitsArg::default())
        {
            return Err(miette!(
                help =
                    "drop --bvh-axes / --bvh-units: the output keeps the rig's own units and axes",
                "--bvh-axes and --bvh-units do not apply with --rig"
            ));
        }
        Ok(())
    }
}

fn load_rig(rig: &Path, map: Option<&Path>) -> Result<Character> {
    Character::load(rig, map).into_diagnostic()
}

fn parse_fps(s: &str) -> std::result::Result<f32, String> {
    let fps: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if fps.is_finite() && fps > 0.0 && fps <= MAX_EXPORT_FPS {
        Ok(fps)
    } else {
        Err(format!(
            "the frame rate must be above 0 and at most {MAX_EXPORT_FPS}"
        ))
    }
}
