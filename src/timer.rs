//! GPU timing by timestamps at the boundaries between passes.
//!
//! Each timed span (a pass, a graph node, a group of passes) begins at a *mark* and ends at the
//! next one: consecutive spans share their boundary, so their sum is the time from the first
//! mark to the last. A mark is two timestamp writes on the encoder, between passes: the first
//! is the boundary, the second is written only to make it true on software drivers.
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
//! flush: it stamps the first at the boundary, before any later work starts. On a GPU it is one
//! more query write between passes (nanoseconds), and it is the same code path that the
//! lavapipe test checks (`tests/timing.rs`).
//!
//! Writing on the encoder needs `TIMESTAMP_QUERY_INSIDE_ENCODERS` (Vulkan, DX12 and Metal on
//! Apple GPUs offer it); a device without it cannot time. Timestamps inside a pass's descriptor
//! (`timestamp_writes`) cannot be made true this way: nothing can be written between a pass's
//! begin timestamp and its first dispatch without `TIMESTAMP_QUERY_INSIDE_PASSES`, and an empty
//! marker pass resolves to zero on Metal.

use crate::error::Result;
use crate::gpu::read_buffer;

/// The features [`GpuTimer`] needs.
pub const TIMER_FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

/// Timestamps at pass boundaries, resolved after the work is submitted.
pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Marks the query set holds (two queries each).
    capacity: u32,
    /// Marks written since the last [`GpuTimer::reset`].
    marks: u32,
    /// Closed spans: label, first mark, last mark.
    spans: Vec<(String, u32, u32)>,
    /// The span begun by the last mark, if any: label and its first mark.
    open: Option<(String, u32)>,
    period_ns: f64,
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
        Some(Self {
            query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("shadowgraph.timer"),
                ty: wgpu::QueryType::Timestamp,
                count: capacity * 2,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("shadowgraph.timer.resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("shadowgraph.timer.readback"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
            capacity,
            marks: 0,
            spans: Vec::new(),
            open: None,
            period_ns: f64::from(queue.get_timestamp_period()),
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
    /// lavapipe stamp the first now (see the module's documentation). `None` when full.
    fn mark(&mut self, encoder: &mut wgpu::CommandEncoder) -> Option<u32> {
        if self.marks >= self.capacity {
            return None;
        }
        let m = self.marks;
        encoder.write_timestamp(&self.query_set, 2 * m);
        encoder.write_timestamp(&self.query_set, 2 * m + 1);
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

    /// Ends the open span and records the query resolve; call after the last timed pass,
    /// before submitting.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.end(encoder);
        let n = 2 * self.marks;
        if n == 0 {
            return;
        }
        encoder.resolve_query_set(&self.query_set, 0..n, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, u64::from(n) * 8);
    }

    /// Milliseconds per span, in the order they began. Call after the submission completed.
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<(String, f64)>> {
        if self.spans.is_empty() {
            return Ok(Vec::new());
        }
        let raw = read_buffer(device, &self.readback)?;
        let ticks: &[u64] = bytemuck::cast_slice(&raw);
        // Only the first timestamp of each mark is a boundary.
        let at = |m: u32| ticks[2 * m as usize];
        Ok(self
            .spans
            .iter()
            .map(|(l, a, b)| {
                let dt = at(*b).wrapping_sub(at(*a));
                (l.clone(), dt as f64 * self.period_ns * 1e-6)
            })
            .collect())
    }
}
