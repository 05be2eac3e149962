//! Export flags shared by every subcommand that writes motion files (`convert`, and `gen` /
//! `run` through `#[command(flatten)]`): `--bvh-fps`, `--bvh-axes`, `--bvh-units`.

use miette::{Result, miette};
use mprog::formats::bvh_export::{BvhAxes, BvhExportOptions, BvhUnits, MAX_EXPORT_FPS};
use std::path::PathBuf;

/// How BVH outputs are written.
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

    /// Refuses BVH flags when no output is a `.bvh` file (they would silently do nothing).
    pub fn check_against(&self, outputs: &[PathBuf]) -> Result<()> {
        let any_bvh = outputs
            .iter()
            .any(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")));
        if *self != ExportArgs::default() && !any_bvh {
            return Err(miette!(
                help = "add a .bvh output, or drop the --bvh-* flags",
                "--bvh-fps / --bvh-axes / --bvh-units only affect .bvh outputs, and there is none"
            ));
        }
        Ok(())
    }
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
