//! Maps and sets keyed by [`Path`] that hash a path by the 64-bit hash it carries.
//!
//! A path's hash is computed once, when the path is made, and is already well mixed
//! (SipHash for a leaf, a Murmur3 finish for a child), so feeding it through the
//! standard map's SipHash again only costs time: about a hundred instructions per
//! lookup, and a layer's specs, the prim indices and their dependencies are looked up
//! by path many times per prim.

use super::Path;
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A hasher that takes a written `u64` as the hash. Other writes (keys that are not
/// paths) are folded in byte by byte, so it stays a hasher for any key, if a weak one.
#[derive(Default, Clone, Copy)]
pub struct PathHasher(u64);

impl Hasher for PathHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        }
    }

    /// The first write is the hash as it is; a key of several paths (a tuple) folds each
    /// one in turned, so that `(a, b)` and `(b, a)` differ and `(a, a)` is not zero.
    fn write_u64(&mut self, n: u64) {
        self.0 = self.0.rotate_left(29) ^ n;
    }
}

/// The `BuildHasher` of [`PathMap`] and [`PathSet`].
pub type BuildPathHasher = BuildHasherDefault<PathHasher>;

/// A `HashMap` keyed by [`Path`], hashed by the path's own hash.
pub type PathMap<V> = HashMap<Path, V, BuildPathHasher>;

/// A `HashSet` of [`Path`]s, hashed by the paths' own hashes.
pub type PathSet = HashSet<Path, BuildPathHasher>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    #[test]
    fn a_path_hashes_to_its_own_hash() {
        let path = Path::new("/World/Mesh.points").unwrap();
        assert_eq!(BuildPathHasher::default().hash_one(&path), path.hash_value());
        let mut map: PathMap<u32> = PathMap::default();
        map.insert(path.clone(), 7);
        assert_eq!(map.get(&Path::new("/World/Mesh.points").unwrap()), Some(&7));
    }

    #[test]
    fn a_pair_of_paths_hashes_by_its_order() {
        let (a, b) = (Path::new("/A").unwrap(), Path::new("/B").unwrap());
        let build = BuildPathHasher::default();
        assert_ne!(build.hash_one((&a, &b)), build.hash_one((&b, &a)));
        assert_ne!(build.hash_one((&a, &a)), 0);
    }

    #[test]
    fn other_keys_still_hash_by_their_bytes() {
        let mut a = PathHasher::default();
        "ab".hash(&mut a);
        let mut b = PathHasher::default();
        "ba".hash(&mut b);
        assert_ne!(a.finish(), b.finish());
    }
}
