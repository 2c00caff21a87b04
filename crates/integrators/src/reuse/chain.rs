//! Which passes continue each other: what an estimator keeps between passes (the temporal
//! history, what ReSTIR DI learned) belongs to the passes of one render, and a pass that does
//! not continue them starts afresh.

use std::sync::Mutex;

/// The passes an estimator has rendered, as far as what it keeps between them is concerned: a
/// pass continues them when it is the next pass of the same seed, or the first pass after
/// [`PassChain::next_frame`] (a new frame of a sequence, whose seed and pass number are its
/// own). Any other pass (a new render with the same estimator, another part of a split render)
/// does not, so rendering twice with one estimator gives the same image twice.
#[derive(Debug, Default)]
pub struct PassChain(Mutex<Next>);

#[derive(Debug, Default)]
enum Next {
    /// Nothing rendered yet.
    #[default]
    Start,
    /// The seed and pass that continue the last one.
    Pass(u64, u32),
    /// A new frame begins: its first pass continues whatever its seed and number.
    Frame,
}

impl PassChain {
    /// Pass `pass` of a render with seed `seed` begins: whether it continues the passes before.
    pub fn advance(&self, seed: u64, pass: u32) -> bool {
        let Ok(mut next) = self.0.lock() else {
            return false;
        };
        let continues = match *next {
            Next::Start => false,
            Next::Pass(s, p) => (s, p) == (seed, pass),
            Next::Frame => true,
        };
        *next = Next::Pass(seed, pass.wrapping_add(1));
        continues
    }

    /// The next pass renders the next frame of a sequence and continues these passes.
    pub fn next_frame(&self) {
        if let Ok(mut next) = self.0.lock()
            && !matches!(*next, Next::Start)
        {
            *next = Next::Frame;
        }
    }
}
