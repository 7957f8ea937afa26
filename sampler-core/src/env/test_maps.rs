//! Maps for the descents' tests: every kind of mass the register paths must handle as the
//! scalar ones do.

use std::vec;
use std::vec::Vec;

/// RGB maps of `4^level` texels: smooth, zeros in rows and columns, a 1e7× texel beside a
/// denormal-sized one, a single lit texel, masses near `f32::MAX`, none.
pub(super) fn maps(level: u32) -> Vec<Vec<[f32; 3]>> {
    let n = 1usize << (2 * level);
    let smooth: Vec<[f32; 3]> = (0..n).map(|i| [(i * 7 % 13) as f32 + 0.5, (i % 3) as f32, 1.0]).collect();
    let mut holes = smooth.clone();
    holes.iter_mut().enumerate().filter(|(i, _)| i % 5 < 2 || (i / 7) % 3 == 0).for_each(|(_, t)| *t = [0.0; 3]);
    let mut sun = smooth.clone();
    sun[n / 3] = [1e7; 3];
    sun[n / 2] = [1e-38; 3];
    let mut lone = vec![[0.0f32; 3]; n];
    lone[n - 1] = [2.0; 3];
    let huge: Vec<[f32; 3]> = (0..n).map(|i| [3e38 * ((i % 4) as f32 / 4.0); 3]).collect();
    vec![smooth, holes, sun, lone, huge, vec![[0.0f32; 3]; n]]
}
