//! Wall-clock timing of the benchmark's kernels (`bench::CASES`), each next to a copy of its
//! output texture in the same format, for devices whose per-pass timestamps cannot be trusted
//! (lavapipe's read near zero after the first pass of an encoder).
//!
//! `cargo run --release --example kernel_wall -- [--sizes 1024,2048] [--repeat 5] [NAME…]`
//! times every case whose name contains one of the NAMEs (all cases without any): the median
//! over `repeat` runs (after two warm-up runs) of record + submit + wait, and the same for a
//! compute kernel that copies the case's output texture (`textureLoad` → `textureStore`, the
//! same format). `× copy` is the copy's time over the case's time: the share of the copy's
//! speed the case reaches. Times include recording, a few hundred microseconds at most.
//! `--min` reports the fastest run instead of the median (for A/B trials on a busy machine);
//! `--cpu` the CPU time of all the process's threads instead of the wall clock (Linux, from
//! `/proc/self/task/*/schedstat`: on a software driver, the work done, whatever else shares
//! the cores).
//! With `--passes`, each pass's share too: the plan cut after each of its steps is timed, and
//! each pass is the difference to the cut before it.
//! `--exact` picks the cases named exactly by a NAME (`vsm_blur r4` without `vsm_blur r4 f16
//! (packed)`); `--no-copy` skips the copies (for `benches/instructions.sh`, which counts the
//! instructions a software driver runs: with it, every compute kernel run is the case's).

use std::time::Instant;

use shadowgraph::low_level::bench::{BenchCase, random_imports};
use shadowgraph::low_level::exec::{ComputeKernel, Executor, wgsl_storage_format};
use shadowgraph::low_level::gpu::{Gpu, submit_and_wait};
use shadowgraph::low_level::graph;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let mut sizes = vec![1024u32, 2048];
    let mut repeat = 5u32;
    let mut names = Vec::new();
    let mut passes = false;
    let mut exact = false;
    let mut copies = true;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--sizes" => {
                let list = args.next().ok_or("--sizes needs a list")?;
                sizes = list
                    .split(',')
                    .map(|s| s.trim().parse().map_err(|e| format!("--sizes `{s}`: {e}")))
                    .collect::<Result<_, _>>()?;
            }
            "--repeat" => {
                let r = args.next().ok_or("--repeat needs a number")?;
                repeat = r.parse().map_err(|e| format!("--repeat `{r}`: {e}"))?;
            }
            "--passes" => passes = true,
            "--exact" => exact = true,
            "--no-copy" => copies = false,
            "--min" => MIN.store(true, std::sync::atomic::Ordering::Relaxed),
            "--cpu" => CPU.store(true, std::sync::atomic::Ordering::Relaxed),
            flag if flag.starts_with('-') => {
                return Err(format!(
                    "unknown option `{flag}` (options: --sizes, --repeat, --passes, --min, --cpu, --exact, --no-copy)"
                ));
            }
            _ => names.push(a),
        }
    }
    // The bench's own checks: a case filter that names nothing or holds an empty entry, a size
    // of 0 or past the device, `--repeat 0`, a case past the memory budget.
    let mut cases =
        shadowgraph::low_level::bench::select_cases(&names).map_err(|e| e.to_string())?;
    if exact {
        cases.retain(|c| names.iter().any(|n| n == c.name));
        if cases.is_empty() {
            return Err(format!("--exact: no case is named {}", names.join(" or ")));
        }
    }
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    shadowgraph::low_level::bench::check_args(&gpu.device, &sizes, repeat)
        .map_err(|e| e.to_string())?;
    let budget = shadowgraph::low_level::limits::memory_budget().map_err(|e| e.to_string())?;
    shadowgraph::low_level::bench::check_memory(&cases, &sizes, budget)
        .map_err(|e| e.to_string())?;
    println!(
        "wall clock on {}; median of {repeat} after 2 warm-up runs",
        gpu.describe()
    );
    println!(
        "{:>6}  {:<24} {:>10} {:>10} {:>8} {:>10}",
        "size", "kernel", "ms", "copy ms", "x copy", "B/texel"
    );
    let mut exec = Executor::new();
    for &n in &sizes {
        for &case in &cases {
            let (ms, copy_ms, format) = time_case(&gpu, &mut exec, case, n, repeat, copies)?;
            if passes {
                for (name, ms) in time_passes(&gpu, &mut exec, case, n, repeat)? {
                    println!("{:>6}    {:<22} {:>10.2}", n, name, ms);
                }
            }
            let built = (case.build)(n);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            let plan = shadowgraph::low_level::graph::plan(&built.graph, &outputs)
                .map_err(|e| e.to_string())?;
            let bytes = shadowgraph::low_level::bench::plan_bytes(&plan)
                .map_err(|e| e.to_string())?
                / (f64::from(n) * f64::from(n));
            println!(
                "{:>6}  {:<24} {:>10.2} {:>10.2} {:>8.2} {:>10.1}   ({format:?})",
                n,
                case.name,
                ms,
                copy_ms,
                copy_ms / ms,
                bytes
            );
        }
    }
    Ok(())
}

/// Whether to time by the threads' CPU time (`--cpu`).
static CPU: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Nanoseconds all threads of this process have run, from `/proc/self/task/*/schedstat`.
fn cpu_ns() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return f64::NAN;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .sum()
}

/// Milliseconds since `start` (wall clock, or CPU time with `--cpu`).
fn elapsed_ms(wall: Instant, cpu: f64) -> f64 {
    if CPU.load(std::sync::atomic::Ordering::Relaxed) {
        (cpu_ns() - cpu) * 1e-6
    } else {
        wall.elapsed().as_secs_f64() * 1e3
    }
}

/// Whether to report the fastest run rather than the median (`--min`).
static MIN: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if MIN.load(std::sync::atomic::Ordering::Relaxed) {
        return v[0];
    }
    v[v.len() / 2]
}

fn time_runs(gpu: &Gpu, repeat: u32, mut record: impl FnMut(&mut wgpu::CommandEncoder)) -> f64 {
    let mut times = Vec::new();
    for run in 0..repeat + 2 {
        let (t0, c0) = (Instant::now(), cpu_ns());
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        record(&mut enc);
        submit_and_wait(&gpu.device, &gpu.queue, enc, "wall").expect("submit");
        if run >= 2 {
            times.push(elapsed_ms(t0, c0));
        }
    }
    median(times)
}

fn time_case(
    gpu: &Gpu,
    exec: &mut Executor,
    case: &BenchCase,
    n: u32,
    repeat: u32,
    copy: bool,
) -> Result<(f64, f64, wgpu::TextureFormat), String> {
    let built = (case.build)(n);
    let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
    let plan = graph::plan(&built.graph, &outputs).map_err(|e| e.to_string())?;
    exec.prepare(&gpu.device, &plan)
        .map_err(|e| e.to_string())?;
    let imports = random_imports(&gpu.device, &gpu.queue, &plan).map_err(|e| e.to_string())?;
    let mut out = None;
    let ms = time_runs(gpu, repeat, |enc| {
        let o = exec
            .record(&gpu.device, enc, &plan, &imports, None)
            .expect("record");
        out = Some(o.textures[&built.outputs[0]].clone());
    });
    let out = out.ok_or("no run")?;
    let copy_ms = if copy {
        time_copy(gpu, &out, repeat)?
    } else {
        f64::NAN
    };
    Ok((ms, copy_ms, out.format()))
}

/// Each step's wall time: the plan cut after the step, less the plan cut before it.
fn time_passes(
    gpu: &Gpu,
    exec: &mut Executor,
    case: &BenchCase,
    n: u32,
    repeat: u32,
) -> Result<Vec<(String, f64)>, String> {
    let built = (case.build)(n);
    let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
    let plan = graph::plan(&built.graph, &outputs).map_err(|e| e.to_string())?;
    let imports = random_imports(&gpu.device, &gpu.queue, &plan).map_err(|e| e.to_string())?;
    let mut before = 0.0;
    let mut out = Vec::new();
    for k in 1..=plan.steps.len() {
        let mut cut = plan.clone();
        cut.steps.truncate(k);
        let ms = time_runs(gpu, repeat, |enc| {
            exec.record(&gpu.device, enc, &cut, &imports, None)
                .expect("record");
        });
        out.push((plan.steps[k - 1].node.name.clone(), ms - before));
        before = ms;
    }
    Ok(out)
}

/// Wall time of a compute kernel copying `src` into a texture of the same format and size.
fn time_copy(gpu: &Gpu, src: &wgpu::Texture, repeat: u32) -> Result<f64, String> {
    let f = src.format();
    let storage = wgsl_storage_format(f).map_err(|e| e.to_string())?;
    let ty = if matches!(
        f,
        wgpu::TextureFormat::R32Uint
            | wgpu::TextureFormat::Rg32Uint
            | wgpu::TextureFormat::Rgba32Uint
    ) {
        "u32"
    } else {
        "f32"
    };
    let wgsl = format!(
        "@group(0) @binding(0) var src: texture_2d<{ty}>;
@group(0) @binding(1) var dst: texture_storage_2d<{storage}, write>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if all(id.xy < textureDimensions(src)) {{
        textureStore(dst, id.xy, textureLoad(src, id.xy, 0));
    }}
}}
"
    );
    let k = ComputeKernel::new(&gpu.device, "wall_copy", &wgsl).map_err(|e| e.to_string())?;
    let dst = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: src.size(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: f,
        usage: wgpu::TextureUsages::STORAGE_BINDING,
        view_formats: &[],
    });
    let (sv, dv) = (
        src.create_view(&Default::default()),
        dst.create_view(&Default::default()),
    );
    let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &k.layouts[0],
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&sv),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&dv),
            },
        ],
    });
    let g = k.groups_for(src.width(), src.height());
    Ok(time_runs(gpu, repeat, |enc| {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&k.pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(g[0], g[1], 1);
    }))
}
