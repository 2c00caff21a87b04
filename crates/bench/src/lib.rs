//! Benchmark-only crate for the restir workspace.
//!
//! The benchmarks live in `benches/`; run them with `cargo bench -p restir-bench --bench gris`
//! (divan) or `--bench render` (path-tracer passes/s and Mrays/s). This library target is empty
//! on purpose: keeping benchmarks in their own package keeps `divan` out of every library's
//! dependency graph.
