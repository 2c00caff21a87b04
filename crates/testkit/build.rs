//! Build script: decides once whether the tests that read the shared scene corpus
//! (`../shared/corpus` beside the clone) can run. When the corpus is absent and `CI` is unset it
//! sets `cfg(restir_corpus_absent)`, and [`corpus_test!`](src/corpus.rs) marks those tests
//! `#[ignore]` (so `cargo test` reports them as ignored, not as passed). Under CI the cfg is never
//! set: the tests run and fail on the missing corpus.

use std::path::Path;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(restir_corpus_absent)");
    println!("cargo::rerun-if-env-changed=CI");
    println!("cargo::rerun-if-changed=build.rs");
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let corpus = Path::new(&manifest).join("../../../shared/corpus");
    if corpus.is_dir() {
        // Rerun when the corpus changes or disappears. (A corpus added later is not noticed:
        // `touch crates/testkit/build.rs` then; watching a missing path would rebuild every
        // test on every run.)
        println!("cargo::rerun-if-changed={}", corpus.display());
    } else if std::env::var_os("CI").is_none() {
        println!("cargo::rustc-cfg=restir_corpus_absent");
    }
}
