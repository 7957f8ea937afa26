//! `ppis info` for USD scenes: what an import brought in, and the conformance check against
//! Pixar's answers (`ppis info --expected DIR`).

use anyhow::{Result, bail};
use std::path::Path;

/// What an import brought in, for `ppis info`.
pub fn print_import(u: &host_usd::UsdScene) {
    let c = &u.counts;
    println!(
        "USD {}: upAxis {:?}, metersPerUnit {}, time code {}, imported in {:.3} s",
        u.file.display(),
        u.up_axis,
        u.meters_per_unit,
        match u.time_code_range {
            Some((start, end)) => format!("{} (the stage's range {start} to {end})", u.time_code),
            None => u.time_code.to_string(),
        },
        u.import_seconds
    );
    println!(
        "  {} prims; {} gprims ({} meshes, {} exact spheres), {} triangles, {} instances, {} hidden",
        c.prims,
        c.gprims,
        c.meshes,
        u.spheres.len(),
        c.triangles,
        c.instances,
        c.hidden
    );
    println!("  materials: {}", u.materials.len());
    for m in &u.materials {
        let l = m.lobes();
        println!(
            "    {}: diffuse {:?}, specular F0 {:?}, α {:.4}, clearcoat {} (α {:.4}){}",
            m.name,
            l.diffuse.to_array(),
            l.specular.to_array(),
            l.alpha,
            l.clearcoat,
            l.clearcoat_alpha,
            if m.textures.is_empty() { String::new() } else { format!(", {} textures", m.textures.len()) }
        );
    }
    match &u.dome {
        Some(d) => println!(
            "  lights: DomeLight {} ({}, radiance scale {:?})",
            d.path,
            d.texture.as_ref().map_or("constant".to_string(), |t| format!("texture {}", t.0)),
            d.radiance.to_array()
        ),
        None => println!("  lights: no DomeLight (a render builds no env hierarchy)"),
    }
    for l in &u.lights {
        println!("    {}", crate::scene::usd_lights::describe(l));
    }
    match &u.camera {
        Some(c) => println!(
            "  camera: {} (focal length {}, aperture {} × {})",
            c.path, c.focal_length, c.horizontal_aperture, c.vertical_aperture
        ),
        None => println!("  camera: none"),
    }
    match &u.render_settings {
        Some(s) => println!(
            "  render settings: {} ({} × {}, pixel aspect {}, {:?}{})",
            s.path,
            s.resolution.0,
            s.resolution.1,
            s.pixel_aspect,
            s.conform,
            s.camera.as_ref().map_or(String::new(), |c| format!(", camera {c}"))
        ),
        None => {
            println!(
                "  render settings: none ({} wide, the camera's aperture aspect)",
                crate::scene::usd::DEFAULT_WIDTH
            )
        }
    }
}

/// `ppis info --expected DIR`: host-usd against Pixar's answers for every file that has them.
pub fn conformance(dir: &Path) -> Result<()> {
    if !dir.is_dir() {
        bail!("{}: not a folder", dir.display());
    }
    let pairs = host_usd::conformance::pairs(dir);
    if pairs.is_empty() {
        bail!("{}: no USD file with a <name>.expected.json beside it", dir.display());
    }
    let (mut ok, mut max_err) = (0, 0.0f64);
    let (mut prims, mut mats, mut binds) = (0, 0, 0);
    for (usd, expected) in &pairs {
        let name = usd.strip_prefix(dir).unwrap_or(usd).display().to_string();
        let check = host_usd::conformance::check(usd, expected);
        let import = host_usd::load(usd);
        match (check, import) {
            (Ok(r), Ok(s)) if r.mismatches.is_empty() => {
                ok += 1;
                max_err = max_err.max(r.max_matrix_error);
                (prims, mats, binds) = (prims + r.prims, mats + r.matrices, binds + r.materials);
                println!(
                    "ok    {name}: {} prims, {} world matrices (max error {:.1e}), {} bindings, {} meshes; import {} triangles, {} skips, {:.3} s",
                    r.prims,
                    r.matrices,
                    r.max_matrix_error,
                    r.materials,
                    r.meshes,
                    s.counts.triangles,
                    s.skipped.len(),
                    s.import_seconds
                );
            }
            (check, import) => {
                println!("FAIL  {name}");
                match check {
                    Ok(r) => r.mismatches.iter().for_each(|m| println!("      {m}")),
                    Err(e) => println!("      check: {e}"),
                }
                if let Err(e) = import {
                    println!("      import: {e}");
                }
            }
        }
    }
    println!(
        "{ok} of {} files match Pixar's answers ({prims} prims, {mats} world matrices within {:.0e} (max {:.1e}), {binds} material bindings) and import without error",
        pairs.len(),
        host_usd::conformance::MATRIX_TOLERANCE,
        max_err
    );
    if ok != pairs.len() {
        bail!("{} of {} files differ from Pixar's answers", pairs.len() - ok, pairs.len());
    }
    Ok(())
}
