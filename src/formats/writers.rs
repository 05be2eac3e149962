//! The writers of the output table ([`super::outputs::OUTPUT_KINDS`]): each turns an
//! [`OutputJob`] into the bytes of one file, or says why it cannot.

use super::outputs::OutputJob;
use crate::motion::Motion;

/// `.bvh`: one person (the table splits people into files).
pub fn bvh(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    let [person] = job.people else {
        return Err(format!(
            "{origin}: a BVH file holds one skeleton but there are {} people; write one .bvh per person or use .json/.npy",
            job.people.len()
        ));
    };
    if let Some(rig) = job.rig {
        return rig_bvh(origin, person, rig, job.bvh).map(String::into_bytes);
    }
    // bvh_string refuses non-finite positions itself (naming frame and joint).
    super::bvh_export::bvh_string(person, job.bvh)
        .map(String::into_bytes)
        .map_err(|e| format!("{origin}: {e}"))
}

/// The BVH of `m` on the user's rig: at the export frame rate if one is set (positions
/// resampled first, as [`super::bvh_export`] does), in the rig's own units and axes.
fn rig_bvh(
    origin: &str,
    m: &Motion,
    rig: &super::Character,
    opts: &super::bvh_export::BvhExportOptions,
) -> Result<String, String> {
    use super::bvh_export::{BvhAxes, BvhUnits};
    let fail = |kind| super::RigError::whole(origin, kind).to_string();
    if opts.units != BvhUnits::default() || opts.axes != BvhAxes::default() {
        return Err(fail(super::character::RigErrorKind::ExportOptions));
    }
    let resampled = export_rate(origin, m, opts)?;
    let posed = rig
        .retarget(resampled.as_ref().unwrap_or(m))
        .map_err(|e| fail(super::character::RigErrorKind::Motion(e)))?;
    Ok(super::character::write::bvh_text(rig, &posed))
}

/// `m` resampled to the BVH export rate, when one is set and differs from the motion's.
pub fn export_rate(
    origin: &str,
    m: &Motion,
    opts: &super::bvh_export::BvhExportOptions,
) -> Result<Option<Motion>, String> {
    use super::bvh_export::{BvhExportError, MAX_EXPORT_FPS, resample_cubic};
    match opts.fps {
        Some(fps) if !(fps.is_finite() && fps > 0.0 && fps <= MAX_EXPORT_FPS) => {
            Err(format!("{origin}: {}", BvhExportError::BadFps(fps)))
        }
        Some(fps) if fps != m.fps => Ok(Some(resample_cubic(m, fps))),
        _ => Ok(None),
    }
}

/// `.npy`: float32 joint positions.
pub fn npy(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    check_finite(origin, job.people)?;
    super::npy::joints_npy_bytes(origin, job.people).map_err(|e| e.to_string())
}

/// `.json`: an mprog-motion document with the job's meta.
pub fn json(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    check_finite(origin, job.people)?;
    let people = super::file::default_names(job.people.to_vec());
    super::json::json_bytes(origin, &people, job.meta).map_err(|e| e.to_string())
}

/// `.gif`: the animation, with the overlays and the prompt timeline in the meta.
pub fn gif(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    crate::render::gif_bytes(job.people, &picture_options(origin, job)?)
        .map_err(|e| format!("cannot render {origin}: {e}"))
}

/// `.png`: a strip of frames, with the overlays and the prompt timeline in the meta.
pub fn png(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    crate::render::strip_bytes(job.people, &picture_options(origin, job)?)
        .map_err(|e| format!("cannot render {origin}: {e}"))
}

/// `.html`: the viewer page, with the program's geometry and timelines in the meta.
pub fn html(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    crate::view::html_string(job.people, job.meta, job.title)
        .map(String::into_bytes)
        .map_err(|e| format!("{origin}: {e}"))
}

fn picture_options(origin: &str, job: &OutputJob) -> Result<crate::render::RenderOptions, String> {
    let mut opts = crate::render::RenderOptions::titled(job.title);
    opts.overlays =
        crate::view::overlays_from_meta(job.meta).map_err(|e| format!("{origin}: {e}"))?;
    let frames = job.people.iter().map(|m| m.len()).max().unwrap_or(0);
    opts.timeline = crate::view::timeline_from_meta(job.meta, job.people.len(), frames)
        .map_err(|e| format!("{origin}: {e}"))?;
    Ok(opts)
}

/// Refuses non-finite joints: JSON would turn them into `null`, `.npy` would carry them.
pub fn check_finite(origin: &str, people: &[Motion]) -> Result<(), String> {
    for (p, m) in people.iter().enumerate() {
        if let Some(f) = m
            .frames
            .iter()
            .position(|pose| !pose.iter().all(|v| v.is_finite()))
        {
            return Err(format!(
                "{origin}: person {} frame {f} has non-finite joint positions",
                p + 1
            ));
        }
    }
    Ok(())
}
