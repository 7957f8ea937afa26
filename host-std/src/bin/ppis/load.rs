//! Loading the scene the arguments name, and telling the user what an import left out.

use crate::args::SceneArgs;
use anyhow::{Result, bail};
use host_std::light::environment::{EnvSource, Placement};
use host_std::scene::{Scene, builtin, json};
use std::path::PathBuf;

/// A loaded scene with what the importer left out or reduced (USD), for the user.
pub(crate) struct Loaded {
    pub(crate) scene: Scene,
    pub(crate) notes: Vec<String>,
    /// The files the scene file refers to (meshes, textures, maps, USD layers and packages;
    /// the scene's own map even when `--env` replaces it), not the scene file and `--env`.
    pub(crate) files: Vec<PathBuf>,
    #[cfg(feature = "usd")]
    pub(crate) usd: Option<host_usd::UsdScene>,
}

/// Loads the scene the arguments name (or the default scene) and applies `--env`. `size` is
/// the command line's width and height, which a USD stage's render settings are conformed to.
/// `exits_after`: the command exits once it has shown the scene, so a USD stage is not
/// freed (that is a tenth to a fifth of a large import).
#[cfg_attr(not(feature = "usd"), allow(unused_variables))]
pub(crate) fn load_scene(args: &SceneArgs, size: (Option<u32>, Option<u32>), exits_after: bool) -> Result<Loaded> {
    #[cfg(feature = "usd")]
    let mut usd = None;
    #[cfg_attr(not(feature = "usd"), allow(unused_mut))]
    let mut notes = Vec::new();
    let mut files = Vec::new();
    let mut scene = match &args.scene {
        None => builtin::scene(),
        Some(path) => {
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
            match ext.as_str() {
                "json" => {
                    let scene = json::load(path)?;
                    files = json::files_read(path)?;
                    scene
                }
                #[cfg(feature = "usd")]
                "usd" | "usda" | "usdc" | "usdz" => {
                    let options = host_std::scene::usd::Options {
                        camera: args.camera.clone(),
                        render_settings: args.render_settings.clone(),
                        width: size.0,
                        height: size.1,
                        leak_stage: exits_after,
                        time: match &args.frame {
                            Some(f) => f.parse().map_err(anyhow::Error::msg)?,
                            None => host_std::scene::usd::TimeCode::Earliest,
                        },
                    };
                    let c = host_std::scene::usd::load(path, &options)?;
                    notes = c.notes;
                    files = c.files;
                    usd = Some(c.usd);
                    c.scene
                }
                #[cfg(not(feature = "usd"))]
                "usd" | "usda" | "usdc" | "usdz" => {
                    bail!("{}: this ppis was built without USD support (cargo feature `usd`)", path.display())
                }
                _ => bail!("{}: unknown scene format (expected .json, .usda, .usdc, .usdz or .usd)", path.display()),
            }
        }
    };
    let is_usd =
        args.scene.as_ref().and_then(|p| p.extension()).is_some_and(|e| {
            matches!(e.to_string_lossy().to_ascii_lowercase().as_str(), "usd" | "usda" | "usdc" | "usdz")
        });
    if args.camera.is_some() && !is_usd {
        bail!("--camera applies to USD scenes only");
    }
    if args.render_settings.is_some() && !is_usd {
        bail!("--render-settings applies to USD scenes only");
    }
    if let Some(env) = &args.env {
        if !env.exists() {
            bail!("{}: environment map not found", env.display());
        }
        scene.env = Some((EnvSource::File(env.clone()), Placement::default()));
    }
    if let Some((_, placement)) = scene.env.as_mut() {
        if let Some(s) = args.env_scale {
            if !(s >= 0.0 && s.is_finite()) {
                bail!("--env-scale must be a finite number ≥ 0, got {s}");
            }
            placement.scale = s;
        }
        if let Some(r) = args.env_rotate_y {
            if !r.is_finite() {
                bail!("--env-rotate-y must be finite, got {r}");
            }
            placement.rotate_y_deg = r;
        }
    }
    Ok(Loaded {
        scene,
        notes,
        files,
        #[cfg(feature = "usd")]
        usd,
    })
}

/// One warning summary of what an import left out (all of it is in `ppis info`).
pub(crate) fn warn_notes(scene: &Scene, notes: &[String]) {
    const SHOWN: usize = 12;
    if notes.is_empty() {
        return;
    }
    // Group alike notes: the same message about different prims or files.
    let mut groups: Vec<(String, usize, &str)> = Vec::new();
    for n in notes {
        let (path, what) = n.split_once(": ").unwrap_or(("", n));
        let key: String = what
            .split(' ')
            .map(|w| if w.contains('/') || w.contains('.') && w.len() > 4 { "…" } else { w })
            .collect::<Vec<_>>()
            .join(" ");
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1 += 1,
            None => groups.push((key, 1, path)),
        }
    }
    eprintln!(
        "ppis: warning: {}: {} things were not rendered as authored (`ppis info` lists them all):",
        scene.name,
        notes.len()
    );
    for (key, count, first) in groups.iter().take(SHOWN) {
        eprintln!("  {count}× {key} (e.g. {first})");
    }
    if groups.len() > SHOWN {
        eprintln!("  … and {} more kinds", groups.len() - SHOWN);
    }
}
