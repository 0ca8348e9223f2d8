//! What a technique's maps hold, as its entry declares it: the encoding a prefiltered technique
//! stores ([`Encoding`], with the parameters its f64 reference takes) and the names of its maps'
//! channels ([`MapChannels`], for `shadowgraph dump`).

use super::{REGISTRY, TechniqueDef};
use crate::model::Technique;

/// The representation a prefiltered technique's encoding kernel stores per texel of linear
/// depth, and its filter reads: what the numerical-stability suite compares, stage by stage,
/// with the f64 reference of the same name (`cpu::vsm`, `cpu::evsm`, …).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// VSM's moments `(z, z²)`.
    Vsm,
    /// EVSM's warped exponentials with exponents `c⁺`, `c⁻` (`evsm2` stores the first two of
    /// the four channels).
    Evsm {
        /// c⁺.
        exp_pos: f32,
        /// c⁻.
        exp_neg: f32,
    },
    /// ESM's `c·z` (log space).
    Esm {
        /// c.
        exponent: f32,
    },
    /// MSM's four power moments, raw or through the 16-bit quantization.
    Msm {
        /// Whether the moments are quantized (`msm_quantized`).
        quantized: bool,
    },
    /// CSM's Fourier basis of `terms` terms.
    Csm {
        /// M.
        terms: u32,
    },
}

/// The encoding `t` stores, if it is a prefiltered technique ([`TechniqueDef::encoding`]).
pub fn encoding(t: &Technique) -> Option<Encoding> {
    (super::of(t).encoding)(t)
}

/// No encoded map: the technique reads the depth, or builds its table from the depth.
pub(super) fn no_encoding(_: &Technique) -> Option<Encoding> {
    None
}

/// How a kind of resource names its channels.
#[derive(Clone, Copy, Debug)]
pub enum ChannelNaming {
    /// Fixed names, in texel order. A texture with more channels than names stores padding
    /// (e.g. CSM's last pair of terms in `Rgba16Float`): the extra channels are not dumped.
    /// Packed f16 pairs (`graph::PACKED_F16X2`, one `r32uint` word a texel) are unpacked on
    /// readback and dumped as their two float channels.
    Fixed(&'static [&'static str]),
    /// Fourier coefficients split into chunks `<kind><k>` (`csm0`, `csm1`, …): channel pairs
    /// `sin_j`, `cos_j` with `j = k·(channels / 2) + pair + 1` (1-based, as the terms of a
    /// Fourier series).
    Fourier,
}

/// A resource kind and how its channels are named.
#[derive(Clone, Copy, Debug)]
pub struct MapChannels {
    /// The kind: what follows `light{i}.` up to the next `.` (e.g. `vsm` for
    /// `light0.vsm.blur_h`). For [`ChannelNaming::Fourier`], the kind without its chunk index.
    pub kind: &'static str,
    /// How its channels are named.
    pub naming: ChannelNaming,
}

/// VSM's moments (`vsm`, `vssm`); f16 storage pads to four channels.
pub(super) const VSM_MAPS: MapChannels = MapChannels {
    kind: "vsm",
    naming: ChannelNaming::Fixed(&["z", "z2"]),
};

/// MSM's four power moments b1..b4 (f32), or their optimized quantization (16-bit storage),
/// named alike (`msm`, `msm_soft`, CSSM's moment search).
pub(super) const MSM_MAPS: MapChannels = MapChannels {
    kind: "msm",
    naming: ChannelNaming::Fixed(&["b1", "b2", "b3", "b4"]),
};

/// CSM's Fourier basis in chunks `csm0`, `csm1`, … of two terms (`csm`, `cssm`).
pub(super) const CSM_MAPS: MapChannels = MapChannels {
    kind: "csm",
    naming: ChannelNaming::Fourier,
};

/// Every technique's map kinds ([`TechniqueDef::maps`]), in registry order (a kind two entries
/// share appears twice, named alike).
pub fn map_kinds() -> impl Iterator<Item = &'static MapChannels> {
    REGISTRY.iter().flat_map(|d: &&TechniqueDef| d.maps.iter())
}
