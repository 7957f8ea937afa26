//! The one file that talks to `openusd` (pinned to 0.6.0): opening a stage, walking its
//! prims and reading composed values as plain numbers, tokens and resolved asset paths. A
//! version bump of openusd touches this file only; the rest of host-usd sees [`Stage`] and
//! [`Value`].

use openusd::ar::{self, Resolver};
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::schemas::shade::{self, MaterialBindingAPI};
use openusd::{sdf, usd};
use std::path::Path;

/// A composed value, reduced to what the importer needs.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// Every numeric scalar, vector, quaternion (w, x, y, z) and matrix, flattened, of any
    /// precision; `shape` is the number of components per element (1 for scalars).
    Numbers {
        values: Vec<f64>,
        shape: usize,
        array: bool,
    },
    Token(String),
    Tokens(Vec<String>),
    Bool(bool),
    /// An asset path as authored, and resolved against the layer that authored it.
    Asset {
        authored: String,
        resolved: Option<String>,
    },
    Other(String),
}

impl Value {
    pub fn numbers(&self) -> Option<&[f64]> {
        match self {
            Value::Numbers { values, .. } => Some(values),
            _ => None,
        }
    }

    pub fn scalar(&self) -> Option<f64> {
        match self {
            Value::Numbers { values, shape: 1, array: false } => values.first().copied(),
            Value::Bool(b) => Some(f64::from(u8::from(*b))),
            _ => None,
        }
    }

    pub fn token(&self) -> Option<&str> {
        match self {
            Value::Token(t) => Some(t),
            _ => None,
        }
    }
}

/// What a UsdPreviewSurface authors; `None` means unauthored (the schema's fallback applies).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreviewInputs {
    pub shader: String,
    pub diffuse_color: Input<[f32; 3]>,
    pub specular_color: Input<[f32; 3]>,
    pub emissive_color: Input<[f32; 3]>,
    pub metallic: Input<f32>,
    pub roughness: Input<f32>,
    pub clearcoat: Input<f32>,
    pub clearcoat_roughness: Input<f32>,
    pub ior: Input<f32>,
    pub opacity: Input<f32>,
    pub use_specular_workflow: Option<bool>,
    /// Inputs driven by a texture that is not a plain UsdUVTexture (or a normal map): named.
    pub unsupported: Vec<String>,
}

/// One UsdPreviewSurface input.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Input<T> {
    #[default]
    Unset,
    Value(T),
    /// Connected to a UsdUVTexture.
    Texture(TextureRef),
}

/// A UsdUVTexture as a UsdPreviewSurface input sees it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureRef {
    /// `inputs:file` as authored, and resolved against the layer that authored it.
    pub authored: String,
    pub resolved: Option<String>,
    /// `inputs:scale` and `inputs:bias` (RGBA).
    pub scale: [f32; 4],
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

/// Any prim seen as Xformable/Imageable (openusd's typed views only wrap matching types).
struct AnyXformable(usd::Prim);

impl usd::SchemaBase for AnyXformable {
    const KIND: usd::SchemaKind = usd::SchemaKind::ConcreteTyped;
    fn prim(&self) -> &usd::Prim {
        &self.0
    }
}
impl Imageable for AnyXformable {}
impl Xformable for AnyXformable {}

/// An opened, composed USD stage.
pub struct Stage {
    inner: usd::Stage,
    time: usd::TimeCode,
}

type Result<T> = std::result::Result<T, String>;

fn err(e: impl std::fmt::Display) -> String {
    format!("{e:#}")
}

fn path(p: &str) -> Result<sdf::Path> {
    sdf::path(p).map_err(err)
}

impl Stage {
    /// Opens `file` (usda, usdc or usdz), composing sublayers, references, payloads and
    /// variants. Values are read at the stage's start time code.
    pub fn open(file: &Path) -> Result<Self> {
        let name = file.to_str().ok_or_else(|| "the path is not valid UTF-8".to_string())?;
        let inner = usd::Stage::open(name).map_err(err)?;
        let time = usd::TimeCode::new(inner.start_time_code());
        Ok(Self { inner, time })
    }

    /// Recoverable composition problems (a missing reference, payload or sublayer).
    pub fn composition_errors(&self) -> Vec<String> {
        self.inner.composition_errors().iter().map(|e| e.to_string()).collect()
    }

    /// Root-layer metadata as a value (`upAxis`, `metersPerUnit`, …).
    pub fn metadata(&self, field: &str) -> Result<Option<Value>> {
        Ok(self.inner.stage_metadata(field).map_err(err)?.map(convert))
    }

    pub fn default_prim(&self) -> Option<String> {
        self.inner.default_prim().map(|t| t.as_str().to_string())
    }

    pub fn time(&self) -> f64 {
        self.time.value()
    }

    /// Every active, loaded, defined, non-abstract prim, depth first, including the
    /// contents of instanceable prims (as instance proxies).
    /// A namespace deeper than [`MAX_DEPTH`] is an error naming the first such prim.
    pub fn prims(&self) -> Result<Vec<String>> {
        let mut out = Vec::new();
        self.inner.traverse(usd::PrimPredicate::DEFAULT_PROXIES, |p| out.push(p.as_str().to_string())).map_err(err)?;
        check_depth(&out)?;
        Ok(out)
    }

    /// Every composed prim, defined or not (`over`s, classes, inactive), without
    /// instance proxies: Pixar's `TraverseAll`.
    pub fn all_prims(&self) -> Result<Vec<String>> {
        let mut out = Vec::new();
        self.inner.traverse(usd::PrimPredicate::ALL, |p| out.push(p.as_str().to_string())).map_err(err)?;
        Ok(out)
    }

    pub fn type_name(&self, prim: &str) -> Result<String> {
        let t = self.inner.prim(path(prim)?).type_name().map_err(err)?;
        Ok(t.map(|t| t.as_str().to_string()).unwrap_or_default())
    }

    pub fn children(&self, prim: &str) -> Result<Vec<String>> {
        let children = self.inner.prim(path(prim)?).children().map_err(err)?;
        Ok(children.iter().map(|c| c.path().as_str().to_string()).collect())
    }

    pub fn is_instance(&self, prim: &str) -> Result<bool> {
        self.inner.prim(path(prim)?).is_instance().map_err(err)
    }

    pub fn is_instance_proxy(&self, prim: &str) -> Result<bool> {
        self.inner.prim(path(prim)?).is_instance_proxy().map_err(err)
    }

    pub fn applied_schemas(&self, prim: &str) -> Result<Vec<String>> {
        let s = self.inner.prim(path(prim)?).api_schemas().map_err(err)?;
        Ok(s.iter().map(|t| t.as_str().to_string()).collect())
    }

    /// Names of the prim's properties.
    pub fn property_names(&self, prim: &str) -> Result<Vec<String>> {
        let names = self.inner.prim(path(prim)?).property_names().map_err(err)?;
        Ok(names.iter().map(|t| t.as_str().to_string()).collect())
    }

    /// The composed value of `prim.attr` at the stage's start time (time samples
    /// interpolated), or its default; `None` when unauthored.
    pub fn value(&self, prim: &str, attr: &str) -> Result<Option<Value>> {
        let a = self.inner.prim(path(prim)?).attribute(attr);
        let v = a.get_at::<sdf::Value>(self.time).map_err(|e| format!("{prim}.{attr}: {}", err(e)))?;
        let v = match v {
            Some(v) => Some(v),
            None => a.get::<sdf::Value>().map_err(|e| format!("{prim}.{attr}: {}", err(e)))?,
        };
        Ok(v.map(convert))
    }

    /// A metadata field of an attribute (`interpolation`, `elementSize`).
    pub fn attr_metadata(&self, prim: &str, attr: &str, key: &str) -> Result<Option<Value>> {
        let a = self.inner.prim(path(prim)?).attribute(attr);
        Ok(a.get_metadata::<sdf::Value>(key).map_err(err)?.map(convert))
    }

    /// Targets of a relationship, as paths.
    pub fn targets(&self, prim: &str, rel: &str) -> Result<Vec<String>> {
        let r = self.inner.prim(path(prim)?).relationship(rel);
        Ok(r.targets().map_err(err)?.iter().map(|p| p.as_str().to_string()).collect())
    }

    /// The composed `xformOpOrder` (list edits applied), or `None` when unauthored.
    pub fn xform_op_order(&self, prim: &str) -> Result<Option<Vec<String>>> {
        AnyXformable(self.inner.prim(path(prim)?)).xform_op_order().map_err(err)
    }

    /// True when the prim or an ancestor is `invisible`.
    pub fn is_invisible(&self, prim: &str) -> Result<bool> {
        let x = AnyXformable(self.inner.prim(path(prim)?));
        Ok(x.compute_visibility().map_err(err)? == openusd::schemas::geom::Visibility::Invisible)
    }

    /// Whether the prim itself authors `visibility = invisible` (its default value, as
    /// UsdGeomImageable's ComputeVisibility reads it).
    pub fn authored_invisible(&self, prim: &str) -> Result<bool> {
        let v = self.attr_metadata(prim, "visibility", "default")?;
        Ok(matches!(v, Some(Value::Token(t)) if t == "invisible"))
    }

    /// The purpose the prim itself authors, if any (an unknown token reads as
    /// `default`, as ComputePurpose does).
    pub fn authored_purpose(&self, prim: &str) -> Result<Option<&'static str>> {
        let v = self.attr_metadata(prim, "purpose", "default")?;
        Ok(v.map(|v| match v.token() {
            Some("render") => "render",
            Some("proxy") => "proxy",
            Some("guide") => "guide",
            _ => "default",
        }))
    }

    /// The computed purpose token (`default`, `render`, `proxy`, `guide`).
    pub fn purpose(&self, prim: &str) -> Result<String> {
        let x = AnyXformable(self.inner.prim(path(prim)?));
        Ok(x.compute_purpose().map_err(err)?.as_token().to_string())
    }

    /// The material bound to the prim for full rendering (`material:binding:full` over the
    /// whole ancestor chain, then all-purpose `material:binding`): the nearest binding on a
    /// prim that applies MaterialBindingAPI, unless an ancestor's is `strongerThanDescendants`
    /// (the topmost such wins). openusd 0.6 reads `bindMaterialAs` only when it is a token,
    /// which a usda file's string is not, so direct bindings are resolved here; chains with
    /// collection bindings go through openusd's resolver.
    pub fn bound_material(&self, prim: &str) -> Result<Option<String>> {
        let mut chain = Vec::new();
        let mut p = Some(path(prim)?);
        while let Some(here) = p {
            if here.is_abs_root() {
                break;
            }
            p = here.parent();
            chain.push(here);
        }
        let mut with_api = Vec::new();
        for here in &chain {
            if MaterialBindingAPI::get(&self.inner, here.clone()).map_err(err)?.is_some() {
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
            return Ok(m.map(|p| p.as_str().to_string()));
        }
        for rel in ["material:binding:full", "material:binding"] {
            let mut winner = None;
            for here in &with_api {
                let Some(target) = self.targets(here.as_str(), rel)?.into_iter().next() else { continue };
                let rel_path = here.append_property(rel).map_err(err)?;
                let strength = self.inner.attribute(rel_path).get_metadata::<sdf::Value>("bindMaterialAs");
                let stronger = match strength.map_err(err)?.map(convert) {
                    Some(Value::Token(t)) => t == "strongerThanDescendants",
                    _ => false,
                };
                if winner.is_none() || stronger {
                    winner = Some(target);
                }
            }
            if winner.is_some() {
                return Ok(winner);
            }
        }
        Ok(None)
    }

    /// The material's surface shader id (`UsdPreviewSurface`, `ND_standard_surface…`), if any.
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
    fn connection(&self, prim: &str, attr: &str) -> Result<Option<sdf::Path>> {
        let mut current = path(prim)?.append_property(attr).map_err(err)?;
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
    fn connected_value(&self, prim: &str, attr: &str) -> Result<Option<Value>> {
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
            let channel = source.name().unwrap_or_default().trim_start_matches("outputs:").to_string();
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

    /// The bytes of a resolved asset (a file, or an entry inside a usdz package).
    pub fn read_asset(&self, resolved: &str) -> std::io::Result<Vec<u8>> {
        let resolver = ar::DefaultResolver::new();
        let mut asset = resolver.open_asset(&ar::ResolvedPath::new(resolved))?;
        asset.read_all()
    }
}

fn map_input<T>(i: Input<Vec<f64>>, f: impl Fn(&[f64]) -> T) -> Input<T> {
    match i {
        Input::Unset => Input::Unset,
        Input::Value(v) => Input::Value(f(&v)),
        Input::Texture(t) => Input::Texture(t),
    }
}

/// The deepest prim namespace imported: the usda parser's nesting limit, applied to
/// every format. Deeper stages are refused with an error rather than imported slowly
/// (each path is as long as its depth).
pub const MAX_DEPTH: usize = openusd::usda::parser::MAX_NAMESPACE_DEPTH;

fn check_depth(prims: &[String]) -> Result<()> {
    let too_deep = prims.iter().find(|p| p.bytes().filter(|&b| b == b'/').count() > MAX_DEPTH);
    match too_deep {
        Some(p) => {
            let cut = p.match_indices('/').nth(3).map_or(p.len(), |(i, _)| i);
            Err(format!("{}/…: namespace deeper than {MAX_DEPTH} levels", &p[..cut]))
        }
        None => Ok(()),
    }
}

/// openusd's value → ours.
fn convert(v: sdf::Value) -> Value {
    use sdf::Value as V;
    fn nums(values: Vec<f64>, shape: usize, array: bool) -> Value {
        Value::Numbers { values, shape, array }
    }
    macro_rules! flat {
        ($v:expr, $($f:ident),+) => { $v.iter().flat_map(|e| [$(e.$f as f64),+]).collect::<Vec<f64>>() };
    }
    macro_rules! flath {
        ($v:expr, $($f:ident),+) => { $v.iter().flat_map(|e| [$(e.$f.to_f64()),+]).collect::<Vec<f64>>() };
    }
    match v {
        V::Bool(b) => Value::Bool(b),
        V::Uchar(x) => nums(vec![x.into()], 1, false),
        V::Int(x) => nums(vec![x.into()], 1, false),
        V::Uint(x) => nums(vec![x.into()], 1, false),
        V::Int64(x) => nums(vec![x as f64], 1, false),
        V::Uint64(x) => nums(vec![x as f64], 1, false),
        V::Half(x) => nums(vec![x.to_f64()], 1, false),
        V::Float(x) => nums(vec![x.into()], 1, false),
        V::Double(x) => nums(vec![x], 1, false),
        V::UcharVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::IntVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::UintVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::Int64Vec(x) => nums(x.into_iter().map(|e| e as f64).collect(), 1, true),
        V::Uint64Vec(x) => nums(x.into_iter().map(|e| e as f64).collect(), 1, true),
        V::HalfVec(x) => nums(x.into_iter().map(|e| e.to_f64()).collect(), 1, true),
        V::FloatVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::DoubleVec(x) => nums(x, 1, true),
        V::Vec2f(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2d(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2h(e) => nums(flath!([e], x, y), 2, false),
        V::Vec2i(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2fVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec2dVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec2hVec(v) => nums(flath!(v, x, y), 2, true),
        V::Vec2iVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec3f(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3d(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3h(e) => nums(flath!([e], x, y, z), 3, false),
        V::Vec3i(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3fVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec3dVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec3hVec(v) => nums(flath!(v, x, y, z), 3, true),
        V::Vec3iVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec4f(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4d(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4h(e) => nums(flath!([e], x, y, z, w), 4, false),
        V::Vec4i(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4fVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Vec4dVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Vec4hVec(v) => nums(flath!(v, x, y, z, w), 4, true),
        V::Vec4iVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Quatf(e) => nums(flat!([e], w, x, y, z), 4, false),
        V::Quatd(e) => nums(flat!([e], w, x, y, z), 4, false),
        V::Quath(e) => nums(flath!([e], w, x, y, z), 4, false),
        V::QuatfVec(v) => nums(flat!(v, w, x, y, z), 4, true),
        V::QuatdVec(v) => nums(flat!(v, w, x, y, z), 4, true),
        V::QuathVec(v) => nums(flath!(v, w, x, y, z), 4, true),
        V::Matrix4d(m) => nums(m.0.to_vec(), 16, false),
        V::Matrix3d(m) => nums(m.0.to_vec(), 9, false),
        V::Matrix4dVec(v) => nums(v.iter().flat_map(|m| m.0).collect(), 16, true),
        V::Token(t) => Value::Token(t.as_str().to_string()),
        V::String(s) => Value::Token(s),
        V::TokenVec(v) => Value::Tokens(v.iter().map(|t| t.as_str().to_string()).collect()),
        V::StringVec(v) => Value::Tokens(v),
        V::AssetPath(a) => Value::Asset {
            authored: a.evaluated_path().unwrap_or(a.as_str()).to_string(),
            resolved: a.resolved_path().map(str::to_string),
        },
        other => Value::Other(format!("{other:?}").chars().take(80).collect()),
    }
}
