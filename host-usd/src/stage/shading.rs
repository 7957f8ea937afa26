//! Material bindings and UsdPreviewSurface networks: which material a prim is bound to, its
//! surface shader, and each input's value or the UsdUVTexture it is connected to.

use super::{PrimPath, PrimRef, Result, Stage, Value, convert, err, path};
use openusd::schemas::shade::{self, MaterialBindingAPI};
use openusd::sdf;

/// What a UsdPreviewSurface authors; `None` means unauthored (the schema's fallback applies).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreviewInputs {
    /// The Shader prim.
    pub shader: String,
    /// `inputs:diffuseColor`.
    pub diffuse_color: Input<[f32; 3]>,
    /// `inputs:specularColor`.
    pub specular_color: Input<[f32; 3]>,
    /// `inputs:emissiveColor`.
    pub emissive_color: Input<[f32; 3]>,
    /// `inputs:metallic`.
    pub metallic: Input<f32>,
    /// `inputs:roughness`.
    pub roughness: Input<f32>,
    /// `inputs:clearcoat`.
    pub clearcoat: Input<f32>,
    /// `inputs:clearcoatRoughness`.
    pub clearcoat_roughness: Input<f32>,
    /// `inputs:ior`.
    pub ior: Input<f32>,
    /// `inputs:opacity`.
    pub opacity: Input<f32>,
    /// `inputs:useSpecularWorkflow`.
    pub use_specular_workflow: Option<bool>,
    /// Inputs driven by a texture that is not a plain UsdUVTexture (or a normal map): named.
    pub unsupported: Vec<String>,
}

/// One UsdPreviewSurface input.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Input<T> {
    /// Not authored: the schema's fallback applies.
    #[default]
    Unset,
    /// An authored value.
    Value(T),
    /// Connected to a UsdUVTexture.
    Texture(TextureRef),
}

/// A UsdUVTexture as a UsdPreviewSurface input sees it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureRef {
    /// `inputs:file` as authored, and resolved against the layer that authored it.
    pub authored: String,
    /// The resolved path, when the asset resolves.
    pub resolved: Option<String>,
    /// `inputs:scale` and `inputs:bias` (RGBA).
    pub scale: [f32; 4],
    /// `inputs:bias` (RGBA).
    pub bias: [f32; 4],
    /// The output used: `rgb`, `r`, `g`, `b` or `a`.
    pub channel: String,
    /// The texture coordinate primvar (`inputs:varname` of the UsdPrimvarReader_float2 on
    /// `inputs:st`; `st` when unconnected).
    pub varname: String,
    /// `inputs:wrapS`, `inputs:wrapT` (`black`, `clamp`, `repeat`, `mirror`, `useMetadata`).
    pub wrap: [String; 2],
    /// `inputs:sourceColorSpace` (`auto`, `raw`, `sRGB`).
    pub color_space: String,
}

impl Stage {
    /// The material bound to the prim for full rendering (`material:binding:full` over the
    /// whole ancestor chain, then all-purpose `material:binding`): the nearest binding on a
    /// prim that applies MaterialBindingAPI, unless an ancestor's is `strongerThanDescendants`
    /// (the topmost such wins). openusd 0.6 reads `bindMaterialAs` only when it is a token,
    /// which a usda file's string is not, so direct bindings are resolved here; chains with
    /// collection bindings go through openusd's resolver.
    pub fn bound_material(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Option<String>> {
        let mut chain = Vec::new();
        let mut p = Some(self.path(prim)?);
        while let Some(here) = p {
            if here.is_abs_root() {
                break;
            }
            p = here.parent();
            chain.push(here);
        }
        let mut with_api = Vec::new();
        for (i, here) in chain.iter().enumerate() {
            if self.applies_binding_api(here, i > 0)? {
                with_api.push(here.clone());
            }
        }
        let collections = with_api.iter().try_fold(false, |any, here| -> Result<bool> {
            let names = self.inner.prim(here.clone()).property_names().map_err(err)?;
            Ok(any || names.iter().any(|n| n.as_str().starts_with("material:binding:collection")))
        })?;
        if collections {
            let Some(nearest) = with_api.first() else { return Ok(None) };
            let api = MaterialBindingAPI::get(&self.inner, nearest.clone()).map_err(err)?;
            let m = match api {
                Some(api) => api.compute_bound_material("full").map_err(|e| format!("{prim}: {}", err(e)))?,
                None => None,
            };
            return Ok(m.map(|p| p.to_string()));
        }
        for rel in ["material:binding:full", "material:binding"] {
            let mut winner = None;
            for here in &with_api {
                let Some(target) = self.targets(&PrimPath(here.clone()), rel)?.into_iter().next() else { continue };
                let rel_path = here.append_property(rel).map_err(err)?;
                let strength = self.inner.attribute(rel_path).get_metadata::<sdf::Value>("bindMaterialAs");
                let stronger = match strength.map_err(err)?.map(convert) {
                    Some(Value::Token(t)) => t == "strongerThanDescendants",
                    _ => false,
                };
                if winner.is_none() || stronger {
                    winner = Some(target.to_string());
                }
            }
            if winner.is_some() {
                return Ok(winner);
            }
        }
        Ok(None)
    }

    /// The material's surface shader id (`UsdPreviewSurface`, `ND_standard_surface…`), if any.
    /// Whether the prim applies MaterialBindingAPI; memoised for `ancestor`s, which
    /// every prim below them asks about again (once per prim, not per prim and level).
    fn applies_binding_api(&self, prim: &sdf::Path, ancestor: bool) -> Result<bool> {
        if let Some(&known) = self.binding_api.borrow().get(prim) {
            return Ok(known);
        }
        let applies = MaterialBindingAPI::get(&self.inner, prim.clone()).map_err(err)?.is_some();
        if ancestor {
            self.binding_api.borrow_mut().insert(prim.clone(), applies);
        }
        Ok(applies)
    }

    /// The Shader prim behind a Material's `outputs:surface`, with its `info:id`.
    pub fn surface_shader(&self, material: &str) -> Result<Option<(String, String)>> {
        // The universal `outputs:surface`, followed through NodeGraph outputs (openusd 0.6
        // stops at a NodeGraph), is what a UsdPreviewSurface renderer reads.
        if let Some(source) = self.connection(material, "outputs:surface")? {
            let shader = source.prim_path().as_str().to_string();
            let id = self.value(&shader, "info:id")?.and_then(|v| v.token().map(str::to_string));
            if let Some(id) = id {
                return Ok(Some((shader, id)));
            }
        }
        let Some(m) = shade::Material::get(&self.inner, path(material)?).map_err(err)? else {
            return Ok(None);
        };
        let Some(s) = m.compute_surface_source().map_err(err)? else {
            return Ok(None);
        };
        Ok(Some((s.path().as_str().to_string(), s.id().map_err(err)?.unwrap_or_default())))
    }

    /// The inputs of a UsdPreviewSurface shader.
    pub fn preview_inputs(&self, shader: &str) -> Result<PreviewInputs> {
        let color =
            |name: &str| self.input(shader, name, 3).map(|i| map_input(i, |v| [v[0] as f32, v[1] as f32, v[2] as f32]));
        let scalar = |name: &str| self.input(shader, name, 1).map(|i| map_input(i, |v| v[0] as f32));
        let mut unsupported = Vec::new();
        if self.connection(shader, "inputs:normal")?.is_some() {
            unsupported.push("normal map".to_string());
        }
        if self.connection(shader, "inputs:displacement")?.is_some() {
            unsupported.push("displacement".to_string());
        }
        let use_spec = self.value(shader, "inputs:useSpecularWorkflow")?.and_then(|v| v.scalar()).map(|v| v != 0.0);
        Ok(PreviewInputs {
            shader: shader.to_string(),
            diffuse_color: color("diffuseColor")?,
            specular_color: color("specularColor")?,
            emissive_color: color("emissiveColor")?,
            metallic: scalar("metallic")?,
            roughness: scalar("roughness")?,
            clearcoat: scalar("clearcoat")?,
            clearcoat_roughness: scalar("clearcoatRoughness")?,
            ior: scalar("ior")?,
            opacity: scalar("opacity")?,
            use_specular_workflow: use_spec,
            unsupported,
        })
    }

    /// The attribute a connection of `prim.attr` points at, following interface
    /// connections (NodeGraph / Material inputs) to the end; `None` when unconnected.
    fn connection(&self, prim: &(impl PrimRef + ?Sized), attr: &str) -> Result<Option<sdf::Path>> {
        let mut current = self.path(prim)?.append_property(attr).map_err(err)?;
        let mut connected = None;
        for _ in 0..16 {
            let next = self.inner.attribute(current.clone()).connections().map_err(err)?.into_iter().next();
            match next {
                Some(n) => {
                    connected = Some(n.clone());
                    current = n;
                }
                None => break,
            }
        }
        Ok(connected)
    }

    /// The value of `prim.attr`, or of the attribute its connections end at (an interface
    /// input of a Material or NodeGraph).
    fn connected_value(&self, prim: &(impl PrimRef + ?Sized), attr: &str) -> Result<Option<Value>> {
        match self.connection(prim, attr)? {
            Some(p) => Ok(self.inner.attribute(p).get::<sdf::Value>().map_err(err)?.map(convert)),
            None => self.value(prim, attr),
        }
    }

    /// One shader input: its authored value (numbers with `n` components), or the texture
    /// it is connected to.
    fn input(&self, shader: &str, name: &str, n: usize) -> Result<Input<Vec<f64>>> {
        let attr = format!("inputs:{name}");
        if let Some(source) = self.connection(shader, &attr)? {
            let tex = source.prim_path();
            let tex_prim = tex.as_str().to_string();
            // The output's name without its namespace: `/Mat/Tex.outputs:r` → `r`.
            let property = source.as_str().strip_prefix(tex.as_str()).and_then(|p| p.strip_prefix('.'));
            let channel = property.and_then(|p| p.strip_prefix("outputs:")).unwrap_or_default().to_string();
            let id = self.value(&tex_prim, "info:id")?.and_then(|v| v.token().map(str::to_string));
            if id.as_deref() == Some("UsdUVTexture") {
                let file_value = self.connected_value(&tex_prim, "inputs:file")?;
                let four = |a: &str, d: f64| -> Result<[f32; 4]> {
                    let v = self.value(&tex_prim, a)?.and_then(|v| v.numbers().map(<[f64]>::to_vec));
                    let v = v.unwrap_or_default();
                    Ok(std::array::from_fn(|i| v.get(i).copied().unwrap_or(d) as f32))
                };
                if let Some(Value::Asset { authored, resolved }) = file_value {
                    let token = |prim: &str, a: &str, d: &str| -> Result<String> {
                        let v = self.connected_value(prim, a)?;
                        Ok(v.and_then(|v| v.token().map(str::to_string)).unwrap_or_else(|| d.to_string()))
                    };
                    // The st input reads a primvar through a UsdPrimvarReader_float2.
                    let varname = match self.connection(&tex_prim, "inputs:st")? {
                        Some(reader) => token(reader.prim_path().as_str(), "inputs:varname", "st")?,
                        None => "st".into(),
                    };
                    return Ok(Input::Texture(TextureRef {
                        authored,
                        resolved,
                        scale: four("inputs:scale", 1.0)?,
                        bias: four("inputs:bias", 0.0)?,
                        channel,
                        varname,
                        wrap: [
                            token(&tex_prim, "inputs:wrapS", "useMetadata")?,
                            token(&tex_prim, "inputs:wrapT", "useMetadata")?,
                        ],
                        color_space: token(&tex_prim, "inputs:sourceColorSpace", "auto")?,
                    }));
                }
                return Ok(Input::Unset);
            }
        }
        // Authored here, or on the interface input it is connected to.
        Ok(match self.connected_value(shader, &attr)?.as_ref().and_then(Value::numbers) {
            Some(v) if v.len() >= n => Input::Value(v.to_vec()),
            _ => Input::Unset,
        })
    }
}

fn map_input<T>(i: Input<Vec<f64>>, f: impl Fn(&[f64]) -> T) -> Input<T> {
    match i {
        Input::Unset => Input::Unset,
        Input::Value(v) => Input::Value(f(&v)),
        Input::Texture(t) => Input::Texture(t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A UsdPreviewSurface whose inputs read a texture through `outputs:rgb`, `outputs:r`,
    /// `outputs:g` and `outputs:a`.
    const NETWORK: &str = r#"#usda 1.0
def Material "Mat"
{
    token outputs:surface.connect = </Mat/Surface.outputs:surface>
    def Shader "Surface"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </Mat/Tex.outputs:rgb>
        float inputs:roughness.connect = </Mat/Tex.outputs:r>
        float inputs:metallic.connect = </Mat/Tex.outputs:g>
        float inputs:opacity.connect = </Mat/Tex.outputs:a>
        token outputs:surface
    }
    def Shader "Tex"
    {
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @tex.png@
        float3 outputs:rgb
        float outputs:r
        float outputs:g
        float outputs:a
    }
}
"#;

    #[test]
    fn a_texture_channel_is_named_without_its_outputs_namespace() {
        let dir = tempfile::Builder::new().prefix("ppis-usd-channel-").tempdir().unwrap();
        let file = dir.path().join("channels.usda");
        std::fs::write(&file, NETWORK).unwrap();
        let stage = Stage::open(&file, super::super::TimeCode::Earliest).unwrap();
        let (shader, id) = stage.surface_shader("/Mat").unwrap().unwrap();
        assert_eq!((shader.as_str(), id.as_str()), ("/Mat/Surface", "UsdPreviewSurface"));
        let inputs = stage.preview_inputs(&shader).unwrap();
        let channel = |input: &Input<f32>| match input {
            Input::Texture(t) => t.channel.clone(),
            other => panic!("not a texture: {other:?}"),
        };
        match &inputs.diffuse_color {
            Input::Texture(t) => assert_eq!(t.channel, "rgb"),
            other => panic!("not a texture: {other:?}"),
        }
        assert_eq!(channel(&inputs.roughness), "r");
        assert_eq!(channel(&inputs.metallic), "g");
        assert_eq!(channel(&inputs.opacity), "a");
    }
}
