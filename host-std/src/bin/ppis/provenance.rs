//! The render's settings as `ppis render` writes them into its EXR's header
//! (`host_std::output::SETTINGS_ATTRIBUTE`), one `key=value` per line: what `ppis merge`
//! compares to refuse tiles of different renders. A whole frame's file holds the same text as
//! each of its tiles', so a merged frame is byte for byte the one-process render. Files are
//! named by their name and the FNV-1a hash of their bytes (not their folder: farm machines
//! mount the same files at different paths), the scene file's and `--env`'s and every file the
//! scene refers to (meshes, textures, maps, a USD stage's layers and packages), so that a
//! change to any input of the pixels makes tiles of different renders.

use crate::render_cmd::RenderArgs;
use anyhow::{Context, Result};
use clap::ValueEnum;
use host_std::light::lights::LightSelection;
use host_std::plan::Settings;
use host_std::plan::carrier::Carrier;
use sampler_core::env::MisHeuristic;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The settings text for a render of a `width`×`height` frame of a scene that reads `files`
/// besides its own file, its distant lights with an angle carried by `carrier` (the one `auto`
/// chose: the same pixels whether chosen or given; `None` where nothing is carried) and MIS
/// weighing by `heuristic` (given or chosen by the split pilot).
pub(crate) fn settings_text(
    args: &RenderArgs,
    settings: &Settings,
    frame: (usize, usize),
    files: &[PathBuf],
    (carrier, heuristic): (Option<Carrier>, MisHeuristic),
) -> Result<String> {
    let scene = &args.scene;
    let mut lines: Vec<(&str, String)> = vec![("ppis", env!("CARGO_PKG_VERSION").to_string())];
    match &scene.scene {
        Some(path) => {
            lines.push(("scene", file_name(path)));
            lines.push(("scene_fnv1a64", file_hash(path)?));
        }
        None => lines.push(("scene", "builtin".into())),
    }
    if let Some(frame) = &scene.frame {
        lines.push(("frame", frame.clone()));
    }
    lines.push(("camera", scene.camera.clone().unwrap_or_default()));
    lines.push(("render_settings", scene.render_settings.clone().unwrap_or_default()));
    if let Some(path) = &scene.env {
        lines.push(("env", file_name(path)));
        lines.push(("env_fnv1a64", file_hash(path)?));
    }
    lines.push(("env_scale", scene.env_scale.map(|s| s.to_bits().to_string()).unwrap_or_default()));
    lines.push(("env_rotate_y", scene.env_rotate_y.map(|r| r.to_bits().to_string()).unwrap_or_default()));
    lines.push(("width", frame.0.to_string()));
    lines.push(("height", frame.1.to_string()));
    lines.push(("method", settings.method.to_string()));
    lines.push(("spp", settings.spp.to_string()));
    lines.push(("shading_points", settings.shading_points.to_string()));
    lines.push(("brdf_samples", settings.brdf_samples.to_string()));
    lines.push(("seed", settings.seed.to_string()));
    lines.push(("shadows", settings.shadows.to_string()));
    let lights = &settings.lights;
    let selection = match lights.selection {
        LightSelection::Tree => "tree",
        LightSelection::Power => "power",
    };
    lines.push(("light_selection", selection.into()));
    // Floats as Rust writes them: the shortest text that reads back to the same bits.
    lines.push(("light_share", lights.share.to_string()));
    lines.push(("sis_lights", lights.sis_lights.to_string()));
    lines.push(("lightcut_error", lights.lightcut_error.to_string()));
    let carrier = carrier.and_then(|c| c.to_possible_value()).map(|v| v.get_name().to_string());
    lines.push(("distant_carrier", carrier.unwrap_or_default()));
    lines.push(("mis_heuristic", crate::render_cmd::heuristic_name(heuristic).into()));
    // By name and content, not by folder or order: the same inputs on any machine.
    let own = scene.scene.as_ref().and_then(|p| p.canonicalize().ok());
    let mut reads = Vec::new();
    for f in files.iter().filter(|f| f.canonicalize().ok() != own) {
        reads.push(format!("{} {}", file_name(f), file_hash(f)?));
    }
    reads.sort();
    lines.extend(reads.into_iter().map(|r| ("reads", r)));
    let mut text = String::new();
    for (key, value) in lines {
        // Latin-1 only in an EXR text attribute: anything else escaped.
        let _ = writeln!(text, "{key}={}", value.escape_default());
    }
    Ok(text)
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// FNV-1a (64 bits) of the file's bytes, in hex: to tell files apart, not against tampering.
fn file_hash(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    Ok(format!("{hash:016x}"))
}
