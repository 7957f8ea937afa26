//! docs/design.md §9 shows `examples/embed.rs` between its `[embed]` markers, verbatim (one
//! indentation level less), so the documented embedding always compiles and runs.

#[test]
fn the_design_documents_embedding_is_the_compiled_example() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let example = std::fs::read_to_string(root.join("examples/embed.rs")).unwrap();
    let marker = "    // [embed]\n";
    let start = example.find(marker).expect("a first [embed] marker") + marker.len();
    let end = start + example[start..].find(marker).expect("a second [embed] marker");
    let code: String =
        example[start..end].lines().map(|l| format!("{}\n", l.strip_prefix("    ").unwrap_or(l))).collect();
    let design = std::fs::read_to_string(root.join("../docs/design.md")).unwrap();
    let section = &design[design.find("## 9.").expect("a §9")..];
    let block = &section[section.find("```rust\n").expect("a rust block") + 8..];
    let block = &block[..block.find("```\n").expect("the block's end")];
    assert_eq!(block, code, "docs/design.md §9 differs from sampler-core/examples/embed.rs: copy the example's code");
}
