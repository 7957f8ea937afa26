//! Values a prim inherits from its ancestors (world transform, visibility, purpose),
//! memoised per path and resolved top-down: a prim costs one step from its parent's
//! answer, never a walk to the root, and no recursion, however deep the namespace.

use crate::stage::{PrimMap, PrimPath, Stage};

/// The value of `prim`: the unresolved ancestors (nearest memoised one or the
/// pseudo-root, whose value is `root`, excluded) are resolved top-down, each by
/// `step(path, parent's value)`, and memoised. `prim` itself is not: the walk asks
/// once per prim, and only ancestors are asked again (by each prim below them), so
/// a stage's leaves, most of its prims, take no memory.
#[allow(clippy::mutable_key_type, reason = "a path's interior mutability is its text cache, outside Eq and Hash")]
pub fn resolve_down<T: Clone>(
    memo: &mut PrimMap<T>,
    prim: &PrimPath,
    root: T,
    mut step: impl FnMut(&PrimPath, &T) -> Result<T, String>,
) -> Result<T, String> {
    let mut chain = Vec::new();
    let mut here = prim.clone();
    let mut value = loop {
        if here.is_root() {
            break root;
        }
        if let Some(v) = memo.get(&here) {
            break v.clone();
        }
        let up = here.parent().unwrap_or_else(PrimPath::root);
        chain.push(here);
        here = up;
    };
    for (i, path) in chain.into_iter().enumerate().rev() {
        value = step(&path, &value)?;
        if i > 0 {
            memo.insert(path, value.clone());
        }
    }
    Ok(value)
}

/// Computed visibility and purpose (UsdGeomImageable's rules), memoised.
#[derive(Default)]
pub struct Hidden {
    invisible: PrimMap<bool>,
    purpose: PrimMap<&'static str>,
}

impl Hidden {
    /// Invisible (the prim or an ancestor authors `visibility = invisible`), or of
    /// purpose `proxy` or `guide` (the nearest authored purpose).
    pub fn hidden(&mut self, stage: &Stage, prim: &PrimPath) -> Result<bool, String> {
        let invisible =
            resolve_down(&mut self.invisible, prim, false, |p, above| Ok(*above || stage.authored_invisible(p)?))?;
        if invisible {
            return Ok(true);
        }
        let purpose = resolve_down(&mut self.purpose, prim, "default", |p, above| {
            Ok(stage.authored_purpose(p)?.unwrap_or(*above))
        })?;
        Ok(matches!(purpose, "proxy" | "guide"))
    }
}
