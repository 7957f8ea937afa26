//! UsdPreviewSurface → the renderer's lobes. Metallic workflow: F0 = lerp(((ior − 1)/(ior +
//! 1))², diffuseColor, metallic) and diffuse weight 1 − metallic; specular workflow: F0 =
//! specularColor. GGX α = roughness²; the clear coat is a second GGX lobe (F0 = 0.04, α =
//! clearcoatRoughness²). Unauthored inputs take the schema's fallbacks.

use crate::stage::{Input, PreviewInputs, Stage, TextureRef};
use glam::Vec3;

/// A UsdPreviewSurface's inputs, fallbacks applied.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The Material prim, or `<fallback>` for gprims with no usable binding.
    pub name: String,
    /// `inputs:diffuseColor`.
    pub diffuse_color: Vec3,
    /// `inputs:specularColor` (used in the specular workflow).
    pub specular_color: Vec3,
    /// `inputs:metallic` (used in the metallic workflow).
    pub metallic: f32,
    /// `inputs:roughness`.
    pub roughness: f32,
    /// `inputs:clearcoat`: the coat lobe's weight.
    pub clearcoat: f32,
    /// `inputs:clearcoatRoughness`.
    pub clearcoat_roughness: f32,
    /// `inputs:ior`: the dielectric specular's index of refraction.
    pub ior: f32,
    /// `inputs:useSpecularWorkflow`: specularColor instead of metallic.
    pub specular_workflow: bool,
    /// Inputs driven by textures; the host decodes them and writes the inputs back.
    pub textures: Vec<Texture>,
}

/// Which input a texture drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureInput {
    /// `inputs:diffuseColor`.
    DiffuseColor,
    /// `inputs:specularColor`.
    SpecularColor,
    /// `inputs:metallic`.
    Metallic,
    /// `inputs:roughness`.
    Roughness,
}

/// A UsdUVTexture feeding an input, with its bytes (from a file or from inside a usdz) or
/// why they could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The input it drives.
    pub input: TextureInput,
    /// The UsdUVTexture as authored.
    pub source: TextureRef,
    /// The image file's bytes, or why they could not be read.
    pub bytes: Result<Vec<u8>, String>,
}

/// The lobes the renderer builds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobes {
    /// The diffuse lobe's albedo.
    pub diffuse: Vec3,
    /// The specular lobe's reflectance at normal incidence.
    pub specular: Vec3,
    /// The specular lobe's GGX α: roughness², to be used as is (not squared again).
    pub alpha: f32,
    /// The coat lobe's weight.
    pub clearcoat: f32,
    /// The coat's GGX α: clearcoatRoughness².
    pub clearcoat_alpha: f32,
}

impl Material {
    /// UsdPreviewSurface with every input at its fallback (diffuse 0.18, roughness 0.5).
    pub fn fallback(name: &str) -> Self {
        Self {
            name: name.to_string(),
            diffuse_color: Vec3::splat(0.18),
            specular_color: Vec3::ZERO,
            metallic: 0.0,
            roughness: 0.5,
            clearcoat: 0.0,
            clearcoat_roughness: 0.01,
            ior: 1.5,
            specular_workflow: false,
            textures: Vec::new(),
        }
    }

    /// The renderer's lobes.
    pub fn lobes(&self) -> Lobes {
        let clamp01 = |x: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 };
        let color = |c: Vec3| Vec3::new(clamp01(c.x), clamp01(c.y), clamp01(c.z));
        let (diffuse, specular) = if self.specular_workflow {
            (color(self.diffuse_color), color(self.specular_color))
        } else {
            let m = clamp01(self.metallic);
            let ior = if self.ior.is_finite() && self.ior > 0.0 { self.ior } else { 1.5 };
            let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
            (color(self.diffuse_color) * (1.0 - m), Vec3::splat(f0).lerp(color(self.diffuse_color), m))
        };
        let r = clamp01(self.roughness);
        let cr = clamp01(self.clearcoat_roughness);
        Lobes { diffuse, specular, alpha: r * r, clearcoat: clamp01(self.clearcoat), clearcoat_alpha: cr * cr }
    }

    /// Reads the UsdPreviewSurface `shader`; textured inputs keep their fallback value until
    /// the host writes the texture's mean back. Returns what could not be honoured.
    pub fn read(stage: &Stage, name: &str, shader: &str) -> Result<(Self, Vec<String>), String> {
        let inputs: PreviewInputs = stage.preview_inputs(shader)?;
        let mut m = Self::fallback(name);
        let mut notes: Vec<String> = inputs.unsupported.iter().map(|u| format!("{u} ignored")).collect();
        let v3 = |v: [f32; 3]| Vec3::from_array(v);
        let mut texture = |input: Option<TextureInput>, what: &str, i: &Input<()>| -> Option<Texture> {
            let Input::Texture(source) = i else { return None };
            let authored = &source.authored;
            let Some(input) = input else {
                notes.push(format!("texture on {what} ignored"));
                return None;
            };
            if authored.contains("<UDIM>") {
                notes.push(format!("UDIM texture {authored} on {what} not supported; fallback value used"));
                return None;
            }
            let bytes = match &source.resolved {
                Some(r) => stage.read_asset(r).map_err(|e| format!("{r}: {e}")),
                None => Err(format!("{authored}: texture not found")),
            };
            Some(Texture { input, source: source.clone(), bytes })
        };
        match inputs.diffuse_color {
            Input::Value(v) => m.diffuse_color = v3(v),
            ref t => m.textures.extend(texture(Some(TextureInput::DiffuseColor), "diffuseColor", &shape(t))),
        }
        match inputs.specular_color {
            Input::Value(v) => m.specular_color = v3(v),
            ref t => m.textures.extend(texture(Some(TextureInput::SpecularColor), "specularColor", &shape(t))),
        }
        match inputs.metallic {
            Input::Value(v) => m.metallic = v,
            ref t => m.textures.extend(texture(Some(TextureInput::Metallic), "metallic", &shape(t))),
        }
        match inputs.roughness {
            Input::Value(v) => m.roughness = v,
            ref t => m.textures.extend(texture(Some(TextureInput::Roughness), "roughness", &shape(t))),
        }
        match inputs.clearcoat {
            Input::Value(v) => m.clearcoat = v,
            ref t => m.textures.extend(texture(None, "clearcoat", &shape(t))),
        }
        match inputs.clearcoat_roughness {
            Input::Value(v) => m.clearcoat_roughness = v,
            ref t => m.textures.extend(texture(None, "clearcoatRoughness", &shape(t))),
        }
        if let Input::Value(v) = inputs.ior {
            m.ior = v;
        }
        m.specular_workflow = inputs.use_specular_workflow.unwrap_or(false);
        for (what, i) in [("emissiveColor", shape(&inputs.emissive_color)), ("opacity", shape(&inputs.opacity))] {
            match i {
                Input::Texture { .. } => notes.push(format!("texture on {what} ignored")),
                Input::Unset => {}
                Input::Value(()) => {}
            }
        }
        if let Input::Value(e) = inputs.emissive_color
            && e.iter().any(|&c| c > 0.0)
        {
            notes.push("emissiveColor ignored (direct lighting from the DomeLight only)".into());
        }
        if let Input::Value(o) = inputs.opacity
            && o < 1.0
        {
            notes.push(format!("opacity {o} ignored (rendered opaque)"));
        }
        Ok((m, notes))
    }
}

/// An input with its value dropped (only whether and how it is driven matters).
fn shape<T>(i: &Input<T>) -> Input<()> {
    match i {
        Input::Unset => Input::Unset,
        Input::Value(_) => Input::Value(()),
        Input::Texture(t) => Input::Texture(t.clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metallic_workflow() {
        let mut m = Material::fallback("m");
        let l = m.lobes();
        assert!((l.specular.x - 0.04).abs() < 1e-6);
        assert_eq!(l.diffuse, Vec3::splat(0.18));
        assert_eq!(l.alpha, 0.25);
        m.metallic = 1.0;
        m.diffuse_color = Vec3::new(0.9, 0.6, 0.2);
        let l = m.lobes();
        assert_eq!(l.diffuse, Vec3::ZERO);
        assert!((l.specular - Vec3::new(0.9, 0.6, 0.2)).length() < 1e-6);
        m.metallic = 0.5;
        m.ior = 2.0;
        let f0 = (1.0f32 / 3.0).powi(2);
        let l = m.lobes();
        assert!((l.specular.x - (0.5 * f0 + 0.45)).abs() < 1e-6);
        assert!((l.diffuse.x - 0.45).abs() < 1e-6);
    }

    #[test]
    fn specular_workflow() {
        let mut m = Material::fallback("m");
        m.specular_workflow = true;
        m.specular_color = Vec3::new(0.2, 0.3, 0.4);
        m.metallic = 1.0; // ignored in the specular workflow
        let l = m.lobes();
        assert_eq!(l.specular, Vec3::new(0.2, 0.3, 0.4));
        assert_eq!(l.diffuse, Vec3::splat(0.18));
    }
}
