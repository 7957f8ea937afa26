//! Checks the pinned images (`../image_cases/mod.rs`) as the build renders them.

#[path = "../image_cases/mod.rs"]
mod image_cases;

// `image_cases` reaches the shared scenes as `super::common`.
use crate::common;
use image_cases::{EXPECTED, cases};

#[test]
fn images_are_bit_identical_to_the_recorded_hashes() {
    let actual = cases();
    let table: String = actual.iter().map(|(case, h)| format!("    (\"{case}\", 0x{h:016x}),\n")).collect();
    let expected: Vec<(String, u64)> = EXPECTED.iter().map(|&(c, h)| (c.to_string(), h)).collect();
    assert!(
        actual == expected,
        "the rendered images differ from the recorded ones. If that is meant (the commit says \
         why), replace EXPECTED in host-std/tests/image_cases/mod.rs with:\n\
         const EXPECTED: &[(&str, u64)] = &[\n{table}];"
    );
}
