//! The cross-crate tests in one binary: the stability suite through the renderer, and the docs'
//! paths.

mod common;
mod doc_paths;
mod stability;
mod stability_table;
