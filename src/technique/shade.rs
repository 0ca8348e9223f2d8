//! The shading kernel's generated block: per light the maps it binds and the WGSL visibility
//! call of its technique.

use std::fmt::Write;

use crate::graph::Graph;
use crate::model::{Filter, Light, PcfKernel, Technique};
use crate::sat::SatVariant;

use super::light_gpu::sat_variant;
use super::nodes::{add_light_nodes, csm_maps};

/// How the shading kernel reads a light's maps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadeInput {
    /// Graph resources bound, in binding order (one for every technique but CSM, which binds
    /// one map per two terms).
    pub maps: Vec<String>,
    /// WGSL type of each binding.
    pub wgsl_type: &'static str,
}

/// Light `light`'s visibility as the shading kernel and the plug-in's host block call it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VisibilityBody {
    /// The modules it needs (`shared/vis_*` and their helpers).
    pub modules: Vec<&'static str>,
    /// WGSL statements ending in a `return`, with `l: Light`, `s: LightSample` in scope and
    /// the light's maps bound under the names given to [`visibility_body`].
    pub body: String,
    /// The `// #fetches` expression of a function made of `body` when its count cannot be
    /// summed from the body's calls (it loops: CSSM's two passes over its basis tables).
    pub fetches: Option<String>,
}

/// The modules, statements and fetch count of light `light`'s visibility with its maps bound
/// as `maps`.
pub fn visibility_body(light: &Light, maps: &[String]) -> VisibilityBody {
    let simple = |modules: Vec<&'static str>, body: String| VisibilityBody {
        modules,
        body,
        fetches: None,
    };
    if let Some(soft) = light.shadow.technique.soft() {
        let (body, fetches) = soft_visibility_body(light, maps, soft.sums);
        return VisibilityBody {
            modules: vec![soft_module(&light.shadow.technique)],
            body,
            fetches,
        };
    }
    if let Some(Filter::Sat { variant, .. }) = light.shadow.technique.filter() {
        let (module, body) = sat_visibility_body(light, maps, variant);
        return simple(vec![module, "shared/sat_lookup"], body);
    }
    let (module, body) = filtered_visibility_body(light, maps);
    simple(vec![module], body)
}

/// [`visibility_body`] with the `sat` filter: each map's rectangle mean, then the technique's
/// `*_of` function.
fn sat_visibility_body(
    light: &Light,
    maps: &[String],
    variant: SatVariant,
) -> (&'static str, String) {
    let sample = |map: &str| {
        let f = match variant {
            SatVariant::Fixed => "sat_sample_fixed",
            SatVariant::Float => "sat_sample_float",
        };
        format!("{f}({map}, l, s.uv, l.filter_width)")
    };
    let map = maps.first().map_or("", String::as_str);
    let call = |module, f: &str| (module, format!("return {f}({}, l, s);", sample(map)));
    match light.shadow.technique {
        Technique::Evsm { .. } => call("shared/vis_evsm", "vis_evsm_of"),
        Technique::Esm { .. } => call("shared/vis_esm", "vis_esm_of_sat"),
        Technique::Msm { .. } => call("shared/vis_msm", "vis_msm_of"),
        Technique::Csm { .. } => {
            let mut body = String::from("var sum = 0.0;");
            for (chunk, m) in maps.iter().enumerate() {
                let _ = write!(
                    body,
                    "\n            sum += csm_chunk_of({}, {chunk}u, l, s);",
                    sample(m)
                );
            }
            body.push_str("\n            return csm_resolve(sum, l);");
            ("shared/vis_csm", body)
        }
        _ => call("shared/vis_vsm", "vis_vsm_of"),
    }
}

/// The module of a soft technique's visibility (it imports the table lookups and
/// `shared/blocker`).
fn soft_module(technique: &Technique) -> &'static str {
    match technique {
        Technique::Cssm { .. } => "shared/vis_cssm",
        Technique::MsmSoft { .. } => "shared/vis_msm_soft",
        _ => "shared/vis_vssm",
    }
}

/// [`visibility_body`] of a soft technique and, where it loops, its fetch count: the table
/// means over the blocker-search square, the blocker estimate, and only where that finds
/// blockers the means over the penumbra width (`shared/blocker`'s two passes). VSSM and soft
/// MSM call their module's complete function; CSSM sums its CSM-Z maps (the maps after the
/// first ⌈M/2⌉) over the search square, then runs the two passes over its basis maps here.
fn soft_visibility_body(
    light: &Light,
    maps: &[String],
    variant: SatVariant,
) -> (String, Option<String>) {
    let suffix = match variant {
        SatVariant::Fixed => "fixed",
        SatVariant::Float => "float",
    };
    let map = maps.first().map_or("", String::as_str);
    let Technique::Cssm { terms, .. } = light.shadow.technique else {
        let f = match light.shadow.technique {
            Technique::MsmSoft { .. } => "vis_msm_soft",
            _ => "vis_vssm",
        };
        return (format!("return {f}_{suffix}({map}, l, s);"), None);
    };
    let (basis, z) = maps.split_at((csm_maps(terms) as usize).min(maps.len()));
    let sample = |m: &str, width: &str| format!("sat_sample_{suffix}({m}, l, s.uv, {width})");
    let mut body = String::from(
        "var look = soft_search(l, s);
    var zsum = 0.0;",
    );
    for (chunk, m) in z.iter().enumerate() {
        let _ = write!(
            body,
            "\n    zsum += csm_z_chunk_of({}, {chunk}u, l, s);",
            sample(m, "look.width")
        );
    }
    body.push_str("\n    var sum = 0.0;\n    for (var k = 0u; k < 2u; k++) {\n        sum = 0.0;");
    for (chunk, m) in basis.iter().enumerate() {
        let _ = write!(
            body,
            "\n        sum += csm_chunk_of({}, {chunk}u, l, s);",
            sample(m, "look.width")
        );
    }
    body.push_str(
        "\n        if k == 0u {\n            look = soft_blockers(cssm_blocker(sum, zsum, l, s), l, s);\n            \
         if !look.blockers {\n                return 1.0;\n            }\n        }\n    }\n    \
         return cssm_resolve(sum, look.blocker, l, s);",
    );
    let fetches = format!(
        "{} * sat_sample_{suffix} + 2 * {} * sat_sample_{suffix}",
        z.len(),
        basis.len()
    );
    (body, Some(fetches))
}

/// [`visibility_body`] without the `sat` filter.
fn filtered_visibility_body(light: &Light, maps: &[String]) -> (&'static str, String) {
    let map = maps.first().map_or("", String::as_str);
    let call = |module, f: &str| (module, format!("return {f}({map}, l, s);"));
    match light.shadow.technique {
        Technique::Hard => call("shared/vis_hard", "vis_hard"),
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        } => (
            "shared/vis_pcf",
            format!("return vis_pcf_hardware({map}, cmp_sampler, l, s);"),
        ),
        Technique::Pcf { .. } => call("shared/vis_pcf", "vis_pcf"),
        Technique::Pcss { .. } => call("shared/vis_pcss", "vis_pcss"),
        Technique::Vsm { .. } => call("shared/vis_vsm", "vis_vsm"),
        Technique::Evsm { .. } => call("shared/vis_evsm", "vis_evsm"),
        Technique::Esm { .. } => call("shared/vis_esm", "vis_esm"),
        Technique::Msm { .. } => call("shared/vis_msm", "vis_msm"),
        Technique::Csm { .. } => {
            let mut body = String::from("var sum = 0.0;");
            for (chunk, m) in maps.iter().enumerate() {
                let _ = write!(body, "\n            sum += csm_chunk({m}, {chunk}u, l, s);");
            }
            body.push_str("\n            return csm_resolve(sum, l);");
            ("shared/vis_csm", body)
        }
        // Soft techniques are handled by `soft_visibility_body`.
        Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
            (soft_module(&light.shadow.technique), String::new())
        }
    }
}

/// The key of the shading kernel for `lights`: what [`shading_block`] reads of each light (its
/// technique, the table it reads through, hardware PCF, whether it follows the pixel's
/// footprint, CSM's terms, its maps' count and type), so that a scene of the same techniques
/// finds its kernel without generating the block (`tests/reuse.rs` checks that lights with
/// equal keys get equal blocks).
pub fn shade_key(lights: &[Light]) -> String {
    let mut key = String::from("shade");
    for (i, light) in lights.iter().enumerate() {
        let t = &light.shadow.technique;
        let table = match sat_variant(light) {
            Some(SatVariant::Fixed) => "u32",
            Some(SatVariant::Float) => "f32",
            None => "-",
        };
        let hardware = matches!(
            t,
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            }
        );
        let footprint =
            matches!(t.filter(), Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0);
        let terms = match *t {
            Technique::Csm { terms, .. } | Technique::Cssm { terms, .. } => terms,
            _ => 0,
        };
        let input = add_light_nodes(&mut Graph::default(), i, light);
        let _ = write!(
            key,
            "|{} {table} {} {} {terms} {}x{}",
            t.name(),
            u8::from(hardware),
            u8::from(footprint),
            input.maps.len(),
            input.wgsl_type
        );
    }
    key
}

/// The `// #generated` block of `kernels/shade.wgsl` for these lights: imports of the
/// techniques used, one group-1 binding per map (light by light, in [`ShadeInput::maps`]
/// order), one visibility function per light and `light_visibility`, which dispatches on the
/// light index. A receiver that faces away from a light reads 0 and one outside its map 1,
/// without a lookup (`light_faces`, `LightSample::inside`).
pub fn shading_block(lights: &[Light]) -> String {
    let mut imports: Vec<&str> = Vec::new();
    let mut bindings = String::new();
    let mut cases = String::new();
    let mut functions = String::new();
    let mut binding = 0;
    for (i, light) in lights.iter().enumerate() {
        let input = add_light_nodes(&mut Graph::default(), i, light);
        let maps: Vec<String> = (0..input.maps.len())
            .map(|k| format!("light{i}_map{k}"))
            .collect();
        let vis = visibility_body(light, &maps);
        for module in vis.modules {
            if !imports.contains(&module) {
                imports.push(module);
            }
        }
        for map in &maps {
            let _ = writeln!(
                bindings,
                "@group(1) @binding({binding}) var {map}: {};",
                input.wgsl_type
            );
            binding += 1;
        }
        if let Some(fetches) = &vis.fetches {
            let _ = writeln!(functions, "// #fetches light{i}_visibility: {fetches}");
        }
        let _ = writeln!(
            functions,
            "fn light{i}_visibility(l: Light, s: LightSample) -> f32 {{\n    {}\n}}",
            vis.body
        );
        // Only anisotropic mip lookups read the footprint (two more projections per pixel).
        let footprint = match light.shadow.technique.filter() {
            Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0 => {
                "\n            s.footprint = light_footprint(l, s, p, n, dpdx, dpdy);"
            }
            _ => "",
        };
        let _ = writeln!(
            cases,
            "        case {i}u: {{\n            let l = lights[{i}];\n            \
             if !light_faces(l, p, n) {{\n                return 0.0;\n            }}\n            \
             var s = light_sample(l, p, n);\n            \
             if !s.inside {{\n                return 1.0;\n            }}{footprint}\n            \
             return light{i}_visibility(l, s);\n        }}"
        );
    }
    let mut s = String::new();
    for m in imports {
        let _ = writeln!(s, "// #import {m}");
    }
    s.push_str(&bindings);
    s.push_str(&functions);
    let _ = write!(
        s,
        "fn light_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> f32 {{\n    switch i {{\n{cases}        default: {{ return 1.0; }}\n    }}\n}}\n"
    );
    s
}
