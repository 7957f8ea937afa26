//! The one module that talks to `openusd` (pinned to 0.6.0): opening a stage, walking its
//! prims and reading composed values as plain numbers, tokens and resolved asset paths
//! (`value.rs`), and the material bindings and UsdPreviewSurface networks (`shading.rs`). A
//! version bump of openusd touches this module only; the rest of host-usd sees [`Stage`] and
//! [`Value`].

mod prim_path;
mod shading;
mod time;
mod value;

pub use prim_path::{PrimMap, PrimPath, PrimRef};
pub use shading::{Input, PreviewInputs, TextureRef};
pub use time::TimeCode;
pub use value::Value;
use value::convert;

use openusd::ar::{self, Resolver};
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::{sdf, usd};
use std::cell::RefCell;
use std::ops::ControlFlow;
use std::path::Path;

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
    time: TimeCode,
    /// Prims known to apply (or not) MaterialBindingAPI (`shading.rs`).
    binding_api: RefCell<sdf::PathMap<bool>>,
    /// The composed property names of the prim asked about last (see [`Stage::authors`]).
    properties: RefCell<Option<(PrimPath, Vec<openusd::tf::Token>)>>,
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
    /// variants. Values are read at `time`.
    pub fn open(file: &Path, time: TimeCode) -> Result<Self> {
        let name = file.to_str().ok_or_else(|| "the path is not valid UTF-8".to_string())?;
        let inner = usd::Stage::open(name).map_err(err)?;
        Ok(Self { inner, time, binding_api: RefCell::default(), properties: RefCell::default() })
    }

    /// `prim`'s path in openusd's terms.
    fn path(&self, prim: &(impl PrimRef + ?Sized)) -> Result<sdf::Path> {
        Ok(prim.prim_path()?.0)
    }

    /// Recoverable composition problems (a missing reference, payload or sublayer).
    pub fn composition_errors(&self) -> Vec<String> {
        self.inner.composition_errors().iter().map(|e| e.to_string()).collect()
    }

    /// Root-layer metadata as a value (`upAxis`, `metersPerUnit`, …).
    pub fn metadata(&self, field: &str) -> Result<Option<Value>> {
        Ok(self.inner.stage_metadata(field).map_err(err)?.map(convert))
    }

    /// The identifiers of the layers composed so far (root layer stack, then those reached
    /// through references and payloads): after a traversal, every layer the stage reads.
    pub fn layers(&self) -> Vec<String> {
        self.inner.layer_identifiers()
    }

    /// The stage's `defaultPrim`, if authored.
    pub fn default_prim(&self) -> Option<String> {
        self.inner.default_prim().map(|t| t.as_str().to_string())
    }

    /// The time code values are read at.
    pub fn time(&self) -> TimeCode {
        self.time
    }

    /// The stage's `startTimeCode` and `endTimeCode`, when both are authored.
    pub fn time_code_range(&self) -> Option<(f64, f64)> {
        let inner = &self.inner;
        inner.has_authored_time_code_range().then(|| (inner.start_time_code(), inner.end_time_code()))
    }

    /// Every active, loaded, defined, non-abstract prim, depth first, including the
    /// contents of instanceable prims (as instance proxies).
    /// A namespace deeper than [`MAX_DEPTH`] is an error naming the first such prim.
    pub fn prims(&self) -> Result<Vec<PrimPath>> {
        let mut out = Vec::new();
        self.walk(|step| -> Result<()> {
            if let Step::Enter(p) = step {
                out.push(p);
            }
            Ok(())
        })?;
        Ok(out)
    }

    /// Visits the prims of [`prims`](Self::prims) in the same order, entering each before
    /// its subtree and leaving it after, and composes each prim once: the stage frees a
    /// prim's composition when the walk leaves it, so a one-pass reader holds the
    /// compositions of the prims from the root to the one it reads, not the whole stage's
    /// (docs/usd.md, "Import speed"). Any prim may still be read at any time; one left
    /// behind composes again. The first error, the visitor's or a namespace deeper than
    /// [`MAX_DEPTH`], ends the walk.
    pub fn walk<E: From<String>>(
        &self,
        mut visit: impl FnMut(Step) -> std::result::Result<(), E>,
    ) -> std::result::Result<(), E> {
        let mut failure = None;
        let walked = self.inner.traverse_once(usd::PrimPredicate::DEFAULT_PROXIES, |step| {
            let step = match step {
                usd::Visit::Enter(p) => Step::Enter(PrimPath(p.clone())),
                usd::Visit::Leave(p) => Step::Leave(PrimPath(p.clone())),
            };
            let outcome = match &step {
                Step::Enter(p) if p.depth() > MAX_DEPTH => Err(E::from(too_deep(p))),
                _ => visit(step),
            };
            outcome.map_err(|e| failure = Some(e)).map_or(ControlFlow::Break(()), ControlFlow::Continue)
        });
        walked.map_err(|e| E::from(err(e)))?;
        failure.map_or(Ok(()), Err)
    }

    /// Every composed prim, defined or not (`over`s, classes, inactive), without
    /// instance proxies: Pixar's `TraverseAll`.
    pub fn all_prims(&self) -> Result<Vec<PrimPath>> {
        let mut out = Vec::new();
        self.inner.traverse(usd::PrimPredicate::ALL, |p| out.push(PrimPath(p.clone()))).map_err(err)?;
        Ok(out)
    }

    /// The prim's type name (empty for a typeless prim).
    pub fn type_name(&self, prim: &(impl PrimRef + ?Sized)) -> Result<String> {
        let t = self.inner.prim(self.path(prim)?).type_name().map_err(err)?;
        Ok(t.map(|t| t.as_str().to_string()).unwrap_or_default())
    }

    /// The paths of the prim's children, in order.
    pub fn children(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Vec<PrimPath>> {
        let children = self.inner.prim(self.path(prim)?).children().map_err(err)?;
        Ok(children.iter().map(|c| PrimPath(c.path().clone())).collect())
    }

    /// True for an instanceable prim's instance.
    pub fn is_instance(&self, prim: &(impl PrimRef + ?Sized)) -> Result<bool> {
        self.inner.prim(self.path(prim)?).is_instance().map_err(err)
    }

    /// True for a prim inside an instance (a proxy of the prototype's prim).
    pub fn is_instance_proxy(&self, prim: &(impl PrimRef + ?Sized)) -> Result<bool> {
        self.inner.prim(self.path(prim)?).is_instance_proxy().map_err(err)
    }

    /// The prim's applied API schemas (`apiSchemas`).
    pub fn applied_schemas(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Vec<String>> {
        let s = self.inner.prim(self.path(prim)?).api_schemas().map_err(err)?;
        Ok(s.iter().map(|t| t.as_str().to_string()).collect())
    }

    /// Names of the prim's properties.
    pub fn property_names(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Vec<String>> {
        let names = self.inner.prim(self.path(prim)?).property_names().map_err(err)?;
        Ok(names.iter().map(|t| t.as_str().to_string()).collect())
    }

    /// Whether the prim has a property `name` among its composed property names. The
    /// importer asks about each prim's attributes one after the other, most of them
    /// unauthored (`doubleSided`, `visibility`, `purpose`, a mesh's optional arrays):
    /// the prim's names are composed once and an absent attribute costs no value
    /// resolution. Only the last prim's names are kept.
    fn authors(&self, prim: &(impl PrimRef + ?Sized), name: &str) -> Result<bool> {
        let prim = prim.prim_path()?;
        let mut memo = self.properties.borrow_mut();
        let names = match memo.as_ref() {
            Some((known, names)) if *known == prim => names,
            _ => {
                let names = self.inner.prim(prim.0.clone()).property_names().map_err(err)?;
                &memo.insert((prim, names)).1
            }
        };
        Ok(names.iter().any(|n| n.as_str() == name))
    }

    /// The composed value of `prim.attr` at the stage's time code (see [`TimeCode`]);
    /// `None` when unauthored, blocked, or (at [`TimeCode::Default`]) time-sampled only.
    pub fn value(&self, prim: &(impl PrimRef + ?Sized), attr: &str) -> Result<Option<Value>> {
        if !self.authors(prim, attr)? {
            return Ok(None);
        }
        let a = self.inner.prim(self.path(prim)?).attribute(attr);
        let v = a.get_at::<sdf::Value>(self.time.query()).map_err(|e| format!("{prim}.{attr}: {}", err(e)))?;
        Ok(v.map(convert))
    }

    /// Whether `prim.attr` has time samples (composed, from any layer).
    pub fn is_time_sampled(&self, prim: &(impl PrimRef + ?Sized), attr: &str) -> Result<bool> {
        if !self.authors(prim, attr)? {
            return Ok(false);
        }
        let a = self.inner.prim(self.path(prim)?).attribute(attr);
        Ok(a.num_time_samples().map_err(|e| format!("{prim}.{attr}: {}", err(e)))? > 0)
    }

    /// A metadata field of an attribute (`interpolation`, `elementSize`).
    pub fn attr_metadata(&self, prim: &(impl PrimRef + ?Sized), attr: &str, key: &str) -> Result<Option<Value>> {
        if !self.authors(prim, attr)? {
            return Ok(None);
        }
        let a = self.inner.prim(self.path(prim)?).attribute(attr);
        Ok(a.get_metadata::<sdf::Value>(key).map_err(err)?.map(convert))
    }

    /// Targets of a relationship, as paths.
    pub fn targets(&self, prim: &(impl PrimRef + ?Sized), rel: &str) -> Result<Vec<PrimPath>> {
        if !self.authors(prim, rel)? {
            return Ok(Vec::new());
        }
        let r = self.inner.prim(self.path(prim)?).relationship(rel);
        Ok(r.targets().map_err(err)?.into_iter().map(PrimPath).collect())
    }

    /// The composed `xformOpOrder` (list edits applied), or `None` when unauthored.
    pub fn xform_op_order(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Option<Vec<String>>> {
        if !self.authors(prim, "xformOpOrder")? {
            return Ok(None);
        }
        AnyXformable(self.inner.prim(self.path(prim)?)).xform_op_order().map_err(err)
    }

    /// True when the prim or an ancestor is `invisible`.
    pub fn is_invisible(&self, prim: &(impl PrimRef + ?Sized)) -> Result<bool> {
        let x = AnyXformable(self.inner.prim(self.path(prim)?));
        Ok(x.compute_visibility().map_err(err)? == openusd::schemas::geom::Visibility::Invisible)
    }

    /// Whether the prim itself authors `visibility = invisible` at the stage's time code (as
    /// UsdGeomImageable's ComputeVisibility reads it: visibility may be animated).
    pub fn authored_invisible(&self, prim: &(impl PrimRef + ?Sized)) -> Result<bool> {
        let v = self.value(prim, "visibility")?;
        Ok(matches!(v, Some(Value::Token(t)) if t == "invisible"))
    }

    /// The purpose the prim itself authors, if any (an unknown token reads as
    /// `default`, as ComputePurpose does).
    pub fn authored_purpose(&self, prim: &(impl PrimRef + ?Sized)) -> Result<Option<&'static str>> {
        let v = self.attr_metadata(prim, "purpose", "default")?;
        Ok(v.map(|v| match v.token() {
            Some("render") => "render",
            Some("proxy") => "proxy",
            Some("guide") => "guide",
            _ => "default",
        }))
    }

    /// The computed purpose token (`default`, `render`, `proxy`, `guide`).
    pub fn purpose(&self, prim: &(impl PrimRef + ?Sized)) -> Result<String> {
        let x = AnyXformable(self.inner.prim(self.path(prim)?));
        Ok(x.compute_purpose().map_err(err)?.as_token().to_string())
    }

    /// The bytes of a resolved asset (a file, or an entry inside a usdz package).
    pub fn read_asset(&self, resolved: &str) -> std::io::Result<Vec<u8>> {
        let resolver = ar::DefaultResolver::new();
        let mut asset = resolver.open_asset(&ar::ResolvedPath::new(resolved))?;
        asset.read_all()
    }
}

/// The deepest prim namespace imported: the usda parser's nesting limit, applied to
/// every format. Deeper stages are refused with an error rather than imported slowly
/// (each path is as long as its depth).
pub const MAX_DEPTH: usize = openusd::usda::parser::MAX_NAMESPACE_DEPTH;

fn too_deep(prim: &PrimPath) -> String {
    format!("{}/…: namespace deeper than {MAX_DEPTH} levels", prim.ancestor_at(3))
}

/// Where [`Stage::walk`] is.
pub enum Step {
    /// At this prim; its subtree follows.
    Enter(PrimPath),
    /// Done with this prim and its subtree.
    Leave(PrimPath),
}
