//! How a summed-area table stores its sums: plain data the technique model holds
//! (`Filter::Sat`, `Soft`) and the table's kernels read.

/// How the table stores its sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SatVariant {
    /// u32 fixed point with wraparound (`r32uint` … `rgba32uint`): exact window sums.
    Fixed,
    /// f32 (`r32float` … `rgba32float`): window sums lose precision with the magnitude of the
    /// corners.
    Float,
}

impl SatVariant {
    /// The table's texel format for a representation of `channels` channels (1, 2, or 4 for
    /// 3 or 4): `r32uint`, `rg32uint`, `rgba32uint` for fixed point, the `*32float` formats for
    /// f32 sums.
    pub fn format(self, channels: u32) -> wgpu::TextureFormat {
        use wgpu::TextureFormat as T;
        match (self, channels) {
            (Self::Fixed, 1) => T::R32Uint,
            (Self::Fixed, 2) => T::Rg32Uint,
            (Self::Fixed, _) => T::Rgba32Uint,
            (Self::Float, 1) => T::R32Float,
            (Self::Float, 2) => T::Rg32Float,
            (Self::Float, _) => T::Rgba32Float,
        }
    }
}
