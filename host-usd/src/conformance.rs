//! Conformance against Pixar's answers: a `*.expected.json` beside a USD file holds what
//! Pixar's own library computes (stage metadata; per prim its type, world matrix, bound
//! material, point and face counts; PointInstancer instance transforms; how many gprims,
//! meshes and instances a renderer draws), all at the default time code, and optionally world
//! matrices at other time codes (`frames`). [`check`] recomputes each with host-usd and
//! reports every difference; world matrices must agree to 1e-9.

use crate::import;
use crate::instancer;
use crate::mesh;
use crate::stage::{PrimPath, Stage, TimeCode, Value};
use crate::xform::WorldTransforms;
use glam::DMat4;
use serde_json::Value as Json;
use std::path::{Path, PathBuf};

/// Largest allowed difference of a world-matrix entry (relative to max(1, |entry|)).
pub const MATRIX_TOLERANCE: f64 = 1e-9;

/// The outcome of one file's check.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Prims whose type was compared.
    pub prims: usize,
    /// World matrices compared.
    pub matrices: usize,
    /// Material bindings compared.
    pub materials: usize,
    /// Meshes whose point and face counts were compared.
    pub meshes: usize,
    /// PointInstancer instance transforms compared.
    pub instances: usize,
    /// The largest world-matrix difference found (relative, see [`MATRIX_TOLERANCE`]).
    pub max_matrix_error: f64,
    /// Every difference from Pixar's answers, one line each.
    pub mismatches: Vec<String>,
}

/// Checks `usd` against Pixar's answers in `expected`.
pub fn check(usd: &Path, expected: &Path) -> Result<Report, String> {
    crate::guard::guarded(usd, || {
        check_unguarded(usd, expected).map_err(|e| crate::UsdError::Open { file: usd.to_owned(), message: e })
    })
    .map_err(|e| e.to_string())
}

fn check_unguarded(usd: &Path, expected: &Path) -> Result<Report, String> {
    let text = std::fs::read_to_string(expected).map_err(|e| format!("{}: {e}", expected.display()))?;
    let want: Json = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", expected.display()))?;
    let stage = import::open(usd, TimeCode::Default).map_err(|e| e.to_string())?;
    let mut r = Report::default();
    let mut mismatches = Vec::new();
    let mut mismatch = |m: String| mismatches.push(m);

    check_stage(&stage, &want["stage"], &mut mismatch)?;

    // A set: the traversals hold 100 000 prims and more.
    let ours: std::collections::HashSet<String> = stage.all_prims()?.iter().map(PrimPath::to_string).collect();
    let Some(prims) = want["prims"].as_object() else {
        return Err(format!("{}: no \"prims\" object", expected.display()));
    };
    for p in prims.keys().filter(|p| !ours.contains(*p)) {
        mismatch(format!("{p}: in Pixar's traversal, not in ours"));
    }
    let mut extra: Vec<&String> = ours.iter().filter(|p| !prims.contains_key(*p)).collect();
    extra.sort();
    for p in extra {
        mismatch(format!("{p}: in our traversal, not in Pixar's"));
    }
    let mut worlds = WorldTransforms::default();
    let mut max_err = 0.0f64;
    let (mut n_mat, mut n_bind, mut n_mesh) = (0, 0, 0);
    for (path, want) in prims.iter().filter(|(p, _)| ours.contains(*p)) {
        let t = stage.type_name(path)?;
        if want["type"].as_str() != Some(t.as_str()) {
            mismatch(format!("{path}: type Pixar {} host-usd {t:?}", want["type"]));
        }
        for (key, ours) in [("instance", stage.is_instance(path)?), ("instanceProxy", stage.is_instance_proxy(path)?)] {
            if want[key].as_bool().is_some_and(|w| w != ours) {
                mismatch(format!("{path}: {key} Pixar {} host-usd {ours}", want[key]));
            }
        }
        if want.get("world").is_some() {
            n_mat += 1;
            let prim_err = matrix_error(&worlds.world(&stage, &PrimPath::new(path)?)?, &want["world"]);
            if prim_err > MATRIX_TOLERANCE {
                mismatch(format!("{path}: world matrix differs from Pixar's by {prim_err:.3e}"));
            }
            max_err = max_err.max(prim_err);
        }
        if let Some(wanted) = want.get("material") {
            n_bind += 1;
            let ours = stage.bound_material(path)?;
            if wanted.as_str().map(str::to_string) != ours {
                mismatch(format!("{path}: material Pixar {wanted} host-usd {ours:?}"));
            }
        }
        if want.get("points").is_some() {
            n_mesh += 1;
            check_mesh(&stage, path, want, &mut mismatch)?;
        }
    }
    if let Some(instancers) = want["instancers"].as_object() {
        for (path, w) in instancers {
            let (n, err) = check_instancer(&stage, path, w, &mut mismatch)?;
            r.instances += n;
            max_err = max_err.max(err);
        }
    }
    if let Some(counts) = want.get("counts") {
        check_counts(usd, counts, &mut mismatch)?;
    }
    if let Some(frames) = want["frames"].as_object() {
        let (n, err) = check_frames(usd, frames, &mut mismatch)?;
        n_mat += n;
        max_err = max_err.max(err);
    }
    r.mismatches = mismatches;
    r.prims = prims.len();
    r.matrices = n_mat;
    r.materials = n_bind;
    r.meshes = n_mesh;
    r.max_matrix_error = max_err;
    Ok(r)
}

/// Stage metadata: upAxis, metersPerUnit, defaultPrim.
fn check_stage(stage: &Stage, meta: &Json, mismatch: &mut impl FnMut(String)) -> Result<(), String> {
    let up = stage.metadata("upAxis")?.and_then(|v| v.token().map(str::to_string)).unwrap_or_else(|| "Y".into());
    if meta["upAxis"].as_str() != Some(up.as_str()) {
        mismatch(format!("upAxis: Pixar {} host-usd {up}", meta["upAxis"]));
    }
    let mpu = stage.metadata("metersPerUnit")?.and_then(|v| v.scalar()).unwrap_or(0.01);
    if meta["metersPerUnit"].as_f64().is_none_or(|m| (m - mpu).abs() > 1e-12 * m.abs()) {
        mismatch(format!("metersPerUnit: Pixar {} host-usd {mpu}", meta["metersPerUnit"]));
    }
    let default_prim = stage.default_prim().map(|d| if d.starts_with('/') { d } else { format!("/{d}") });
    if meta["defaultPrim"].as_str().map(str::to_string) != default_prim {
        mismatch(format!("defaultPrim: Pixar {} host-usd {default_prim:?}", meta["defaultPrim"]));
    }

    Ok(())
}

/// A mesh's point and face counts, and that host-usd reads its topology.
fn check_mesh(stage: &Stage, path: &str, want: &Json, mismatch: &mut impl FnMut(String)) -> Result<(), String> {
    let points = match stage.value(path, "points")? {
        Some(Value::Numbers { values, .. }) => values.len() / 3,
        _ => 0,
    };
    if want["points"].as_u64() != Some(points as u64) {
        mismatch(format!("{path}: points Pixar {} host-usd {points}", want["points"]));
    }
    let counts: Vec<i64> = match stage.value(path, "faceVertexCounts")? {
        Some(Value::Numbers { values, .. }) => values.iter().map(|&x| x as i64).collect(),
        _ => Vec::new(),
    };
    // Pixar's answer lists the counts, or for large meshes their number and sum.
    let fvc = &want["faceVertexCounts"];
    let same = match fvc.as_array() {
        Some(a) => a.iter().filter_map(Json::as_i64).eq(counts.iter().copied()),
        None => {
            fvc["faces"].as_u64() == Some(counts.len() as u64)
                && fvc["sum"].as_i64() == Some(counts.iter().sum::<i64>())
        }
    };
    if !same {
        mismatch(format!("{path}: faceVertexCounts differ from Pixar's {fvc}"));
    }
    if let Err(e) = mesh::read(stage, &PrimPath::new(path)?, Some("st")) {
        mismatch(format!("{path}: {e}"));
    }
    Ok(())
}

/// The largest difference of a matrix entry from Pixar's rows (relative to max(1, |entry|));
/// infinite when Pixar's answer is not a 4 × 4 matrix of numbers.
fn matrix_error(ours: &DMat4, rows: &Json) -> f64 {
    // glam's columns are USD's rows.
    let m = ours.to_cols_array();
    let mut err = 0.0f64;
    for i in 0..4 {
        for j in 0..4 {
            let w = rows[i][j].as_f64().unwrap_or(f64::NAN);
            let e = (m[4 * i + j] - w).abs() / w.abs().max(1.0);
            err = err.max(if e.is_nan() { f64::INFINITY } else { e });
        }
    }
    err
}

/// One PointInstancer: which instances are visible, their prototypes, and the transforms Pixar
/// saved (those of the first visible instances, in order; Pixar's include the prototype root's
/// own transform). Returns the transforms compared and their largest error.
fn check_instancer(
    stage: &Stage,
    path: &str,
    w: &Json,
    mismatch: &mut impl FnMut(String),
) -> Result<(usize, f64), String> {
    let (protos, instances) = instancer::read(stage, &PrimPath::new(path)?)?;
    let mask: Vec<bool> = w["mask"].as_array().into_iter().flatten().filter_map(Json::as_bool).collect();
    let visible: Vec<usize> = instances.iter().map(|i| i.index).collect();
    // An empty mask: every instance is visible.
    let n = w["protoIndices"].as_array().map_or(0, Vec::len);
    let want_visible: Vec<usize> = (0..n).filter(|&i| mask.get(i).copied().unwrap_or(mask.is_empty())).collect();
    if visible != want_visible {
        mismatch(format!(
            "{path}: visible instances differ from Pixar's ({} vs {})",
            visible.len(),
            want_visible.len()
        ));
        return Ok((0, 0.0));
    }
    let transforms = w["transforms"].as_array().map_or(&[][..], Vec::as_slice);
    let total = w["instanceCount"].as_u64().map_or(transforms.len(), |c| c as usize);
    if total != instances.len() || transforms.len() > instances.len() {
        mismatch(format!("{path}: {} instances, Pixar {total}", instances.len()));
        return Ok((0, 0.0));
    }
    let mut worlds = WorldTransforms::default();
    let mut max_err = 0.0f64;
    for (inst, rows) in instances.iter().zip(transforms) {
        if w["protoIndices"][inst.index].as_u64() != Some(inst.prototype as u64) {
            mismatch(format!("{path}: instance {} prototype differs from Pixar's", inst.index));
        }
        let root = &protos[inst.prototype];
        let ours = inst.transform * worlds.relative_to(stage, root, root)?;
        let err = matrix_error(&ours, rows);
        if err > MATRIX_TOLERANCE {
            mismatch(format!("{path}: instance {} transform differs from Pixar's by {err:.3e}", inst.index));
        }
        max_err = max_err.max(err);
    }
    Ok((transforms.len(), max_err))
}

/// World matrices at other time codes: `frames` maps a time code (`earliest` or a number) to
/// the world matrices of prims at it. Returns the matrices compared and their largest error.
fn check_frames(
    usd: &Path,
    frames: &serde_json::Map<String, Json>,
    mismatch: &mut impl FnMut(String),
) -> Result<(usize, f64), String> {
    let (mut n, mut max_err) = (0, 0.0f64);
    for (time, prims) in frames {
        let time: TimeCode = time.parse()?;
        let stage = import::open(usd, time).map_err(|e| e.to_string())?;
        let mut worlds = WorldTransforms::default();
        for (path, rows) in prims.as_object().into_iter().flatten() {
            let err = matrix_error(&worlds.world(&stage, &PrimPath::new(path)?)?, rows);
            if err > MATRIX_TOLERANCE {
                mismatch(format!("{path} at time code {time}: world matrix differs from Pixar's by {err:.3e}"));
            }
            max_err = max_err.max(err);
            n += 1;
        }
    }
    Ok((n, max_err))
}

/// How many gprims, meshes and instances the import draws, against Pixar's count of those a
/// viewer draws.
fn check_counts(usd: &Path, want: &Json, mismatch: &mut impl FnMut(String)) -> Result<(), String> {
    let options = import::Options { time: TimeCode::Default, ..Default::default() };
    let scene = import::load_with(usd, &options).map_err(|e| e.to_string())?;
    let c = &scene.counts;
    for (key, ours) in [("gprims", c.gprims), ("meshes", c.meshes), ("instances", c.instances)] {
        if want[key].as_u64() != Some(ours as u64) {
            mismatch(format!("{key}: Pixar {} host-usd {ours}", want[key]));
        }
    }
    Ok(())
}

/// Every USD file under `dir` (recursively) with a `<stem>.expected.json` beside it.
pub fn pairs(dir: &Path) -> Vec<(PathBuf, PathBuf)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_owned()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        let mut entries: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
            if !matches!(ext.as_str(), "usd" | "usda" | "usdc" | "usdz") {
                continue;
            }
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            let expected = p.with_file_name(format!("{stem}.expected.json"));
            if expected.is_file() {
                out.push((p, expected));
            }
        }
    }
    out.sort();
    out
}
