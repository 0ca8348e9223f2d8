//! Each technique's `[light.shadow]` keys: what applies, ranges, defaults and clamps.

use super::*;

#[test]
fn pcss_needs_a_light_size() {
    let text = scene_with(&[("technique = \"hard\"", "technique = \"pcss\"")]);
    // No `size` key: the error points at the light (its `kind`).
    let shown = expect(&text, "kind", &["light[0].size", "pcss"]);
    assert!(shown.starts_with("inline.toml:13:"), "{shown}");

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = 0.0"),
    ]);
    expect(&text, "size = 0.0", &["light[0].size", "pcss"]);

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = -1.0"),
    ]);
    expect(&text, "size = -1.0", &["light[0].size"]);

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = 0.5"),
    ]);
    let s = parse(&text).expect("pcss with size parses");
    assert_eq!(s.lights[0].size, 0.5);
    assert!(matches!(
        s.lights[0].shadow.technique,
        Technique::Pcss { .. }
    ));
}

#[test]
fn parameter_that_does_not_apply_to_the_technique() {
    let text = scene_with(&[("technique = \"hard\"", "technique = \"hard\"\nradius = 2")]);
    let shown = expect(&text, "radius", &["light[0].shadow.radius", "\"hard\""]);
    assert!(shown.starts_with("inline.toml:22:"), "{shown}");

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"pcf\"\nblocker_samples = 8",
    )]);
    expect(
        &text,
        "blocker_samples",
        &["light[0].shadow.blocker_samples", "\"pcf\""],
    );

    let text = scene_with(&[
        (
            "technique = \"hard\"",
            "technique = \"pcss\"\nkernel = \"tent\"",
        ),
        ("far = 20.0", "far = 20.0\nsize = 0.5"),
    ]);
    expect(&text, "kernel", &["light[0].shadow.kernel", "\"pcss\""]);

    // And the ones that do apply parse.
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"pcf\"\nradius = 3\nkernel = \"tent\"",
    )]);
    let s = parse(&text).expect("pcf parameters parse");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Pcf {
            radius: 3,
            kernel: PcfKernel::Tent
        }
    );
}

#[test]
fn sat_filter_keys() {
    use shadowgraph::{Filter, SatVariant};
    // `sat_sums` needs the sat filter; `filter_width` needs mips or sat.
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"blur\"\nsat_sums = \"float\"",
    )]);
    expect(&text, "sat_sums", &["light[0].shadow.sat_sums", "sat"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"sat\"\nsat_sums = \"double\"",
    )]);
    expect(&text, "sat_sums", &["light[0].shadow.sat_sums", "double"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"sat\"\nfilter_width = 2000.0",
    )]);
    expect(&text, "filter_width", &["light[0].shadow.filter_width"]);

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"msm\"\nfilter = \"sat\"\nfilter_width = 7.5\nsat_sums = \"float\"",
    )]);
    let s = parse(&text).expect("sat parameters parse");
    assert_eq!(
        s.lights[0].shadow.technique.filter(),
        Some(Filter::Sat {
            width: 7.5,
            variant: SatVariant::Float
        })
    );
}

/// Exponents past what a summed-area table keeps accurate are clamped to
/// `sat_exponent_limit`, with a warning when the scene set them; defaults clamp silently.
#[test]
fn sat_filter_clamps_exponents() {
    use shadowgraph::Filter;
    use shadowgraph::low_level::technique::sat_exponent_limit;
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"evsm4\"\nfilter = \"sat\"\nfilter_width = 4.0",
    )]);
    let s = parse(&text).expect("parses");
    let filter = Filter::Sat {
        width: 4.0,
        variant: shadowgraph::SatVariant::Fixed,
    };
    // (4 + 1)² = 25 texels: ½ ln(2²² / 25) = 6.0.
    let limit = sat_exponent_limit(&filter, false).expect("a limit");
    assert!(
        (limit - 0.5 * (4194304.0f32 / 25.0).ln()).abs() < 1e-5,
        "{limit}"
    );
    let Technique::Evsm {
        exp_pos, exp_neg, ..
    } = s.lights[0].shadow.technique
    else {
        panic!("evsm4")
    };
    assert_eq!((exp_pos, exp_neg), (limit, 5.0f32.min(limit)));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"esm\"\nfilter = \"sat\"\nfilter_width = 4.0\nexponent = 60.0",
    )]);
    let s = parse(&text).expect("parses");
    let esm_limit = sat_exponent_limit(&filter, true).expect("a limit");
    assert!((esm_limit - 4.0 * limit).abs() < 1e-4);
    let Technique::Esm { exponent, .. } = s.lights[0].shadow.technique else {
        panic!("esm")
    };
    assert_eq!(exponent, esm_limit);
    assert!(
        s.warnings.iter().any(|w| w.contains("exponent")),
        "{:?}",
        s.warnings
    );
}

/// `max_anisotropy` belongs to the mips filter, 0–16.
#[test]
fn max_anisotropy_key() {
    use shadowgraph::Filter;
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"blur\"\nmax_anisotropy = 4",
    )]);
    expect(
        &text,
        "max_anisotropy",
        &["light[0].shadow.max_anisotropy", "mips"],
    );
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"mips\"\nmax_anisotropy = 17",
    )]);
    expect(&text, "max_anisotropy", &["light[0].shadow.max_anisotropy"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"esm\"\nfilter = \"mips\"\nfilter_width = 2.0\nmax_anisotropy = 16",
    )]);
    let s = parse(&text).expect("parses");
    assert_eq!(
        s.lights[0].shadow.technique.filter(),
        Some(Filter::Mips {
            width: 2.0,
            max_anisotropy: 16
        })
    );
}

#[test]
fn soft_techniques_keys_defaults_and_errors() {
    use shadowgraph::{SatVariant, Soft, Storage};
    let soft = |keys: &str, size: &str| {
        scene_with(&[
            ("technique = \"hard\"", keys),
            ("far = 20.0", &format!("far = 20.0\n{size}")),
        ])
    };
    // Each needs an area light, named at the light's `kind` when no `size` is given.
    for t in ["cssm", "vssm", "msm_soft"] {
        let text = scene_with(&[("technique = \"hard\"", &format!("technique = \"{t}\""))]);
        let shown = expect(&text, "kind", &["light[0].size", t]);
        assert!(shown.starts_with("inline.toml:13:"), "{shown}");
        let text = soft(&format!("technique = \"{t}\""), "size = 0.0");
        expect(&text, "size = 0.0", &["light[0].size", t]);
    }
    // Defaults: f32 representation, fixed-point sums, search cap 0.1; CSSM as CSM plus the
    // sharpening; VSSM as VSM; soft MSM as MSM.
    let defaults = Soft {
        storage: Storage::F32,
        sums: SatVariant::Fixed,
        max_search: 0.1,
    };
    let s = parse(&soft("technique = \"cssm\"", "size = 0.5")).expect("cssm parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Cssm {
            soft: defaults,
            terms: 8,
            attenuation: 1.0,
            offset: 0.0625,
            scale: 2.0,
            sharpen: shadowgraph::low_level::model::DEFAULT_SHARPEN,
            sharpen_falloff: shadowgraph::low_level::model::DEFAULT_SHARPEN_FALLOFF,
            search: shadowgraph::CssmSearch::Moments,
            resolve: shadowgraph::CssmResolve::TwoDepth,
        }
    );
    let s = parse(&soft("technique = \"vssm\"", "size = 0.5")).expect("vssm parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Vssm {
            soft: defaults,
            bleed: 0.2,
            min_variance: 1e-5,
        }
    );
    let keys = "technique = \"msm_soft\"\nformat = \"unorm16\"\nsat_sums = \"float\"\n\
                max_search = 0.05\nreconstruction = \"hausdorff\"";
    let s = parse(&soft(keys, "size = 0.5")).expect("msm_soft parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::MsmSoft {
            soft: Soft {
                storage: Storage::Unorm16,
                sums: SatVariant::Float,
                max_search: 0.05,
            },
            hausdorff: true,
            moment_bias: shadowgraph::low_level::model::default_soft_moment_bias(Storage::Unorm16),
            bleed: 0.0,
        }
    );
    // Keys out of range, of another technique, or of a fixed filter name themselves.
    for (keys, at, needles) in [
        (
            "technique = \"cssm\"\nsharpen = -1.0",
            "sharpen",
            &["light[0].shadow.sharpen", "-1"][..],
        ),
        (
            "technique = \"cssm\"\nsharpen_falloff = 1e5",
            "sharpen_falloff",
            &["light[0].shadow.sharpen_falloff"],
        ),
        (
            "technique = \"cssm\"\nterms = 17",
            "terms",
            &["light[0].shadow.terms"],
        ),
        (
            "technique = \"vssm\"\nmax_search = 0.0",
            "max_search",
            &["light[0].shadow.max_search"],
        ),
        (
            "technique = \"vssm\"\nsat_sums = \"double\"",
            "sat_sums",
            &["light[0].shadow.sat_sums", "\"fixed\""],
        ),
        (
            "technique = \"vssm\"\nformat = \"unorm16\"",
            "format",
            &["light[0].shadow.format", "\"f16\""],
        ),
        (
            "technique = \"vssm\"\nfilter = \"sat\"",
            "filter",
            &["light[0].shadow.filter", "\"vssm\""],
        ),
        (
            "technique = \"msm_soft\"\nfilter_width = 4.0",
            "filter_width",
            &["light[0].shadow.filter_width", "\"msm_soft\""],
        ),
        (
            "technique = \"csm\"\nsharpen = 1.0",
            "sharpen",
            &["light[0].shadow.sharpen", "\"csm\""],
        ),
    ] {
        expect(&soft(keys, "size = 0.5"), at, needles);
    }
    // A search cap whose squares no fixed-point table can sum names `max_search`.
    let text = soft(
        "technique = \"vssm\"\nmax_search = 1.0",
        "size = 0.5\nshadow_map = 60000",
    );
    expect(
        &text,
        "max_search",
        &["light[0].shadow.max_search", "sat_sums"],
    );
    let text = soft(
        "technique = \"vssm\"\nmax_search = 1.0\nsat_sums = \"float\"",
        "size = 0.5\nshadow_map = 60000",
    );
    parse(&text).expect("f32 sums have no window limit");
}

/// The cascade keys: ranges by the one checker, the technique (`smrt`) and light kinds that
/// cannot have cascades, each named with its key and line; a valid table gives its values,
/// PCSS's, the soft techniques' and the second-depth techniques' too.
#[test]
fn cascade_keys_are_checked() {
    let tech = "technique = \"hard\"";
    for (edit, at, needles) in [
        (
            "technique = \"hard\"\ncascades = 9",
            "cascades = 9",
            &["cascades", "8"][..],
        ),
        (
            "technique = \"hard\"\ncascades = 0",
            "cascades = 0",
            &["cascades"][..],
        ),
        (
            "technique = \"hard\"\ncascades = 3\ncascade_lambda = 1.5",
            "cascade_lambda = 1.5",
            &["cascade_lambda"][..],
        ),
        (
            "technique = \"pcf\"\ncascades = 3\ncascade_blend = 0.6",
            "cascade_blend = 0.6",
            &["cascade_blend"][..],
        ),
        (
            "technique = \"smrt\"\ncascades = 4",
            "cascades = 4",
            &["cascades", "smrt", "guard band"][..],
        ),
    ] {
        let text = scene_with(&[(tech, edit)]);
        expect(&text, at, needles);
    }
    let spot = scene_with(&[
        (
            "kind = \"directional\"",
            "kind = \"spot\"\nfov_degrees = 60.0",
        ),
        ("extent = 4.0\n", ""),
        (tech, "technique = \"vsm\"\ncascades = 2"),
    ]);
    expect(&spot, "cascades = 2", &["cascades", "directional"]);
    let ok = scene_with(&[(
        tech,
        "technique = \"msm\"\ncascades = 4\ncascade_lambda = 0.8\ncascade_blend = 0.2",
    )]);
    let c = parse(&ok).expect("valid cascades").lights[0]
        .shadow
        .cascades;
    assert_eq!((c.count, c.lambda, c.blend), (4, 0.8, 0.2));
    // A guard band past a quarter of each cascade's map (normal_bias 80: 80 + 3 texels of a
    // 256² map) is named at normal_bias's line with the smallest map that fits.
    let wide = scene_with(&[
        (
            "extent = 4.0\n",
            "extent = 4.0\nsize = 0.2\nshadow_map = 256\n",
        ),
        (
            tech,
            "technique = \"vssm\"\ncascades = 3\nnormal_bias = 80.0",
        ),
    ]);
    expect(
        &wide,
        "normal_bias = 80.0",
        &["guard band of 83 texels", "256", "332", "normal_bias"],
    );
    // PCSS and the soft techniques take cascades (each with a guard band), and so do the
    // second-depth techniques (each cascade peeled).
    for t in [
        "pcss",
        "vssm",
        "msm_soft",
        "cssm",
        "midpoint",
        "second_depth",
    ] {
        let text = scene_with(&[
            ("extent = 4.0\n", "extent = 4.0\nsize = 0.2\n"),
            (tech, &format!("technique = \"{t}\"\ncascades = 3")),
        ]);
        let c = parse(&text).unwrap_or_else(|e| panic!("{t}: {e}")).lights[0]
            .shadow
            .cascades;
        assert_eq!(c.count, 3, "{t}");
    }
    let c = parse(BASE).expect("base").lights[0].shadow.cascades;
    assert_eq!(c, shadowgraph::Cascades::SINGLE);
}
