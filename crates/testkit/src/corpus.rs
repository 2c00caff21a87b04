//! The shared scene corpus (`../shared/corpus` beside the clone): where it is, and
//! [`corpus_test!`](crate::corpus_test), which declares a test that reads it. A test that needs
//! the corpus must not report `ok` without it: when the corpus was absent at build time (and
//! `CI` unset) such tests are `#[ignore]`d with the reason; under CI, or when run with
//! `--ignored`, they run and [`corpus_dir`] fails with the path it looked for.

use std::path::PathBuf;

/// Why corpus tests are ignored when the corpus is missing.
pub const CORPUS_IGNORE_REASON: &str = "needs ../shared/corpus (the scene corpus beside the clone)";

/// The corpus directory. Panics, naming the path, when it is missing: a corpus test must fail
/// rather than pass without checking.
pub fn corpus_dir() -> PathBuf {
    let dir = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/corpus"
    ));
    assert!(
        dir.is_dir(),
        "the scene corpus is missing at {} (required when CI is set; otherwise the corpus tests \
         are ignored when it is absent at build time: `touch crates/testkit/build.rs` after \
         adding or removing it)",
        dir.display()
    );
    dir
}

/// Declares a `#[test]` that reads the shared corpus: ignored (with
/// [`CORPUS_IGNORE_REASON`]) when the corpus was absent at build time outside CI, a normal test
/// otherwise. The body gets the corpus directory from [`corpus_dir`].
///
/// ```text
/// restir_testkit::corpus_test! {
///     /// Loads a corpus scene.
///     fn a_corpus_scene_loads() {
///         let dir = restir_testkit::corpus_dir();
///         assert!(dir.join("lajolla").is_dir());
///     }
/// }
/// ```
#[cfg(not(restir_corpus_absent))]
#[macro_export]
macro_rules! corpus_test {
    ($(#[$meta:meta])* fn $name:ident() $body:block) => {
        $(#[$meta])*
        #[test]
        fn $name() $body
    };
}

/// Declares a `#[test]` that reads the shared corpus (see the other definition): the corpus was
/// absent at build time, so the test is ignored with its reason.
#[cfg(restir_corpus_absent)]
#[macro_export]
macro_rules! corpus_test {
    ($(#[$meta:meta])* fn $name:ident() $body:block) => {
        $(#[$meta])*
        #[test]
        #[ignore = "needs ../shared/corpus (the scene corpus beside the clone)"]
        fn $name() $body
    };
}
