//! Benchmark-only crate for the restir workspace.
//!
//! The benchmarks live in `benches/`; run them with
//! `cargo bench -p restir-bench --bench gris`. This library target is empty on purpose: keeping
//! benchmarks in their own package keeps `divan` out of every library's dependency graph.
