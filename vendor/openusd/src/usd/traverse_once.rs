//! A traversal that composes each prim once (ppis patch, see PATCHED.md, "Composing
//! once"). [`Stage::traverse`] leaves every prim's composed index in the cache, where the
//! stage keeps it for its whole life: on a stage of many simple prims the indices are
//! most of its memory. A one-pass reader needs a prim's index while it reads the prim and
//! while the prim's children compose (each child's index starts from its parent's), and
//! never again, so [`Stage::traverse_once`] frees each index when the walk leaves the
//! prim's subtree.

use anyhow::Result;

use crate::sdf;

use super::stage::{PrimPredicate, PrimStatus, Stage};
use super::status::Inherited;

impl Stage {
    /// Visits the prims [`traverse`](Self::traverse) visits, in the same order,
    /// telling the visitor when it enters a prim and when it leaves it (after the
    /// prim's whole subtree), and frees each prim's composed index once the prim is
    /// left (ppis patch, see PATCHED.md, "Composing once"). A one-pass reader then
    /// holds only the indices of the prims on the path from the root to the one it
    /// reads, not the whole stage's: the visitor may query any prim during either
    /// call (a freed index composes again on demand, with the same result). The walk
    /// ends early, without error, when the visitor returns
    /// [`ControlFlow::Break`](std::ops::ControlFlow::Break).
    pub fn traverse_once(
        &self,
        predicate: PrimPredicate,
        mut visitor: impl FnMut(Visit<'_>) -> std::ops::ControlFlow<()>,
    ) -> Result<()> {
        enum Step {
            Enter(sdf::Path, Inherited),
            Leave(sdf::Path, bool),
            /// The children of a prim not yet entered, in order: a prim of many children
            /// holds a list of exactly their paths, not a step per child.
            Children(std::vec::IntoIter<sdf::Path>, Inherited),
        }
        let needed = predicate.consulted_bits();
        let mut stack = vec![Step::Enter(sdf::Path::abs_root(), Inherited::ROOT)];
        while let Some(step) = stack.pop() {
            let (path, above) = match step {
                Step::Enter(path, above) => (path, above),
                Step::Children(mut children, below) => {
                    if let Some(child) = children.next() {
                        stack.push(Step::Children(children, below));
                        stack.push(Step::Enter(child, below));
                    }
                    continue;
                }
                Step::Leave(path, visited) => {
                    if visited && visitor(Visit::Leave(&path)).is_break() {
                        return Ok(());
                    }
                    self.with_cache(|graph, cache| {
                        cache.release_index(graph, &path);
                        Ok(())
                    })?;
                    continue;
                }
            };
            let mut below = above;
            if path != sdf::Path::abs_root() {
                let (status, inherited) = self.prim_status_inherited(&path, needed, above)?;
                below = inherited;
                let visited = predicate.matches(status);
                if visited && visitor(Visit::Enter(&path)).is_break() {
                    return Ok(());
                }
                stack.push(Step::Leave(path.clone(), visited));
                let stops_at_instance = !predicate.traverse_instance_proxies && status.contains(PrimStatus::INSTANCE);
                if predicate.prunes_descendants(status) || stops_at_instance {
                    continue;
                }
            }
            let names = self.masked(&path, |g, cache| cache.prim_children(g, &path))?;
            let names = self.filter_child_names(&path, names);
            let mut children = Vec::with_capacity(names.len());
            children.extend(names.iter().filter_map(|name| path.append_path(name.as_str()).ok()));
            stack.push(Step::Children(children.into_iter(), below));
        }
        Ok(())
    }
}

/// What [`Stage::traverse_once`] tells its visitor.
#[derive(Clone, Copy, Debug)]
pub enum Visit<'a> {
    /// The walk reaches this prim; its subtree follows.
    Enter(&'a sdf::Path),
    /// The walk is done with this prim and its subtree.
    Leave(&'a sdf::Path),
}

#[cfg(test)]
mod tests {
    use std::ops::ControlFlow;

    use anyhow::Result;

    use super::Visit;
    use crate::test_tempdir as tempfile;
    use crate::usd::{PrimPredicate, Stage};

    const LAYER: &str = r#"#usda 1.0
def Xform "A" {
    def Sphere "B" { double radius = 2 }
    def Xform "C" {
        def Sphere "D" {}
    }
}
def Xform "E" (active = false) {
    def Sphere "F" {}
}
def Xform "G" {}
"#;

    fn stage() -> Result<(tempfile::TempDir, Stage)> {
        let dir = tempfile::tempdir()?;
        let file = dir.path().join("root.usda");
        std::fs::write(&file, LAYER)?;
        let stage = Stage::open(file.to_str().unwrap())?;
        Ok((dir, stage))
    }

    #[test]
    fn visits_what_traverse_visits_entering_and_leaving_each_subtree() -> Result<()> {
        let (_dir, stage) = stage()?;
        let mut plain = Vec::new();
        stage.traverse(PrimPredicate::DEFAULT, |p| plain.push(p.to_string()))?;
        let mut steps = Vec::new();
        stage.traverse_once(PrimPredicate::DEFAULT, |step| {
            steps.push(match step {
                Visit::Enter(p) => format!("+{p}"),
                Visit::Leave(p) => format!("-{p}"),
            });
            ControlFlow::Continue(())
        })?;
        let entered: Vec<String> = steps.iter().filter_map(|s| s.strip_prefix('+')).map(str::to_string).collect();
        assert_eq!(entered, plain);
        let want = ["+/A", "+/A/B", "-/A/B", "+/A/C", "+/A/C/D", "-/A/C/D", "-/A/C", "-/A", "+/G", "-/G"];
        assert_eq!(steps, want);
        Ok(())
    }

    #[test]
    fn frees_each_index_after_its_subtree_and_reads_the_same_again() -> Result<()> {
        let (_dir, stage) = stage()?;
        let mut held = Vec::new();
        stage.traverse_once(PrimPredicate::DEFAULT, |step| {
            if let Visit::Leave(p) = step {
                // The prim is still composed while the visitor is told it is left.
                held.push((p.to_string(), stage.cache().is_indexed(p)));
            }
            ControlFlow::Continue(())
        })?;
        assert!(held.iter().all(|(_, indexed)| *indexed), "{held:?}");
        for prim in ["/A", "/A/B", "/A/C", "/A/C/D", "/E", "/G"] {
            assert!(!stage.cache().is_indexed(&crate::sdf::path(prim)?), "{prim} is freed after the walk");
        }
        // What remains is the pseudo-root's, which the walk starts from.
        assert_eq!(stage.cache().indexed_count(), 1);
        let radius = stage.prim(crate::sdf::path("/A/B")?).attribute("radius").get::<f64>()?;
        assert_eq!(radius, Some(2.0));
        Ok(())
    }

    #[test]
    fn stops_when_the_visitor_breaks() -> Result<()> {
        let (_dir, stage) = stage()?;
        let mut entered = 0;
        stage.traverse_once(PrimPredicate::DEFAULT, |step| {
            entered += usize::from(matches!(step, Visit::Enter(_)));
            if entered == 2 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })?;
        assert_eq!(entered, 2);
        Ok(())
    }
}
