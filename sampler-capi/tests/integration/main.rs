//! The C ABI's integration tests in one binary. `arguments` has a binary of its own, since its
//! counting allocator is the whole process's.

mod examples;
mod header;
mod properties;
