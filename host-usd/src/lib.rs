//! `host-usd`: USD scene import (usda, usdc, usdz) for ppis through the pure-Rust `openusd`
//! crate (pinned to 0.6.0). `stage/` is the only module that touches openusd; the rest
//! works on its plain values and yields a [`UsdScene`] of plain data.

#![warn(missing_docs)]

pub mod blackbody;
pub mod camera;
pub mod conformance;
pub mod dome;
pub mod error;
mod guard;
pub mod import;
pub mod inherit;
pub mod instanced;
pub mod instancer;
pub mod lights;
pub mod material;
pub mod mesh;
pub mod primvar;
pub mod render_settings;
pub mod scene;
pub mod shapes;
pub mod shaping;
pub mod stage;
pub mod xform;
pub mod xform_ops;

pub use error::UsdError;
pub use import::{Options, load, load_with};
pub use scene::*;
pub use stage::TimeCode;
