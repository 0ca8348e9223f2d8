//! The mip chain's redesign after AMD FidelityFX SPD (`kernels/shared/mips_spd.wgsl`, what the
//! `redesign` kernel layout compiles for `mips` and `mips_log`) against the shipped chain
//! (`kernels/shared/mip_chain.wgsl`, the `gpu` layout): every level bit for bit. Each texel of
//! both is the same `quad` (or general reduction) of the same four values in the same order, so
//! any difference is a texel read, kept or stored wrongly. `tests/prefilter/` checks both
//! layouts against the f64 chain.

mod common;

use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

use rand::Rng;
use shadowgraph::Filter;
use shadowgraph::low_level::cpu::Texels;
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::filter::{BlurMode, add_filter};
use shadowgraph::low_level::gpu::{Gpu, read_resource_texture, submit_and_wait};
use shadowgraph::low_level::graph::{Graph, plan};
use shadowgraph::low_level::kernels::Replacements;

/// Every level of the mip chain of the `w × h` map `data` (of `format`), run in `layout`; with
/// `poisoned`, the kernels' workgroup memory filled with NaN first (`tests/common/poison.rs`).
fn chain(
    g: &Gpu,
    (layout, poisoned): (KernelLayout, bool),
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    data: &[u8],
    mode: BlurMode,
) -> Vec<Texels> {
    let mut graph = Graph::default();
    graph.import("in", format, w, h, Some(0));
    let filter = Filter::Mips {
        width: 1.0,
        max_anisotropy: 0,
    };
    let out = add_filter(&mut graph, 0, "in", &filter, mode);
    let plan = plan(&graph, &[out.as_str()]).expect("plan");
    let input = common::upload(&g.device, &g.queue, "test.input", (w, h), format, data);
    let mut exec = Executor::new();
    exec.kernels.set_layout(layout);
    if poisoned {
        static POISONED: OnceLock<Arc<Replacements>> = OnceLock::new();
        let kernels = POISONED.get_or_init(|| Arc::new(common::poison::poisoned_kernels()));
        assert!(kernels.contains_key("mips_spd") && kernels.contains_key("mips_spd_log"));
        exec.kernels.set_replacements(kernels.clone());
    }
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let outputs = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "mips").unwrap();
    let t = &outputs.textures[out.as_str()];
    let stored = plan.resource(&out).expect("planned").resource.format;
    (0..t.mip_level_count())
        .map(|level| {
            let (c, v) = read_resource_texture(&g.device, &g.queue, t, level, stored).unwrap();
            let (lw, lh) = ((w >> level).max(1), (h >> level).max(1));
            Texels::from_f32(lw as usize, lh as usize, c, &v)
        })
        .collect()
}

/// The redesign's chain equals the shipped one's, level by level, bit for bit, and its own
/// with its workgroup memory poisoned.
fn same_chains(g: &Gpu, size: (u32, u32), format: wgpu::TextureFormat, mode: BlurMode, seed: u64) {
    let mut rng = common::rng(seed);
    let n = (size.0 * size.1) as usize;
    // Log mode holds logarithms (ESM's c·z with c = 80); linear mode depths or moments.
    let scale = if mode.is_log() { 80.0 } else { 1.0 };
    let mut f32s = |n: usize| -> Vec<f32> { (0..n).map(|_| scale * rng.random::<f32>()).collect() };
    let data: Vec<u8> = match format {
        wgpu::TextureFormat::R32Float => bytemuck::cast_slice(&f32s(n)).to_vec(),
        wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice(&f32s(4 * n)).to_vec(),
        // Positive normal halves in [2⁻¹⁴, 2): exponent 1 … 14, any mantissa.
        wgpu::TextureFormat::Rgba16Float => (0..4 * n)
            .flat_map(|_| {
                (rng.random_range(1u16..15) << 10 | rng.random_range(0u16..1024)).to_le_bytes()
            })
            .collect(),
        other => panic!("no random texels of {other:?}"),
    };
    let shipped = chain(g, (KernelLayout::Gpu, false), size, format, &data, mode);
    let redesign = chain(
        g,
        (KernelLayout::Redesign, false),
        size,
        format,
        &data,
        mode,
    );
    // Every entry of its workgroup memory written before it is read: poisoned, the same bits.
    let poisoned = chain(g, (KernelLayout::Redesign, true), size, format, &data, mode);
    assert_eq!(shipped.len(), redesign.len(), "{size:?}: levels");
    assert!(
        shipped[0].data.iter().any(|&v| v != 0.0),
        "{size:?}: all zeros"
    );
    for (level, (a, b)) in shipped.iter().zip(&redesign).enumerate() {
        let what = format!("{size:?} {format:?} {mode:?} level {level}");
        assert!(a.data.iter().all(|v| v.is_finite()), "{what}: not finite");
        common::assert_same_bits(&what, a, b);
        common::assert_same_bits(&format!("{what}, poisoned"), b, &poisoned[level]);
    }
}

/// Sizes through every path of a dispatch: one tile exactly; tiles cut by the edge (not
/// multiples of 64 at any level); odd sides (the general reduction, its own dispatch), a side
/// of one texel kept while the other halves (in level s + 1 and deeper in a dispatch); six
/// levels of several workgroups, then the tail's dispatch; a 1×1 map.
#[test]
fn the_redesign_gives_the_shipped_chain_bit_for_bit() {
    let g = common::gpu();
    let r32 = wgpu::TextureFormat::R32Float;
    for (k, (w, h, mode)) in [
        (64u32, 64u32, BlurMode::Linear),
        (300, 200, BlurMode::Linear),
        (300, 200, BlurMode::LogSumExp),
        (65, 130, BlurMode::Linear),
        (1000, 37, BlurMode::Linear),
        (2, 256, BlurMode::Linear),
        (256, 4, BlurMode::LogSumExp),
        (1, 57, BlurMode::Linear),
        (1, 1, BlurMode::Linear),
        (130, 7, BlurMode::LogSumExp),
        (640, 384, BlurMode::Linear),
        (512, 512, BlurMode::LogSumExp),
    ]
    .into_iter()
    .enumerate()
    {
        same_chains(&g, (w, h), r32, mode, 90 + k as u64);
    }
    // Four channels, each its own values (a channel swapped or dropped shows).
    same_chains(
        &g,
        (192, 320),
        wgpu::TextureFormat::Rgba32Float,
        BlurMode::Linear,
        80,
    );
    same_chains(
        &g,
        (200, 75),
        wgpu::TextureFormat::Rgba16Float,
        BlurMode::Linear,
        81,
    );
}

/// The redesign is a file of its own, compiled for the shipped kernels in the `redesign`
/// layout only: `gpu` and `cpu` keep the shipped kernels.
#[test]
fn only_the_redesign_layout_compiles_the_spd_chain() {
    for (shipped, redesign) in [("mips", "mips_spd"), ("mips_log", "mips_spd_log")] {
        assert_eq!(KernelLayout::Redesign.kernel_source(shipped), redesign);
        assert_eq!(KernelLayout::Gpu.kernel_source(shipped), shipped);
        assert_eq!(KernelLayout::Cpu.kernel_source(shipped), shipped);
    }
    let g = common::gpu();
    let mut exec = Executor::new();
    exec.kernels.set_layout(KernelLayout::Redesign);
    let k = exec.kernels.get(&g.device, "mips").expect("compiles");
    assert_eq!(k.name, "mips_spd");
    assert_eq!(k.reflection.workgroup_size, Some([16, 16, 1]));
    exec.kernels.set_layout(KernelLayout::Gpu);
    let k = exec.kernels.get(&g.device, "mips").expect("compiles");
    assert_eq!(k.name, "mips");
    assert_eq!(k.reflection.workgroup_size, Some([8, 8, 1]));
}
