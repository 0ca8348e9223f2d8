//! `shadowgraph`: the command-line tool. Each subcommand calls one library function.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

use shadowgraph::low_level::cli;
use shadowgraph::low_level::gpu::Gpu;

#[derive(Parser)]
#[command(
    name = "shadowgraph",
    version,
    about = "Shadow-map prefiltering on the GPU"
)]
struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to PNG.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long, default_value = "out.png")]
        output: PathBuf,
        /// Also write position, normal and per-light visibility as 32-bit float OpenEXR here.
        #[arg(long)]
        aux: Option<PathBuf>,
        /// Print GPU time per pass (timestamps between passes) and each frame's wall time.
        #[arg(long)]
        timings: bool,
        /// Frames to render (timings are medians over them), 1 to 1000.
        #[arg(long, default_value_t = 1, value_parser = repeat_range())]
        repeat: u32,
    },
    /// Print the kernels a scene will run (per light), its resources and peak memory.
    Plan {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Print Graphviz instead of text.
        #[arg(long)]
        dot: bool,
    },
    /// Write every resource of the executed plan: OpenEXR per texture and mip level, a PNG
    /// preview per channel, and manifest.json with provenance and per-channel statistics.
    Dump {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Dump only this resource (e.g. `light0.linear`).
        #[arg(long)]
        only: Option<String>,
    },
    /// Print the adapter, its backend, and the features and limits that matter.
    Info,
    /// Time kernels by GPU timestamps against a texture copy of their output's format (and the
    /// texture copies against a buffer copy), bytes from the plan's cost model.
    Bench {
        /// Square map sizes (default 512,1024,2048,4096; not with `--lookup`, whose map is
        /// `--map`).
        #[arg(long, value_delimiter = ',')]
        sizes: Option<Vec<u32>>,
        /// Timed repetitions per kernel and size (the median is reported), 1 to 1000.
        #[arg(long, default_value_t = 10, value_parser = repeat_range())]
        repeat: u32,
        /// Instead: the shading pass's cost as the filter widens, PCF against summed-area
        /// tables, at these odd widths (texels).
        #[arg(long, value_delimiter = ',', num_args = 0.., default_missing_value = "3,5,9,17,33,65")]
        lookup: Option<Vec<u32>>,
        /// With `--lookup`: the light sizes (world units) at which PCSS and the soft techniques
        /// are compared on `scenes/techniques/cssm.toml`.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "0.25,0.5,1,2",
            requires = "lookup",
            allow_negative_numbers = true
        )]
        light_sizes: Vec<f32>,
        /// With `--lookup`: shade at this image size, WIDTHxHEIGHT (default: the scenes' own,
        /// 400x300 and 200x150, small for a CPU driver; a GPU wants 1920x1080).
        #[arg(long, value_parser = parse_size, requires = "lookup")]
        image: Option<(u32, u32)>,
        /// With `--lookup`: render the light's shadow map at this size, texels a side
        /// (default: the scenes' own, 512).
        #[arg(long, value_parser = clap::value_parser!(u32).range(16..=32768), requires = "lookup")]
        map: Option<u32>,
        /// Time only the kernels whose name contains one of these (e.g. `sat,mips`); the
        /// texture copies, their yardsticks, always run. With `--lookup`: only these soft
        /// configurations (e.g. `cssm`), `hard` and PCSS 16+32, their yardstick.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// What the kernels' imported textures hold: `random` values, a `smooth` field or a
        /// `constant` (a GPU that stores textures compressed moves smooth and constant data
        /// faster; the texture copies read the same kind).
        #[arg(long, default_value = "random", value_parser = parse_inputs, conflicts_with = "lookup")]
        inputs: shadowgraph::low_level::bench::Inputs,
        /// Also print each dispatch's median time under a kernel of several.
        #[arg(long, conflicts_with = "lookup")]
        passes: bool,
        /// Time each kernel in each of these variants in turn (`gpu`, `cpu`: the kernels'
        /// two, today the summed-area tables' pass 3 and the fused tile blurs; see
        /// SHADOWGRAPH_KERNEL_LAYOUT), rows
        /// named `<kernel> [gpu]`, … (default: the device's variant alone).
        #[arg(long, value_delimiter = ',', value_parser = shadowgraph::low_level::exec::KernelLayout::parse, conflicts_with = "lookup")]
        layouts: Vec<shadowgraph::low_level::exec::KernelLayout>,
        /// Time each kernel compiled from each of these folders of `.wgsl` replacements in
        /// turn (as SHADOWGRAPH_KERNEL_DIR reads one; `shipped`: the embedded kernels;
        /// `zeroed`: the embedded kernels with their workgroup memory zeroed first, wgpu's
        /// default; `unchecked`: the embedded kernels' shader modules created without wgpu's
        /// runtime checks), in one process, rows named `<kernel> [<folder's name>]`: kernel
        /// variants side by side.
        #[arg(long, value_delimiter = ',', conflicts_with_all = ["lookup", "layouts"])]
        kernel_dirs: Vec<PathBuf>,
    },
    /// Sweep techniques and their accuracy knobs, time each on the GPU and measure its error
    /// against ground truth: report.html/.md/.csv/.json, pareto{,_penumbra,_flip}.svg, grid.png
    /// (+ grid.txt).
    Evaluate {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Techniques to sweep (default: all), e.g. `hard,pcf,vsm`.
        #[arg(long, value_delimiter = ',')]
        techniques: Option<Vec<String>>,
        /// Output folder (created if missing).
        #[arg(long, default_value = "evaluation")]
        out: PathBuf,
        /// A tiny sweep that runs in seconds (one size, one width, K = 16, small image).
        #[arg(long)]
        quick: bool,
        /// Shadow-map sizes (default 512,1024,2048,4096; quick: 512).
        #[arg(long, value_delimiter = ',')]
        sizes: Option<Vec<u32>>,
        /// Emitter samples K of the area-light truth (default 256; quick: 16).
        #[arg(long)]
        k: Option<u32>,
        /// Shadow-map side of the truth's samples (default max(2048, 2 × the light's map)).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        truth_resolution: Option<u32>,
        /// Timed frames per configuration, 1 to 1000: rounds of the interleaved time protocol
        /// (median and quartiles reported; default 5, quick 3).
        #[arg(long, value_parser = repeat_range())]
        repeat: Option<u32>,
        /// Evaluate at this image size, WIDTHxHEIGHT (default: 1920x1080 on a GPU, the scene's
        /// own size on a CPU driver; quick: at most 160 wide).
        #[arg(long, value_parser = parse_size)]
        image: Option<(u32, u32)>,
        /// Time budget per light of the report's verdict, ms (default: 1 on a GPU, the median
        /// configuration's on a CPU driver).
        #[arg(long, value_parser = parse_budget, allow_negative_numbers = true)]
        budget: Option<f64>,
        /// How often every light's map is redrawn: `every` (each frame), a period K in frames,
        /// or `static` (default: each light's `update`; quick: that, then static). Frames are
        /// timed over a whole period. A list times each rate past the first again, its report
        /// in DIR/update-<rate>/.
        #[arg(long, value_parser = parse_update, allow_negative_numbers = true, value_delimiter = ',')]
        update: Option<Vec<shadowgraph::low_level::scene::UpdateRate>>,
        /// Run every MSM configuration at each of these moment biases (default: the storage's).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
        moment_bias: Option<Vec<f32>>,
        /// Image sizes of the crossover against PCSS, WxH,WxH,…: the shading is fitted at all
        /// but the last, the last checks the fit (default 480x360,1280x720,960x540 on a CPU
        /// driver, 1280x720,3840x2160,1920x1080 on a GPU; quick: 80x60,160x120,120x90).
        #[arg(long, value_parser = parse_size, value_delimiter = ',')]
        crossover_sizes: Option<Vec<(u32, u32)>>,
    },
    /// Compare two evaluation reports of one scene: whether each Pareto front has the same
    /// techniques and each front configuration's time lies within the other run's range; exits
    /// non-zero when a front differs.
    Compare {
        /// The first run's `report.json`.
        first: PathBuf,
        /// The second run's `report.json`.
        second: PathBuf,
    },
    /// Run the numerical-stability suite: each hard input through the real kernels against its
    /// f64 reference and stated bound; exits non-zero when a check fails.
    Stability {
        /// Summed-area tables at 8192² (256 MiB each) instead of 2048².
        #[arg(long)]
        large: bool,
    },
}

/// `bench --inputs`: one of `Inputs::NAMES`.
fn parse_inputs(name: &str) -> Result<shadowgraph::low_level::bench::Inputs, String> {
    shadowgraph::low_level::bench::Inputs::parse(name).map_err(|e| e.to_string())
}

/// `--repeat` of every command: 1 to `render::MAX_REPEAT` frames (each keeps a row of timings).
fn repeat_range() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=i64::from(shadowgraph::low_level::render::MAX_REPEAT))
}

/// `evaluate --budget`: a positive, finite number of milliseconds.
fn parse_budget(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("`{s}`: a budget is a positive number of milliseconds"))
}

/// `evaluate --update`: `every`, a period of at least 1 frame (1 is every frame) up to
/// `scene::MAX_UPDATE_PERIOD`, or `static`.
fn parse_update(s: &str) -> Result<shadowgraph::low_level::scene::UpdateRate, String> {
    use shadowgraph::low_level::scene::{MAX_UPDATE_PERIOD, UpdateRate};
    match s.trim() {
        "every" => Ok(UpdateRate::EveryFrame),
        "static" => Ok(UpdateRate::Static),
        k => match k.parse::<i64>() {
            Ok(1) => Ok(UpdateRate::EveryFrame),
            Ok(k) if (2..=MAX_UPDATE_PERIOD).contains(&k) => Ok(UpdateRate::Every(k as u32)),
            _ => Err(format!(
                "`{s}`: expected `every`, `static` or a period of 1 to {MAX_UPDATE_PERIOD} frames"
            )),
        },
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("`{s}`: expected WIDTHxHEIGHT, e.g. 160x120"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("`{s}`: sides must be positive integers"))
    };
    Ok((n(w)?, n(h)?))
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = match Args::try_parse() {
        Ok(args) => args,
        // A usage error is one line and status 1, as every other error (`--help` prints all).
        Err(e)
            if e.use_stderr()
                && e.kind() != clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            // clap's message is its first paragraph (the error, then what it names on indented
            // lines, e.g. a missing argument), before the usage: joined into one line.
            let text = e.to_string();
            let first: Vec<&str> = text
                .lines()
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect();
            if first.is_empty() {
                eprintln!("error: invalid arguments");
            } else {
                eprintln!("{}", first.join(" "));
            }
            std::process::exit(1);
        }
        Err(e) => e.exit(),
    };
    if let Err(e) = run(args) {
        eprintln!("error: {}", one_line(&e));
        std::process::exit(1);
    }
}

/// `e` and its causes joined by ": ", each cause left out where the text so far already says
/// it (`Error::Exec`'s "executor: {0}" names the error that is also its source).
fn one_line(e: &anyhow::Error) -> String {
    let mut s = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if s.contains(&text) {
            continue;
        }
        if !s.is_empty() {
            s.push_str(": ");
        }
        s.push_str(&text);
    }
    s
}

fn run(args: Args) -> Result<()> {
    match args.command {
        Command::Render {
            scene,
            output,
            aux,
            timings,
            repeat,
        } => {
            let gpu = Gpu::new()?;
            let report = cli::render(&gpu, &scene, &output, aux.as_deref(), timings, repeat)?;
            print!("{report}");
        }
        Command::Plan { scene, dot } => print!("{}", cli::plan(&scene, dot)?),
        Command::Dump { scene, out, only } => {
            let gpu = Gpu::new()?;
            print!(
                "{}",
                shadowgraph::low_level::dump::dump(&gpu, &scene, &out, only.as_deref())?
            );
        }
        Command::Info => print!("{}", Gpu::new()?.info_report()),
        Command::Evaluate {
            scene,
            techniques,
            out,
            quick,
            sizes,
            k,
            truth_resolution,
            repeat,
            image,
            budget,
            update,
            moment_bias,
            crossover_sizes,
        } => {
            let opts = shadowgraph::low_level::evaluate::EvaluateOptions {
                techniques,
                quick,
                sizes,
                samples: k,
                truth_resolution,
                repeat: repeat.unwrap_or(if quick { 3 } else { 5 }),
                image,
                moment_biases: moment_bias,
                budget_ms: budget,
                image_default: false,
                update: update.as_ref().and_then(|u| u.first().copied()),
                // Past the first rate, each a further operating point; --quick alone times a
                // static light too.
                more_updates: match &update {
                    Some(u) => u.iter().skip(1).copied().collect(),
                    None if quick => vec![shadowgraph::low_level::scene::UpdateRate::Static],
                    None => Vec::new(),
                },
                crossover_sizes,
            };
            let gpu = Gpu::new()?;
            print!(
                "{}",
                shadowgraph::low_level::evaluate::run(&gpu, &scene, &out, &opts)?
            );
        }
        Command::Bench {
            sizes,
            repeat,
            lookup,
            light_sizes,
            image,
            map,
            only,
            inputs,
            passes,
            layouts,
            kernel_dirs,
        } => {
            if lookup.is_some() {
                // Refused before the first table, not after it. (Not a clap conflict: one
                // would lift `--map`'s and `--image`'s requirement of `--lookup`.)
                if sizes.is_some() {
                    anyhow::bail!(
                        "--sizes is the kernel bench's; `--lookup` renders its map at `--map`"
                    );
                }
                shadowgraph::low_level::bench::check_soft_args(&light_sizes, repeat, &only)?;
            }
            let sizes = sizes.unwrap_or_else(|| vec![512, 1024, 2048, 4096]);
            let gpu = Gpu::new()?;
            match lookup {
                Some(widths) => {
                    let rows = shadowgraph::low_level::bench::lookup_cost(
                        &gpu, &widths, repeat, image, map,
                    )?;
                    let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
                    print!(
                        "{}",
                        shadowgraph::low_level::bench::format_lookup_table(
                            &gpu.describe(),
                            cpu,
                            repeat,
                            &rows
                        )
                    );
                    let soft = shadowgraph::low_level::bench::soft_cost(
                        &gpu,
                        &light_sizes,
                        repeat,
                        image,
                        map,
                        &only,
                    )?;
                    print!(
                        "\n{}",
                        shadowgraph::low_level::bench::format_soft_table(
                            &gpu.describe(),
                            cpu,
                            repeat,
                            &light_sizes,
                            &soft
                        )
                    );
                }
                None => {
                    print!(
                        "{}",
                        shadowgraph::low_level::bench::run(
                            &gpu,
                            &sizes,
                            repeat,
                            &only,
                            inputs,
                            passes,
                            &layouts,
                            &kernel_dirs
                        )?
                    )
                }
            }
        }
        Command::Compare { first, second } => {
            use shadowgraph::low_level::evaluate::agreement;
            let a = agreement::read_report(&first)?;
            let b = agreement::read_report(&second)?;
            let comparison = agreement::compare(&a, &b)?;
            print!("{}", comparison.text());
            if !comparison.agrees() {
                anyhow::bail!("the two runs' fronts differ");
            }
        }
        Command::Stability { large } => {
            let gpu = Gpu::new()?;
            let opts = shadowgraph::low_level::stability::StabilityOptions { large };
            let report = shadowgraph::low_level::stability::run(&gpu, &opts, &mut |case, name| {
                eprintln!("stability: case {case}/7, {name}");
            })?;
            print!("{}", report.table());
            let failed = report.failures().len();
            if failed > 0 {
                anyhow::bail!("{failed} stability check(s) failed");
            }
        }
    }
    Ok(())
}
