//! `host-std`: the renderer around `sampler-core` (environment maps, tracer, command line).
//! Tracked by the host-std issue; this crate currently only hosts the `ppis` entry point.
