//! How the evaluation sweeps a technique, as data in its registry entry: the knobs are the
//! technique's, the machinery (`evaluate::sweep`: map sizes, box widths, storages, validation
//! as a scene's) the evaluation's. A new technique is swept by naming its plan here.

use crate::model::{ParamValue, Storage};

/// A technique's place in the evaluation's sweep.
#[derive(Clone, Copy, Debug)]
pub enum SweepPlan {
    /// Its defaults, at every map size.
    Defaults,
    /// Boxes of these radii (`quick`: these), the `every_size` one at every map size and the
    /// others at the base size; labelled `pcf box<2r+1>`.
    Radii {
        /// Radii of the full sweep.
        full: &'static [u32],
        /// Radii of a quick sweep.
        quick: &'static [u32],
        /// The radius run at every map size.
        every_size: u32,
    },
    /// The scene's own configuration (else the defaults) at every map size, and these
    /// (blocker search, filter) tap counts at the base size (not when quick); labelled by taps.
    Taps(&'static [(u32, u32)]),
    /// Labelled variants for the soft techniques (a summed-area-table lookup each step),
    /// validated as a scene's with the scene's light size: the first at every map size, the
    /// others at the base size; a quick sweep takes the first `quick` of them.
    Variants {
        /// Every variant.
        full: &'static [SweepVariant],
        /// How many of them a quick sweep takes.
        quick: usize,
    },
    /// A prefiltered encoding: every filter (blur, mips, table) at every box width in f32 and
    /// at the middle width in the other storages, at the base size; the default (f32, blur,
    /// middle width) at every map size.
    Prefiltered {
        /// The storages swept besides f32.
        storages: SweptStorages,
        /// CSM's term counts: the one the knobs are swept at (full, quick) and the others,
        /// run with the first filter at the middle width; `None` for the others.
        terms: Option<SweptTerms>,
    },
}

/// One labelled variant of [`SweepPlan::Variants`].
#[derive(Clone, Copy, Debug)]
pub struct SweepVariant {
    /// The configuration's label (before its map size).
    pub label: &'static str,
    /// Values over the defaults.
    pub values: &'static [(&'static str, ParamValue)],
    /// Its storage, if not the default.
    pub storage: Option<Storage>,
}

/// Which storages a prefiltered technique is swept in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweptStorages {
    /// f32 only (its one storage: ESM's log-space value).
    F32Only,
    /// The evaluation's storages (f32, f16).
    Standard,
    /// Those and unorm16 (MSM's 16-bit optimized quantization), in a full sweep.
    WithUnorm16,
}

/// CSM's term counts in the sweep.
#[derive(Clone, Copy, Debug)]
pub struct SweptTerms {
    /// The terms the knobs are swept at.
    pub full: u32,
    /// The same in a quick sweep.
    pub quick: u32,
    /// The other term counts (full sweep only).
    pub others: &'static [u32],
}
