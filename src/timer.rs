//! GPU timing by timestamps at the boundaries between passes.
//!
//! Each timed span (a pass, a graph node, a group of passes) begins at a *mark* and ends at the
//! next one: consecutive spans share their boundary, so their sum is the time from the first
//! mark to the last. A mark is two timestamp writes on the encoder, between passes: the first
//! is the boundary, the second is written only to make it true on software drivers, which also
//! wait for the first's stamp (below).
//!
//! Why two: Mesa's lavapipe (llvmpipe) does not stamp a timestamp when the command buffer
//! reaches it. `vkCmdWriteTimestamp` (at any stage but the top of the pipe) flushes the
//! rasterizer's current scene and bins the query into the *next* scene; the rasterizer threads
//! write the time when that scene is flushed in turn (`lp_setup_end_query`,
//! `lp_rast_end_query`). Compute dispatches do not go through scenes: llvmpipe runs them at once
//! on its compute threads. So a timestamp written before a compute pass was stamped at the next
//! flush, *after* the dispatch, unless a barrier happened to flush in between; a pass's own
//! begin/end pair read the gap between two flushes, near zero for every compute pass after the
//! first (a blur of 40–270 ms per frame read 0.1 ms). The second write of a mark is such a
//! flush: it hands the first to the rasterizer threads at the boundary. On a GPU it is one
//! more query write between passes (nanoseconds), and it is the same code path that the
//! lavapipe test checks (`tests/timing.rs`).
//!
//! Handing it over is not stamping it: the rasterizer threads run asynchronously and compete
//! for the cores with the compute threads of the dispatch that follows, so on a CPU driver a
//! boundary could still be stamped after most of the next pass (a 3.5 ms copy read 0.1 ms in
//! 8 of its 12 runs, each run's wall clock 3.4–3.8 ms; `tests/timing.rs` checks the bench
//! run by run against the wall clock). So on a CPU device (an adapter of
//! [`wgpu::DeviceType::Cpu`]) each mark also resolves its boundary query into a scratch buffer:
//! lavapipe copies a query result with Vulkan's wait flag, which waits for the scene holding
//! the timestamp, so the next pass starts only after its boundary is stamped. A GPU writes its
//! timestamps in order and skips that copy, which would add a small command to every span.
//!
//! Writing on the encoder needs `TIMESTAMP_QUERY_INSIDE_ENCODERS` (Vulkan, DX12 and Metal on
//! Apple GPUs offer it); a device without it cannot time. Timestamps inside a pass's descriptor
//! (`timestamp_writes`) cannot be made true this way: nothing can be written between a pass's
//! begin timestamp and its first dispatch without `TIMESTAMP_QUERY_INSIDE_PASSES`, and an empty
//! marker pass resolves to zero on Metal.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::error::{Error, Result};
use crate::gpu_objects;

/// Least wall time of untimed work before a GPU is timed, ms. A GPU left idle (while the
/// host fills the next case's textures, or measures the last frame's error) drops its clocks,
/// and runs of a few milliseconds right after read up to 4× slow: without it, two thirds of an
/// H200's busy samples during the kernel benchmark ran below 1000 MHz of its 1980, and the
/// kernels at 4096² and 8192² read 1.4-4.6× their warm times (`benches/RESULTS.md`,
/// 2026-11-27). A CPU device has no such governor.
pub const GPU_WARMUP_MS: f64 = 300.0;

/// Most untimed runs on a GPU (a kernel of microseconds would otherwise make thousands).
pub const MAX_WARMUP_RUNS: u32 = 2000;

/// Whether another untimed run is due after `runs` of them over `elapsed_ms`: `least` runs
/// on any device, and on a GPU (`gpu`) until [`GPU_WARMUP_MS`] have passed (at most
/// [`MAX_WARMUP_RUNS`] runs). The benchmarks and the evaluation warm up with it.
pub fn keep_warming(runs: u32, least: u32, elapsed_ms: f64, gpu: bool) -> bool {
    runs < least || (gpu && runs < MAX_WARMUP_RUNS && elapsed_ms < GPU_WARMUP_MS)
}

/// Whether `device` is a GPU (not a CPU driver), whose clocks [`warm_up`] must raise.
pub fn is_gpu(device: &wgpu::Device) -> bool {
    device.adapter_info().device_type != wgpu::DeviceType::Cpu
}

/// Calls `run` (one untimed run) while [`keep_warming`] says so: `least` times on any device,
/// and on `device` if it is a GPU until [`GPU_WARMUP_MS`] have passed. Returns the runs made.
pub fn warm_up(
    device: &wgpu::Device,
    least: u32,
    mut run: impl FnMut() -> Result<()>,
) -> Result<u32> {
    let gpu = is_gpu(device);
    let start = std::time::Instant::now();
    let mut runs = 0;
    while keep_warming(runs, least, start.elapsed().as_secs_f64() * 1e3, gpu) {
        run()?;
        runs += 1;
    }
    Ok(runs)
}

/// The features [`GpuTimer`] needs.
pub const TIMER_FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

/// Readback buffers the resolved timestamps rotate through: a frame's are mapped after its
/// submission and read once the device is done with them, while the next frames resolve into
/// the others, so no frame waits for its timestamps (three: one being written, one in flight,
/// one being read).
const RING: usize = 3;

/// Where a readback buffer of the ring is.
mod slot {
    /// Free (nothing to read).
    pub const IDLE: u8 = 0;
    /// Holds a copy recorded into an encoder not yet known to be submitted.
    pub const RECORDED: u8 = 1;
    /// Mapping requested after the submission.
    pub const MAPPING: u8 = 2;
    /// Mapped: readable.
    pub const MAPPED: u8 = 3;
    /// The mapping failed (or was cancelled by reusing the slot).
    pub const FAILED: u8 = 4;
}

/// One readback buffer of the ring and the spans of the frame it holds.
struct Readback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    spans: Vec<(String, u32, u32)>,
    /// Frame number (order of [`GpuTimer::resolve`] calls).
    frame: u64,
}

impl Readback {
    /// Drops the frame the buffer holds, unread, and makes it free for the next copy. Only a
    /// buffer whose mapping was requested (pending: cancelled) or done is unmapped: one whose
    /// copy was only recorded, or whose mapping failed, is not mapped, and unmapping it is a
    /// validation error. The state is a new one, so that the callback of a cancelled or stale
    /// mapping, whenever it runs, finds nothing to change.
    fn take_back(&mut self) {
        let state = self.state.load(Ordering::Acquire);
        if state == slot::MAPPING || state == slot::MAPPED {
            self.buffer.unmap();
        }
        self.state = Arc::new(AtomicU8::new(slot::IDLE));
    }
}

/// Timestamps at pass boundaries, resolved into a ring of readback buffers and read back a
/// frame or more later without waiting ([`GpuTimer::collect`]), or waited for when asked
/// ([`GpuTimer::read`], [`GpuTimer::finish`]).
pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    ring: Vec<Readback>,
    /// Frames resolved so far; the next goes to `ring[frames % RING]`.
    frames: u64,
    /// Marks the query set holds (two queries each).
    capacity: u32,
    /// Marks written since the last [`GpuTimer::reset`].
    marks: u32,
    /// Closed spans: label, first mark, last mark.
    spans: Vec<(String, u32, u32)>,
    /// The span begun by the last mark, if any: label and its first mark.
    open: Option<(String, u32)>,
    period_ns: f64,
    /// On a CPU device: where each mark resolves its boundary, to wait for its stamp (see the
    /// module's documentation).
    wait_marks: Option<wgpu::Buffer>,
}

impl GpuTimer {
    /// A timer for up to `spans` spans per frame (any mix of shared and separate boundaries),
    /// or `None` when the device lacks [`TIMER_FEATURES`].
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, spans: u32) -> Option<Self> {
        if !device.features().contains(TIMER_FEATURES) || spans == 0 {
            return None;
        }
        // A span needs at most two marks of its own (begin, end).
        let capacity = 2 * spans;
        let bytes = u64::from(capacity) * 2 * 8;
        let ring = (0..RING)
            .map(|_| Readback {
                buffer: gpu_objects::buffer(
                    device,
                    &wgpu::BufferDescriptor {
                        label: Some("shadowgraph.timer.readback"),
                        size: bytes,
                        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                        mapped_at_creation: false,
                    },
                ),
                state: Arc::new(AtomicU8::new(slot::IDLE)),
                spans: Vec::new(),
                frame: 0,
            })
            .collect();
        Some(Self {
            query_set: gpu_objects::query_set(
                device,
                &wgpu::QuerySetDescriptor {
                    label: Some("shadowgraph.timer"),
                    ty: wgpu::QueryType::Timestamp,
                    count: capacity * 2,
                },
            ),
            resolve: gpu_objects::buffer(
                device,
                &wgpu::BufferDescriptor {
                    label: Some("shadowgraph.timer.resolve"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                },
            ),
            ring,
            frames: 0,
            capacity,
            marks: 0,
            spans: Vec::new(),
            open: None,
            period_ns: f64::from(queue.get_timestamp_period()),
            wait_marks: (device.adapter_info().device_type == wgpu::DeviceType::Cpu).then(|| {
                gpu_objects::buffer(
                    device,
                    &wgpu::BufferDescriptor {
                        label: Some("shadowgraph.timer.wait"),
                        size: 8,
                        usage: wgpu::BufferUsages::QUERY_RESOLVE,
                        mapped_at_creation: false,
                    },
                )
            }),
        })
    }
    /// The number of spans this timer can hold per frame.
    pub fn span_capacity(&self) -> u32 {
        self.capacity / 2
    }

    /// Forgets the spans of the last frame.
    pub fn reset(&mut self) {
        self.marks = 0;
        self.spans.clear();
        self.open = None;
    }

    /// Writes a mark: two timestamps, the first the boundary, the second the write that makes
    /// lavapipe hand the first to its rasterizer now, and on a CPU device the resolve that
    /// waits for the first's stamp (see the module's documentation). `None` when full.
    fn mark(&mut self, encoder: &mut wgpu::CommandEncoder) -> Option<u32> {
        if self.marks >= self.capacity {
            return None;
        }
        let m = self.marks;
        encoder.write_timestamp(&self.query_set, 2 * m);
        encoder.write_timestamp(&self.query_set, 2 * m + 1);
        if let Some(wait) = &self.wait_marks {
            encoder.resolve_query_set(&self.query_set, 2 * m..2 * m + 1, wait, 0);
        }
        self.marks += 1;
        Some(m)
    }

    /// Ends the open span (if any) and begins one named `label`: everything recorded into
    /// `encoder` from here to the next [`GpuTimer::begin`] or [`GpuTimer::end`] is its time.
    /// Call it between passes, never inside one.
    pub fn begin(&mut self, encoder: &mut wgpu::CommandEncoder, label: &str) {
        let Some(m) = self.mark(encoder) else {
            log::warn!("timer full: `{label}` is not timed");
            self.open = None;
            return;
        };
        if let Some((l, start)) = self.open.take() {
            self.spans.push((l, start, m));
        }
        self.open = Some((label.to_string(), m));
    }

    /// Ends the open span, if any.
    pub fn end(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let Some((label, start)) = self.open.take() else {
            return;
        };
        match self.mark(encoder) {
            Some(m) => self.spans.push((label, start, m)),
            None => log::warn!("timer full: `{label}` is not timed"),
        }
    }

    /// Ends the open span and records the query resolve and its copy into the next readback
    /// buffer of the ring; call after the last timed pass, before submitting. A buffer still
    /// holding an unread frame is taken back, whatever became of it (its copy recorded, its
    /// mapping requested or done): that frame's times are dropped.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.end(encoder);
        let n = 2 * self.marks;
        if n == 0 {
            return;
        }
        let frame = self.frames;
        self.frames += 1;
        let slot = &mut self.ring[(frame % RING as u64) as usize];
        slot.take_back();
        encoder.resolve_query_set(&self.query_set, 0..n, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &slot.buffer, 0, u64::from(n) * 8);
        slot.spans = std::mem::take(&mut self.spans);
        slot.frame = frame;
        slot.state.store(slot::RECORDED, Ordering::Release);
    }

    /// Requests the mapping of every frame resolved since the last call; call after the
    /// encoders holding them were submitted. Never waits.
    pub fn submitted(&mut self) {
        for slot in &self.ring {
            if slot.state.load(Ordering::Acquire) != slot::RECORDED {
                continue;
            }
            slot.state.store(slot::MAPPING, Ordering::Release);
            let state = slot.state.clone();
            slot.buffer.map_async(wgpu::MapMode::Read, .., move |r| {
                let to = if r.is_ok() {
                    slot::MAPPED
                } else {
                    slot::FAILED
                };
                // Only a mapping still awaited completes (a reused slot has a new state).
                let _ =
                    state.compare_exchange(slot::MAPPING, to, Ordering::AcqRel, Ordering::Acquire);
            });
        }
    }

    /// Milliseconds per span of every frame whose timestamps have arrived, oldest first, each
    /// frame's spans in the order they began; frames still in flight stay for a later call.
    /// Requests mappings as [`GpuTimer::submitted`] does, polls the device without waiting.
    pub fn collect(&mut self, device: &wgpu::Device) -> Result<Vec<Vec<(String, f64)>>> {
        self.submitted();
        device.poll(wgpu::PollType::Poll).map_err(poll_error)?;
        self.take_mapped()
    }

    /// [`GpuTimer::collect`] after waiting for every frame submitted so far.
    pub fn finish(&mut self, device: &wgpu::Device) -> Result<Vec<Vec<(String, f64)>>> {
        self.submitted();
        let waiting = |t: &Self| {
            t.ring
                .iter()
                .any(|s| s.state.load(Ordering::Acquire) == slot::MAPPING)
        };
        if waiting(self) {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(poll_error)?;
        }
        if waiting(self) {
            return Err(Error::Gpu {
                stage: "timer".into(),
                message: "timestamps were not read back after the device went idle".into(),
            });
        }
        self.take_mapped()
    }

    /// Milliseconds per span of the last frame resolved, in the order they began; waits for
    /// it. Call after the submission completed. Earlier unread frames are dropped.
    pub fn read(&mut self, device: &wgpu::Device) -> Result<Vec<(String, f64)>> {
        Ok(self.finish(device)?.pop().unwrap_or_default())
    }

    /// Reads and frees every mapped slot, oldest frame first.
    fn take_mapped(&mut self) -> Result<Vec<Vec<(String, f64)>>> {
        let mut ready: Vec<usize> = (0..self.ring.len())
            .filter(|&i| {
                let s = self.ring[i].state.load(Ordering::Acquire);
                s == slot::MAPPED || s == slot::FAILED
            })
            .collect();
        ready.sort_by_key(|&i| self.ring[i].frame);
        let mut frames = Vec::new();
        for i in ready {
            let slot = &mut self.ring[i];
            if slot.state.load(Ordering::Acquire) == slot::FAILED {
                slot.state.store(slot::IDLE, Ordering::Release);
                return Err(Error::Gpu {
                    stage: "timer".into(),
                    message: "mapping the timestamps failed".into(),
                });
            }
            let spans = {
                let view = slot.buffer.get_mapped_range(..).map_err(|e| Error::Gpu {
                    stage: "timer".into(),
                    message: e.to_string(),
                })?;
                let ticks: &[u64] = bytemuck::cast_slice(&view);
                // Only the first timestamp of each mark is a boundary.
                let at = |m: u32| ticks[2 * m as usize];
                slot.spans
                    .iter()
                    .map(|(l, a, b)| {
                        let dt = at(*b).wrapping_sub(at(*a));
                        (l.clone(), dt as f64 * self.period_ns * 1e-6)
                    })
                    .collect()
            };
            slot.buffer.unmap();
            slot.state.store(slot::IDLE, Ordering::Release);
            frames.push(spans);
        }
        Ok(frames)
    }
}

fn poll_error(e: wgpu::PollError) -> Error {
    Error::Gpu {
        stage: "timer".into(),
        message: crate::gpu::one_line(&e.to_string()),
    }
}
