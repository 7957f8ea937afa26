//! The materials of a gprim: the UsdPreviewSurface bound to it (imported on first use), its
//! displayColor when nothing is bound, or a fallback; and per-face materials from its
//! `materialBind` GeomSubsets.

use super::Importer;
use crate::material::Material;
use crate::stage::{PrimPath, Value};
use glam::Vec3;
use std::collections::HashMap;

/// A mesh's per-face materials from its `materialBind` GeomSubsets that bind a material: where
/// subsets overlap, the first in namespace order binds the face. One map for all subsets, so
/// a mesh's faces find theirs in time linear in faces and subsets together.
#[derive(Default)]
pub(super) struct FaceMaterials {
    by_face: HashMap<i64, usize>,
    /// Each subset's material, in namespace order.
    materials: Vec<usize>,
}

impl FaceMaterials {
    /// The material bound to `face`, if a subset binds one.
    pub(super) fn get(&self, face: u32) -> Option<usize> {
        if self.by_face.is_empty() { None } else { self.by_face.get(&i64::from(face)).copied() }
    }

    /// Each subset's material, in namespace order.
    pub(super) fn materials(&self) -> &[usize] {
        &self.materials
    }
}

impl Importer<'_> {
    /// The per-face materials of the mesh's `materialBind` GeomSubsets.
    pub(super) fn subset_materials(&mut self, prim: &PrimPath) -> Result<FaceMaterials, String> {
        let mut out = FaceMaterials::default();
        for child in self.stage.children(prim)? {
            if self.stage.type_name(&child)? != "GeomSubset" {
                continue;
            }
            let family = self.stage.value(&child, "familyName")?;
            if family.as_ref().and_then(Value::token) != Some("materialBind") {
                continue;
            }
            if self.stage.bound_material(&child)?.is_none() {
                continue;
            }
            let mat = self.material_for(&child)?;
            if let Some(Value::Numbers { values, .. }) = self.stage.value(&child, "indices")? {
                values.iter().for_each(|&x| {
                    out.by_face.entry(x as i64).or_insert(mat);
                });
            }
            out.materials.push(mat);
        }
        Ok(out)
    }

    /// The index of the material bound to `prim` (imported on first use), or of a fallback.
    pub(super) fn material_for(&mut self, prim: &PrimPath) -> Result<usize, String> {
        let bound = self.stage.bound_material(prim)?;
        // Unbound gprims show their displayColor (its mean over the elements), as viewers do.
        let display = match &bound {
            Some(_) => None,
            None => crate::primvar::Primvar::read(self.stage, prim, "displayColor", None)?
                .filter(|p| p.width == 3 && !p.is_empty())
                .map(|p| {
                    let n = p.len();
                    let sum = (0..n)
                        .filter_map(|i| p.element(i))
                        .fold([0.0; 3], |a, e| [a[0] + e[0], a[1] + e[1], a[2] + e[2]]);
                    Vec3::new((sum[0] / n as f64) as f32, (sum[1] / n as f64) as f32, (sum[2] / n as f64) as f32)
                }),
        };
        let key = match (&bound, display) {
            (Some(m), _) => m.clone(),
            (None, Some(c)) => format!("<displayColor {} {} {}>", c.x, c.y, c.z),
            (None, None) => "<fallback>".to_string(),
        };
        if let Some(&i) = self.materials.get(&key) {
            return Ok(i);
        }
        let material = match &bound {
            None => {
                let mut m = Material::fallback(&key);
                if let Some(c) = display {
                    m.diffuse_color = c;
                }
                m
            }
            Some(path) => match self.stage.surface_shader(path)? {
                Some((shader, id)) if id == "UsdPreviewSurface" => {
                    let (m, notes) = Material::read(self.stage, path, &shader)?;
                    notes.into_iter().for_each(|n| self.skip(path, n));
                    m
                }
                Some((shader, id)) => {
                    self.skip(path, format!("surface shader {shader} ({id}) is not a UsdPreviewSurface (MaterialX?); fallback material used"));
                    Material::fallback(path)
                }
                None => {
                    self.skip(path, "no surface shader; fallback material used");
                    Material::fallback(path)
                }
            },
        };
        self.scene.materials.push(material);
        let i = self.scene.materials.len() - 1;
        self.materials.insert(key, i);
        Ok(i)
    }
}
