//! Human-readable and Graphviz views of a plan.

use std::fmt::Write;

use super::Plan;
use super::cost;
use crate::error::Result;

/// `1.5 MiB`-style byte counts.
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 4] = ["B", "KiB", "MiB", "GiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u < UNITS.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

impl Plan {
    /// The text `shadowgraph plan` prints: per light, the ordered nodes and the resources they
    /// touch (format, size, bytes), then `per_light[i]` (e.g. [`Plan::cost_text`]) where given;
    /// then memory totals.
    pub fn to_text(&self, light_labels: &[String], per_light: &[String]) -> String {
        let mut s = String::new();
        for (li, label) in light_labels.iter().enumerate() {
            let _ = writeln!(s, "light {li}: {label}");
            let steps: Vec<_> = self
                .steps
                .iter()
                .enumerate()
                .filter(|(_, st)| st.node.light == Some(li))
                .collect();
            if steps.is_empty() {
                let _ = writeln!(
                    s,
                    "  (no kernels: the shading pass reads the rasterized map)"
                );
            }
            for (i, st) in steps {
                let n = &st.node;
                let ins: Vec<&str> = n.inputs.iter().map(|(_, r)| r.as_str()).collect();
                let outs: Vec<&str> = n.outputs.iter().map(|(_, r)| r.as_str()).collect();
                let _ = writeln!(
                    s,
                    "  {i:>2}. {:<24} kernel {:<12} {} -> {}",
                    n.name,
                    n.kernel,
                    ins.join(", "),
                    outs.join(", ")
                );
            }
            for r in self
                .resources
                .iter()
                .filter(|r| r.resource.light == Some(li))
            {
                let role = if r.resource.imported {
                    "imported".to_string()
                } else {
                    format!("slot {}", r.slot.map_or("-".into(), |s| s.to_string()))
                };
                let out = if self.outputs.contains(&r.resource.name) {
                    ", read by shading"
                } else {
                    ""
                };
                let _ = writeln!(
                    s,
                    "      {:<24} {:<14} {:>5}x{:<5} {:>10}  ({role}{out})",
                    r.resource.name,
                    super::format_label(r.resource.format),
                    r.width,
                    r.height,
                    human_bytes(r.bytes)
                );
                if !r.resource.layers.is_empty() {
                    let _ = writeln!(
                        s,
                        "        interleaved along x: {}",
                        r.resource.layers.join(", ")
                    );
                }
            }
            if let Some(extra) = per_light.get(li) {
                s.push_str(extra);
            }
        }
        let imported: u64 = self
            .resources
            .iter()
            .filter(|r| r.resource.imported)
            .map(|r| r.bytes)
            .sum();
        let _ = writeln!(
            s,
            "memory: {} in {} pooled texture(s), peak live {}, plus {} imported",
            human_bytes(self.slot_bytes()),
            self.slots.len(),
            human_bytes(self.peak_live_bytes()),
            human_bytes(imported)
        );
        s
    }

    /// Light `light`'s traffic per texel of its map ([`cost`]): per node its dispatches and
    /// the bytes it reads and writes, then
    /// `total: N dispatches, X B/texel (one read + one write of the result: Y B/texel)`, where
    /// the second figure is one read of the rasterized depth and one write of the maps the
    /// shading reads, what a single fused kernel would move.
    pub fn cost_text(&self, light: usize) -> Result<String> {
        let nodes = cost::light_traffic(self, light)?;
        let (w, h) = cost::map_dims(self, light);
        let texels = f64::from(w) * f64::from(h);
        let mut s = String::new();
        if nodes.is_empty() {
            return Ok(s);
        }
        let dims = if w == h {
            format!("{w}²")
        } else {
            format!("{w}×{h}")
        };
        let _ = writeln!(s, "    traffic per texel of the {dims} map:");
        let (mut dispatches, mut bytes) = (0, 0.0);
        let width = nodes.iter().map(|(n, _)| n.name.len()).max().unwrap_or(0);
        for (node, t) in &nodes {
            let _ = writeln!(
                s,
                "      {:<width$} {:>3} dispatch{} reads {:>7.2} B, writes {:>7.2} B",
                node.name,
                t.dispatches,
                if t.dispatches == 1 { ", " } else { "es," },
                t.read / texels,
                t.written / texels,
            );
            dispatches += t.dispatches;
            bytes += t.bytes();
        }
        let _ = writeln!(
            s,
            "    total: {dispatches} dispatch{}, {:.2} B/texel (one read + one write of the \
             result: {:.2} B/texel)",
            if dispatches == 1 { "" } else { "es" },
            bytes / texels,
            cost::ideal_bytes(self, light)
        );
        Ok(s)
    }

    /// Graphviz: resources as boxes, nodes as ellipses, one cluster per light.
    pub fn to_dot(&self) -> String {
        let mut s = String::from("digraph shadowgraph {\n  rankdir=LR;\n");
        for r in &self.resources {
            let _ = writeln!(
                s,
                "  \"{0}\" [shape=box, label=\"{0}\\n{1} {2}x{3}\"];",
                r.resource.name,
                super::format_label(r.resource.format),
                r.width,
                r.height
            );
        }
        for st in &self.steps {
            let n = &st.node;
            let _ = writeln!(
                s,
                "  \"{0}\" [shape=ellipse, label=\"{0}\\n{1}\"];",
                n.name, n.kernel
            );
            for (_, r) in &n.inputs {
                let _ = writeln!(s, "  \"{r}\" -> \"{}\";", n.name);
            }
            for (_, r) in &n.outputs {
                let _ = writeln!(s, "  \"{}\" -> \"{r}\";", n.name);
            }
        }
        let _ = writeln!(s, "  \"shade\" [shape=doubleoctagon];");
        for o in &self.outputs {
            let _ = writeln!(s, "  \"{o}\" -> \"shade\";");
        }
        s.push_str("}\n");
        s
    }
}
