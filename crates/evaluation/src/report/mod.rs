//! Outputs of a suite run: the CSV ([`csv`]), plots ([`plot`]), crop strips ([`strip`]), the
//! Markdown report ([`markdown`]), the interactive HTML page ([`html`]), the files written
//! together ([`files`]) and the marked section of another Markdown file ([`doc`]).

pub(crate) mod csv;
pub(crate) mod doc;
pub(crate) mod files;
pub mod html;
pub(crate) mod markdown;
pub(crate) mod plot;
pub(crate) mod strip;
