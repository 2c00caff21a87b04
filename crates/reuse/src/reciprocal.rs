//! Reciprocal spatial reuse: neighbours chosen in pairs, so one pair of shifts serves both
//! pixels of a pair.
//!
//! Pairwise MIS at pixel `p` with neighbour `q` needs two shifts: `q`'s sample into `p`
//! (the candidate) and `p`'s sample into `q` (the canonical sample's weight). At `q` with
//! neighbour `p` it needs the same two. When the neighbour relation is symmetric each pair's
//! shifts are therefore computed once and read by both pixels, halving the shifts (and their
//! shadow rays and replayed segments) of a round. The idea of sharing one shift between the
//! two pixels of a reciprocal pair is from Lin, Kettunen and Wyman ("ReSTIR PT Enhanced").
//!
//! Each round draws `⌈k/2⌉` offsets `o_j` in the disk of the reuse radius, the same for every
//! pixel of the pass (from a stream of the pass and round alone, so a cropped render draws the
//! same ones); pixel `p`'s neighbours are `p + o_j` and `p − o_j` that exist, have a surface
//! and pass the similarity test (which is symmetric). The choice depends on the surfaces and the
//! pass's stream only, never on reservoirs, so the reuse stays unbiased. A round runs in two
//! phases: the shifts of every pair `(p, p + o_j)`, stored per pixel and offset, then each
//! pixel's resampling with a [`ShiftMap`] that reads them. Both run chunk of rows by chunk of
//! rows, so the table holds the pairs of one chunk and of the rows its pixels' neighbours reach
//! (64 rows and the radius above and below on up to 4 threads; 16 rows per thread beyond), not
//! the whole image's. [`table_bytes`] bounds it for memory estimates.

use std::borrow::Borrow;

use restir_gris::{MisScheme, Reservoir, ShiftMap, Shifted};
use restir_sampling::Pcg32;

use crate::bands::{BAND_ROWS, Bands};
use crate::passes::{Expected, Scratch, resample_pixel};
use crate::settings::ReuseSettings;
use crate::shift::ReuseShift;
use crate::surfaces::{Streams, Surfaces};

/// Whether `scheme` uses only shifts between the canonical pixel and each neighbour (the
/// pairwise family), the shifts a reciprocal pair shares.
pub fn shares_pair_shifts(scheme: MisScheme) -> bool {
    matches!(
        scheme,
        MisScheme::Pairwise | MisScheme::DefensivePairwise | MisScheme::ConfidenceWeightedPairwise
    )
}

/// Bytes of the shift table the reciprocal rounds of `settings` keep at most (0 when they do not
/// run) for a film of `width × height` pixels on `threads` threads, for an estimator's
/// `buffer_bytes`: the pairs of the window of rows a round holds, which spans the whole film
/// only when the film is short or the threads are many.
pub fn table_bytes<S>(
    settings: &ReuseSettings,
    width: usize,
    height: usize,
    threads: usize,
) -> u64 {
    if !settings.runs_reciprocal() {
        return 0;
    }
    // A round's offsets lie in the disk of the radius, so no pair reaches further in rows.
    let reach = settings.radius.max(0.0).ceil() as usize;
    let rows = Window::with_threads(height, reach, threads).rows();
    let entries = (settings.neighbors as usize).div_ceil(2);
    (rows * width * entries * std::mem::size_of::<Option<PairShifts<S>>>()) as u64
}

/// The two shifts of a pair `(a, b = a + o_j)`: `a`'s sample into `b` and `b`'s into `a`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PairShifts<S> {
    a_into_b: Option<Shifted<S>>,
    b_into_a: Option<Shifted<S>>,
}

/// A domain as the cached map sees it: the pixel being resampled, or one of its neighbours
/// named by the pair entry that holds their shifts.
#[derive(Clone, Copy, Debug)]
enum Slot {
    Canonical,
    /// The pair's entry in the table and whether the canonical pixel is the pair's first
    /// pixel `a` (neighbour `p + o_j`) or its second `b` (neighbour `p − o_j`).
    Neighbor {
        entry: usize,
        canonical_is_a: bool,
    },
}

/// The shift map of one pixel's resampling: every shift is read from the round's table.
struct CachedShifts<'t, S> {
    table: &'t [Option<PairShifts<S>>],
    /// Negative control: read the other shift of the pair.
    mismatched: bool,
}

impl<S: Copy> ShiftMap<S> for CachedShifts<'_, S> {
    type Domain = Slot;

    fn shift(&self, from: &Slot, to: &Slot, _sample: &S) -> Option<Shifted<S>> {
        let (entry, canonical_is_a, into_neighbor) = match (*from, *to) {
            (
                Slot::Canonical,
                Slot::Neighbor {
                    entry,
                    canonical_is_a,
                },
            ) => (entry, canonical_is_a, true),
            (
                Slot::Neighbor {
                    entry,
                    canonical_is_a,
                },
                Slot::Canonical,
            ) => (entry, canonical_is_a, false),
            // Pairwise MIS shifts only between the canonical pixel and a neighbour.
            _ => {
                debug_assert!(false, "a reciprocal pair has no shift {from:?} → {to:?}");
                return None;
            }
        };
        let pair = self.table[entry].as_ref()?;
        // canonical = a: into the neighbour is a→b; canonical = b: into the neighbour is b→a.
        if (into_neighbor == canonical_is_a) != self.mismatched {
            pair.a_into_b
        } else {
            pair.b_into_a
        }
    }
}

/// The rows of a round, resampled chunk by chunk: the table holds the pairs of one chunk's
/// rows and of the rows its neighbours reach, not the image's (at 1800×1080 pixels and 4
/// neighbours a whole image's table of light samples held 300 MB).
#[derive(Clone, Copy, Debug)]
struct Window {
    height: usize,
    /// Rows per chunk: enough bands for every thread.
    chunk: usize,
    /// How many rows above and below a pixel its neighbours lie.
    reach: usize,
}

impl Window {
    /// The window of a round on the current pool's threads.
    fn new(height: usize, reach: usize) -> Self {
        Self::with_threads(height, reach, rayon::current_num_threads())
    }

    fn with_threads(height: usize, reach: usize, threads: usize) -> Self {
        let chunk = (8 * BAND_ROWS * threads).max(64);
        Self {
            height,
            chunk,
            reach,
        }
    }

    /// Rows the table holds at most.
    fn rows(&self) -> usize {
        (self.chunk + 2 * self.reach).min(self.height)
    }

    /// The chunks, `(first row, end row)`, in order.
    fn chunks(self) -> impl Iterator<Item = (usize, usize)> {
        (0..self.height)
            .step_by(self.chunk)
            .map(move |r| (r, (r + self.chunk).min(self.height)))
    }

    /// The rows whose pairs the pixels of `chunk` read.
    fn reached(&self, (first, end): (usize, usize)) -> (usize, usize) {
        (
            first.saturating_sub(self.reach),
            (end + self.reach).min(self.height),
        )
    }
}

/// Offsets of one round: `count` distinct integer offsets in the disk of `radius` pixels, none
/// zero and none the negation of another.
fn round_offsets(radius: f32, count: usize, rng: &mut Pcg32) -> Vec<(i64, i64)> {
    let mut out: Vec<(i64, i64)> = Vec::with_capacity(count);
    let r = radius.max(1.0);
    // Distinct offsets of the disk, up to sign: about 1.5 r² of them; ask for no more.
    let wanted = count.min((1.5 * r * r) as usize).max(1);
    let mut tries = 0;
    while out.len() < wanted && tries < 1000 {
        tries += 1;
        let (u, v) = (2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0);
        if u * u + v * v > 1.0 {
            continue;
        }
        let o = ((u * r).round() as i64, (v * r).round() as i64);
        if o == (0, 0) || out.iter().any(|&q| q == o || q == (-o.0, -o.1)) {
            continue;
        }
        out.push(o);
    }
    out
}

/// `R` reciprocal spatial rounds (see the module docs); the settings must use a pairwise MIS
/// ([`shares_pair_shifts`]). With `expected` (as long as the image), the last round also
/// writes each pixel's expectation of its shading over the selection. The buffers come from
/// `scratch` and go back to it. Returns the rays traced.
#[allow(clippy::too_many_arguments)]
pub fn spatial<R: ReuseShift, G: Surfaces>(
    reuse: &R,
    settings: &ReuseSettings,
    streams: &impl Streams,
    surfaces: &G,
    first_stage: u64,
    current: &mut Vec<Reservoir<R::Sample>>,
    mut expected: Option<&mut Expected>,
    scratch: &mut Scratch<R::Sample>,
) -> u64 {
    debug_assert!(shares_pair_shifts(settings.mis));
    let (w, h) = (surfaces.width() as i64, surfaces.height() as i64);
    let bands = Bands::new(surfaces.width());
    let similarity = settings.similarity();
    let n = current.len();
    let mut next = scratch.next(n);
    let mut rays = 0;
    let pairs_per_round = (settings.neighbors as usize).div_ceil(2);
    let mut table = std::mem::take(&mut scratch.table);
    for round in 0..settings.spatial_rounds {
        let stage = first_stage + u64::from(round);
        let last = round + 1 == settings.spatial_rounds;
        let offsets = round_offsets(
            settings.radius,
            pairs_per_round,
            &mut streams.pass(stage ^ 0x5eed_0ff5),
        );
        let m = offsets.len();
        if m == 0 {
            break;
        }
        let input = &*current;
        // The pixel at offset `o` from `a`, if it is on the film.
        let step = |a: usize, (ox, oy): (i64, i64)| -> Option<usize> {
            let (x, y) = (a as i64 % w + ox, a as i64 / w + oy);
            (x >= 0 && y >= 0 && x < w && y < h).then_some((y * w + x) as usize)
        };
        // The partner `a + o` of pixel `a`, when the pair exists (both hit, similar).
        let partner = |a: usize, o: (i64, i64)| -> Option<usize> {
            let b = step(a, o)?;
            surfaces.similar(a, b, &similarity).then_some(b)
        };

        // The rows a pixel's pairs reach: its neighbours p ± o_j lie within `reach` rows.
        let reach = offsets
            .iter()
            .map(|&(_, oy)| oy.unsigned_abs() as usize)
            .max();
        let reach = reach.unwrap_or(0);
        let window = Window::new(surfaces.height(), reach);
        // The expectation's slots, in the last round only.
        let mut slots = expected.as_deref_mut().filter(|_| last).map(|e| &mut e[..]);
        let expect = slots.is_some();
        let width = surfaces.width();
        table.clear();
        table.resize(window.rows() * width * m, None);
        // Rows of the image whose pairs' shifts the table holds: [held.0, held.1).
        let mut held = (0usize, 0usize);
        for chunk in window.chunks() {
            // Phase 1: the shifts of every pair (a, a + o_j) of rows the chunk's pixels reach,
            // at entry (a − the window's first pixel)·m + j. Rows the window held for the
            // chunk before are moved to its front, not shifted again.
            let want = window.reached(chunk);
            let keep = (want.0.max(held.0), held.1.min(want.1));
            if keep.0 < keep.1 {
                table.copy_within(
                    (keep.0 - held.0) * width * m..(keep.1 - held.0) * width * m,
                    (keep.0 - want.0) * width * m,
                );
            }
            let fresh = if keep.0 < keep.1 { keep.1 } else { want.0 };
            let first_fresh = fresh * width;
            let fresh_entries =
                &mut table[(fresh - want.0) * width * m..(want.1 - want.0) * width * m];
            rays += bands.run_strided(fresh_entries, m, |first, out| {
                let mut rays = 0;
                for (i, entries) in out.chunks_mut(m).enumerate() {
                    let a = first_fresh + first + i;
                    for (entry, &o) in entries.iter_mut().zip(&offsets) {
                        *entry = None;
                        let Some(b) = partner(a, o) else {
                            continue;
                        };
                        let (da, db) = (reuse.domain(a, false), reuse.domain(b, false));
                        let (ra, rb) = (&input[a], &input[b]);
                        let map_a = reuse.map(ra);
                        let a_into_b = ra
                            .sample
                            .as_ref()
                            .and_then(|y| map_a.shift(da.borrow(), db.borrow(), y));
                        rays += R::rays(&map_a);
                        let map_b = reuse.map(rb);
                        let b_into_a = rb
                            .sample
                            .as_ref()
                            .and_then(|y| map_b.shift(db.borrow(), da.borrow(), y));
                        rays += R::rays(&map_b);
                        *entry = Some(PairShifts { a_into_b, b_into_a });
                    }
                }
                rays
            });
            held = want;

            // Phase 2: every pixel of the chunk resamples with its neighbours p + o_j and
            // p − o_j.
            let table = &table[..];
            let base = want.0 * width;
            let (lo, hi) = (chunk.0 * width, chunk.1 * width);
            let chunk_slots = slots.as_deref_mut().map(|s| &mut s[lo..hi]);
            bands.run(
                (&mut next[lo..hi], chunk_slots),
                |first, (out, mut slots)| {
                    let mut neighbors = Vec::with_capacity(2 * m);
                    for (i, res) in out.iter_mut().enumerate() {
                        let p = lo + first + i;
                        let canonical = &input[p];
                        if !surfaces.has_surface(p) {
                            *res = *canonical;
                            continue;
                        }
                        neighbors.clear();
                        for (j, &(ox, oy)) in offsets.iter().enumerate() {
                            // Pair (p, p + o_j), entered at p; pair (p − o_j, p), entered at
                            // p − o_j.
                            let at_p = (p - base) * m + j;
                            if table[at_p].is_some()
                                && let Some(q) = step(p, (ox, oy))
                            {
                                let slot = Slot::Neighbor {
                                    entry: at_p,
                                    canonical_is_a: true,
                                };
                                neighbors.push((slot, &input[q]));
                            }
                            if let Some(q) = step(p, (-ox, -oy))
                                && table[(q - base) * m + j].is_some()
                            {
                                let slot = Slot::Neighbor {
                                    entry: (q - base) * m + j,
                                    canonical_is_a: false,
                                };
                                neighbors.push((slot, &input[q]));
                            }
                        }
                        let mut rng = streams.pixel(p, stage);
                        let (out, e) = resample_pixel::<R, _, _>(
                            &CachedShifts {
                                table,
                                mismatched: settings.reciprocal_mismatched,
                            },
                            settings.mis,
                            &Slot::Canonical,
                            canonical,
                            &neighbors,
                            || rng.next_f32(),
                            expect,
                        );
                        *res = out.with_confidence_cap(settings.mcap);
                        if let Some(slots) = slots.as_deref_mut() {
                            slots[i] = e;
                        }
                    }
                    0
                },
            );
        }
        std::mem::swap(current, &mut next);
    }
    scratch.next = next;
    scratch.table = table;
    rays
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_are_distinct_up_to_sign_and_inside_the_disk() {
        let mut rng = Pcg32::new(3, 5);
        for radius in [1.0f32, 2.0, 3.0, 10.0, 30.0] {
            let o = round_offsets(radius, 4, &mut rng);
            assert!(!o.is_empty() && o.len() <= 4, "{radius}: {o:?}");
            for (i, &(x, y)) in o.iter().enumerate() {
                assert!((x, y) != (0, 0));
                assert!(((x * x + y * y) as f32).sqrt() <= radius.max(1.0) + 0.75);
                for &(x2, y2) in &o[..i] {
                    assert!((x2, y2) != (x, y) && (x2, y2) != (-x, -y));
                }
            }
        }
    }

    /// The memory estimate counts the rows a round's table holds, not the film's: a 4K film's
    /// table is the window's few rows (and a short film's all of them).
    #[test]
    fn table_bytes_count_the_window_of_rows() {
        let mut settings = ReuseSettings::direct();
        settings.neighbors = 12;
        settings.radius = 2.5;
        assert!(settings.runs_reciprocal());
        let entry = std::mem::size_of::<Option<PairShifts<[f32; 4]>>>() as u64;
        let bytes = |s: &ReuseSettings, w, h, threads| table_bytes::<[f32; 4]>(s, w, h, threads);
        let s = &settings;
        // 64 rows per chunk on up to 4 threads, and 3 rows (the radius) above and below.
        assert_eq!(bytes(s, 3840, 2160, 2), 70 * 3840 * 6 * entry);
        assert_eq!(bytes(s, 3840, 2160, 4), 70 * 3840 * 6 * entry);
        // 16 rows per thread beyond.
        assert_eq!(bytes(s, 3840, 2160, 8), 134 * 3840 * 6 * entry);
        assert_eq!(bytes(s, 640, 50, 2), 50 * 640 * 6 * entry);
        assert_eq!(bytes(s, 640, 2160, 1000), 2160 * 640 * 6 * entry);
        let off = ReuseSettings {
            reciprocal: false,
            ..settings
        };
        assert_eq!(bytes(&off, 3840, 2160, 2), 0);
    }
}
