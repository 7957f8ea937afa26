//! A prim body's property names in the order it declares them, each once (ppis patch, see
//! PATCHED.md).
//!
//! A property is declared by its default, its `.connect` and its `.timeSamples` lines, each
//! of which names it again. A scan of the names so far per declaration made a body of `n`
//! properties cost `n²` comparisons, minutes for a hostile file with 10⁵ properties on one
//! prim; past a few names a hash set answers instead. The prim indexer composes a prim's
//! variant set names across its layers the same way.

use std::collections::HashSet;

use crate::tf;

/// How many names are scanned before the set is built: most prims declare a handful.
const SCAN_LIMIT: usize = 16;

/// Names in first-declared order, without repeats.
#[derive(Debug, Default)]
pub(crate) struct OrderedNames {
    names: Vec<tf::Token>,
    /// Every name in `names`, once there are more than [`SCAN_LIMIT`].
    seen: Option<HashSet<tf::Token>>,
}

impl OrderedNames {
    /// Appends `name` unless it is already there.
    pub(crate) fn push(&mut self, name: tf::Token) {
        let is_new = match &mut self.seen {
            Some(seen) => seen.insert(name.clone()),
            None => !self.names.contains(&name),
        };
        if !is_new {
            return;
        }
        self.names.push(name);
        if self.seen.is_none() && self.names.len() > SCAN_LIMIT {
            self.seen = Some(self.names.iter().cloned().collect());
        }
    }

    /// Appends every name of `other` that is not already here, in `other`'s order.
    pub(super) fn extend(&mut self, other: OrderedNames) {
        for name in other.names {
            self.push(name);
        }
    }

    /// The names, in the order they were first pushed.
    pub(crate) fn into_vec(self) -> Vec<tf::Token> {
        self.names
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Order and uniqueness are the same below and above the scan limit.
    #[test]
    fn keeps_first_order_without_repeats() {
        for n in [3, SCAN_LIMIT, 5 * SCAN_LIMIT] {
            let mut names = OrderedNames::default();
            for i in (0..n).chain((0..n).rev()).chain(0..n) {
                names.push(tf::Token::from(format!("p{i}")));
            }
            let mut more = OrderedNames::default();
            more.push(tf::Token::from("p0"));
            more.push(tf::Token::from("q"));
            names.extend(more);
            let expected: Vec<String> = (0..n).map(|i| format!("p{i}")).chain(["q".to_string()]).collect();
            let got: Vec<String> = names.into_vec().iter().map(|t| t.as_str().to_string()).collect();
            assert_eq!(got, expected);
        }
    }
}
