// Two f16 values a texel in one r32uint word (`graph::PACKED_F16X2`): how a representation of
// one or two channels at f16 precision is stored in 4 bytes, since `rg16float` is no core
// WebGPU storage format. Kernels written for float textures are compiled for packed ones by
// the executor (`exec::packed`), which routes their stores through `pack_f16x2` and their loads
// through `unpack_f16x2`; the shading reads packed maps through shared/sampling_packed.
// The value is rounded to f16 once, here, as a store to an rgba16float texture would; channels
// past the second are dropped, and read back as a two-channel float texture reads (0, 1).

fn pack_f16x2(v: vec4<f32>) -> vec4<u32> {
    return vec4<u32>(pack2x16float(v.xy), 0u, 0u, 1u);
}

fn unpack_f16x2(w: vec4<u32>) -> vec4<f32> {
    return vec4<f32>(unpack2x16float(w.x), 0.0, 1.0);
}
