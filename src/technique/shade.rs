//! The shading kernel's generated block: per light the maps it binds and the WGSL visibility
//! call of its technique ([`super::TechniqueDef::visibility`]), with the helpers the
//! techniques' visibility bodies share.

use std::fmt::Write;

use crate::graph::Graph;
use crate::model::SatVariant;
use crate::model::{Filter, Light, LightKind};

use super::cascade_shade::{CASCADE_MODULE, CascadeGroup, cascade_functions};
use super::light_gpu::sat_variant;
use super::nodes::add_light_nodes;

/// How the shading kernel reads a light's maps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadeInput {
    /// Graph resources bound, in binding order (one for every technique but CSM and CSSM,
    /// which bind one map per two terms and the search's maps, or through fixed-point tables
    /// the textures their tables are interleaved in, `Graph::interleaved`).
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

impl VisibilityBody {
    /// A body of `module` whose fetches sum from its calls.
    pub fn simple(modules: Vec<&'static str>, body: String) -> Self {
        Self {
            modules,
            body,
            fetches: None,
        }
    }
}

/// The modules, statements and fetch count of light `light`'s visibility with its maps bound
/// as `maps`.
pub fn visibility_body(light: &Light, maps: &[String]) -> VisibilityBody {
    (super::of(&light.shadow.technique).visibility)(light, maps)
}

/// The first map's name (every technique but CSM's binds one).
pub(super) fn first(maps: &[String]) -> &str {
    maps.first().map_or("", String::as_str)
}

/// `return f(map, l, s);` from `module`.
pub(super) fn call(module: &'static str, f: &str, maps: &[String]) -> VisibilityBody {
    VisibilityBody::simple(vec![module], format!("return {f}({}, l, s);", first(maps)))
}

/// The table lookup's suffix of a table variant (`sat_sample_fixed`, `vis_vssm_float`, …).
pub(super) fn table_suffix(variant: SatVariant) -> &'static str {
    match variant {
        SatVariant::Fixed => "fixed",
        SatVariant::Float => "float",
    }
}

/// The filtering sampler of f32 tables' lookups (a global of `kernels/shade.wgsl`: linear,
/// clamped to the edge; a plug-in host binds its own after the maps).
pub const SAT_SAMPLER: &str = "sat_sampler";

/// The table arguments of a soft technique's filter lookup or visibility function of
/// `variant`: the map, then for f32 tables, whose filter reads filtered fetches, the sampler
/// ([`SAT_SAMPLER`]).
pub(super) fn table_args(variant: SatVariant, map: &str) -> String {
    match variant {
        SatVariant::Fixed => map.to_string(),
        SatVariant::Float => format!("{map}, {SAT_SAMPLER}"),
    }
}

/// The rectangle mean of `map` at `width` as a WGSL expression (the `sat` filter: sixteen
/// loads, in either variant).
pub(super) fn sat_sample(variant: SatVariant, map: &str, width: &str) -> String {
    format!(
        "sat_sample_{}({map}, l, s.uv, {width})",
        table_suffix(variant)
    )
}

/// A prefiltered technique's visibility: through the `sat` filter, `of(mean, l, s)` of the
/// map's rectangle mean (and the table lookups' module); from packed f16 pairs
/// `of(sample_map_packed(map, l, s), l, s)`; else `plain(map, l, s)`.
pub(super) fn prefiltered(
    light: &Light,
    maps: &[String],
    module: &'static str,
    plain: &str,
    of: &str,
) -> VisibilityBody {
    match light.shadow.technique.filter() {
        Some(Filter::Sat { variant, .. }) => {
            let mean = sat_sample(variant, first(maps), "l.filter_width");
            VisibilityBody::simple(
                vec![module, "shared/sat_lookup"],
                format!("return {of}({mean}, l, s);"),
            )
        }
        _ if super::nodes::maps_packed(light) => VisibilityBody::simple(
            vec![module, "shared/sampling_packed"],
            format!(
                "return {of}(sample_map_packed({}, l, s), l, s);",
                first(maps)
            ),
        ),
        _ => call(module, plain, maps),
    }
}

/// A soft technique's visibility whose module does it all: `f_<table>(map, l, s)`.
pub(super) fn soft_call(
    light: &Light,
    maps: &[String],
    module: &'static str,
    f: &str,
) -> VisibilityBody {
    let sums = light
        .shadow
        .technique
        .soft()
        .map_or(SatVariant::Fixed, |s| s.sums);
    VisibilityBody::simple(
        vec![module],
        format!(
            "return {f}_{}({}, l, s);",
            table_suffix(sums),
            table_args(sums, first(maps))
        ),
    )
}

/// The key of the shading kernel for `lights`: what [`shading_block`] reads of each light (its
/// technique and what its visibility code depends on, [`super::TechniqueDef::variant`], the
/// table it reads through, whether it follows the pixel's footprint, its maps' count and
/// type), so that a scene of the same techniques finds its kernel without generating the
/// block (`tests/reuse.rs` checks that lights with equal keys get equal blocks).
pub fn shade_key(lights: &[Light]) -> String {
    let mut key = String::from("shade");
    for (i, light) in lights.iter().enumerate() {
        let t = &light.shadow.technique;
        let table = match sat_variant(light) {
            Some(SatVariant::Fixed) => "u32",
            Some(SatVariant::Float) => "f32",
            None => "-",
        };
        let footprint =
            matches!(t.filter(), Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0);
        let def = super::of(t);
        let mut graph = Graph::default();
        let input = add_light_nodes(&mut graph, i, light);
        // Tables interleaved in a texture are read at their slots (`SatLayer(n, k)`): the
        // tables each binding holds, where any holds several.
        let held: Vec<String> = input
            .maps
            .iter()
            .map(|m| {
                graph
                    .find(m)
                    .map_or(1, |r| r.layers.len().max(1))
                    .to_string()
            })
            .collect();
        let layout = if held.iter().any(|h| h != "1") {
            format!(" [{}]", held.join(","))
        } else {
            String::new()
        };
        let point = if light.kind == LightKind::Point {
            " point"
        } else {
            ""
        };
        let _ = write!(
            key,
            "|{}{point} {table} {} {} {}x{}{layout}",
            def.name,
            u8::from(footprint),
            (def.variant)(t),
            input.maps.len(),
            input.wgsl_type
        );
    }
    key
}

/// The name of light `light`'s map `map` in the shading kernel's group 1 ([`shading_block`]).
pub fn map_binding(light: usize, map: usize) -> String {
    format!("light{light}_map{map}")
}

/// The `// #generated` block of `kernels/shade.wgsl` for these lights: imports of the
/// techniques used, one group-1 binding per map (light by light, in [`ShadeInput::maps`]
/// order), one visibility function per light and `light_visibility`, which dispatches on the
/// light index. A receiver that faces away from a light reads 0 and one outside its map 1,
/// without a lookup (`light_faces`, `LightSample::inside`).
pub fn shading_block(lights: &[Light]) -> String {
    shading_block_cascaded(lights, &[])
}

/// [`shading_block`] where the lights `groups` name are cascaded: `lights` holds the scene's
/// lights (a cascaded one as its cascade 0) followed by every group's further cascades, each
/// a light of its own (bindings and visibility function); `light_visibility` dispatches on the
/// scene's lights only, and a cascaded light's case picks its cascade per pixel
/// (`cascade_shade`).
pub fn shading_block_cascaded(lights: &[Light], groups: &[CascadeGroup]) -> String {
    let visible = lights.len() - groups.iter().map(|g| g.extra()).sum::<usize>();
    let mut imports: Vec<&str> = Vec::new();
    let mut bindings = String::new();
    let mut cases = String::new();
    let mut functions = String::new();
    let mut binding = 0;
    for (i, light) in lights.iter().enumerate() {
        let input = add_light_nodes(&mut Graph::default(), i, light);
        let maps: Vec<String> = (0..input.maps.len()).map(|k| map_binding(i, k)).collect();
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
        if i >= visible {
            continue;
        }
        let body = match groups.iter().find(|g| g.light == i) {
            Some(g) => {
                functions.push_str(&cascade_functions(g, lights));
                if !imports.contains(&CASCADE_MODULE) {
                    imports.push(CASCADE_MODULE);
                }
                format!("\n            return light{i}_cascaded(p, n, dpdx, dpdy);")
            }
            None => light_case(i, light),
        };
        let _ = writeln!(cases, "        case {i}u: {{{body}\n        }}");
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

/// The statements of light `i`'s case: whether the receiver faces it, where it lands in the
/// map, and its visibility function.
pub(super) fn light_case(i: usize, light: &Light) -> String {
    // Only anisotropic mip lookups read the footprint (two more projections per pixel).
    let footprint = match light.shadow.technique.filter() {
        Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0 => {
            "\n            s.footprint = light_footprint(l, s, p, n, dpdx, dpdy);"
        }
        _ => "",
    };
    // The projection of the light's kind, chosen here rather than branched on per pixel.
    let sample = if light.kind == LightKind::Point {
        "point_sample"
    } else {
        "map_sample"
    };
    format!(
        "\n            let l = lights[{i}];\n            \
         if !light_faces(l, p, n) {{\n                return 0.0;\n            }}\n            \
         var s = {sample}(l, p, n);\n            \
         if !s.inside {{\n                return 1.0;\n            }}{footprint}\n            \
         return light{i}_visibility(l, s);"
    )
}
