//! Scene keys refused where they do not apply or when written twice, each with one line naming
//! the file, the line and the key. No GPU needed.

use std::path::Path;

use shadowgraph::Error;
use shadowgraph::low_level::scene::Scene;

/// Two lights (a spot, then the light `LIGHT` puts in) over a plane.
const BASE: &str = r#"[output]
width = 64
height = 48

[camera]
position = [0.0, 3.0, 6.0]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 45.0

[[light]]
kind = "spot"
position = [-3.0, 6.0, 2.0]
target = [0.0, 0.0, 0.0]
fov_degrees = 50.0

[light.shadow]
technique = "pcf"
radius = 2

LIGHT

[[object]]
shape = "plane"
size = [8.0, 8.0]
"#;

/// `BASE` with its second light.
fn scene(light: &str) -> String {
    BASE.replace("LIGHT", light)
}

/// Parses `text` expecting a one-line `Error::Scene` at the line of the `nth` occurrence of
/// `at`, naming each of `needles`.
#[track_caller]
fn expect(text: &str, at: &str, nth: usize, needles: &[&str]) {
    let offset = text
        .match_indices(at)
        .nth(nth)
        .expect("the marker occurs")
        .0;
    let line = text[..offset].matches('\n').count() + 1;
    let err = match Scene::parse(Path::new("keys.toml"), text) {
        Ok(_) => panic!("expected an error at line {line}, but the scene parsed:\n{text}"),
        Err(e) => e,
    };
    let shown = err.to_string();
    assert!(
        matches!(err, Error::Scene { .. }),
        "expected Error::Scene: {err:?}"
    );
    assert!(
        shown.starts_with(&format!("keys.toml:{line}:")),
        "`{shown}` is not at line {line}"
    );
    assert!(!shown.contains('\n'), "more than one line: {shown}");
    for n in needles {
        assert!(shown.contains(n), "`{shown}` does not mention `{n}`");
    }
}

/// The cascade keys apply to directional lights only (docs/SCENES.md, PARAMETERS.md): on a
/// spot or a point light each of them, `cascades = 1` too, is refused naming its key and line,
/// as `extent` is; on a directional light they load.
#[test]
fn cascade_keys_apply_to_directional_lights_only() {
    let spot = "[[light]]\nkind = \"spot\"\nposition = [3.0, 6.0, 2.0]\n\
                target = [0.0, 0.0, 0.0]\nfov_degrees = 40.0\n\n[light.shadow]\n\
                technique = \"hard\"\n";
    let point = "[[light]]\nkind = \"point\"\nposition = [3.0, 6.0, 2.0]\n\n[light.shadow]\n\
                 technique = \"hard\"\n";
    let sun = "[[light]]\nkind = \"directional\"\nposition = [3.0, 6.0, 2.0]\n\
               target = [0.0, 0.0, 0.0]\nextent = 5.0\n\n[light.shadow]\ntechnique = \"hard\"\n";
    for key in [
        "cascades = 1",
        "cascades = 3",
        "cascade_lambda = 0.5",
        "cascade_blend = 0.2",
    ] {
        let name = key.split(' ').next().expect("a key");
        let named = format!("light[1].shadow.{name}");
        for (light, kind) in [(spot, "spot"), (point, "point")] {
            let text = scene(&format!("{light}{key}\n"));
            expect(&text, key, 0, &[&named, "directional lights only", kind]);
        }
        let text = scene(&format!("{sun}{key}\n"));
        Scene::parse(Path::new("keys.toml"), &text).expect("a directional light takes it");
    }
}

/// A key or a table written twice names its dotted path (arrays of tables by index), at the
/// line of the second.
#[test]
fn duplicated_keys_and_tables_are_named() {
    let sun = "[[light]]\nkind = \"directional\"\nposition = [3.0, 6.0, 2.0]\n\
               target = [0.0, 0.0, 0.0]\nextent = 5.0\n\n[light.shadow]\ntechnique = \"hard\"\n";
    let cases: [(String, &str, usize, &str); 6] = [
        (
            scene("").replace("height = 48", "height = 48\nwidth = 32"),
            "width",
            1,
            "`output.width`",
        ),
        (
            scene(&format!("{sun}bias = 0.1\nbias = 0.2\n")),
            "bias",
            1,
            "`light[1].shadow.bias`",
        ),
        (
            scene(&format!("{sun}\n[light.shadow]\n")),
            "[light.shadow]",
            2,
            "`light[1].shadow`",
        ),
        (
            scene("").replace("[[object]]", "[output]\nwidth = 3\n\n[[object]]"),
            "[output]",
            1,
            "`output`",
        ),
        (
            scene("[light]\nkind = \"spot\"\n"),
            "[light]\n",
            0,
            "`light`",
        ),
        (
            scene("").replace("radius = 2", "radius = 2\n\"radius\" = 3"),
            "\"radius\"",
            0,
            "`light[0].shadow.radius`",
        ),
    ];
    for (text, at, nth, named) in &cases {
        expect(text, at, *nth, &["duplicate key", named]);
    }
}

/// The reader knows every key of the registry's tables (`format::ShadowFile` and `validate`'s
/// lookup are written by hand): each technique refuses, naming it, every other technique's key
/// it does not take, and no key of its own is unknown to the reader.
#[test]
fn every_registry_key_reaches_the_checker() {
    use shadowgraph::low_level::model::{ParamKind, keys};
    use shadowgraph::low_level::technique::REGISTRY;
    let all: Vec<_> = REGISTRY
        .iter()
        .flat_map(|d| d.params.iter().flat_map(|t| t.iter()))
        .collect();
    for def in REGISTRY {
        let own = keys(def.params);
        for spec in &all {
            let value = match spec.kind {
                ParamKind::Int { lo, .. } => lo.to_string(),
                ParamKind::Float { lo, .. } => format!("{lo:?}"),
                ParamKind::Choice(options) => format!("{:?}", options[0]),
            };
            let sun = format!(
                "[[light]]\nkind = \"directional\"\nposition = [3.0, 6.0, 2.0]\n\
                 target = [0.0, 0.0, 0.0]\nextent = 5.0\nsize = 0.5\n\n[light.shadow]\n\
                 technique = \"{}\"\n{} = {value}\n",
                def.name, spec.key
            );
            let text = scene(&sun);
            let got = Scene::parse(Path::new("keys.toml"), &text);
            let key = format!("light[1].shadow.{}", spec.key);
            if own.contains(&spec.key) {
                if let Err(e) = got {
                    assert!(!e.to_string().contains("unknown"), "{}: {e}", def.name);
                }
            } else {
                let at = format!("{} = ", spec.key);
                let last = text.matches(&at).count() - 1;
                expect(&text, &at, last, &[&key, "does not apply", def.name]);
            }
        }
    }
}

/// Every key of the biases' and the cascades' tables reaches the light it is written in: a
/// value other than its default (the middle of its range) changes the loaded light, for every
/// key of those tables as the registry lists them.
#[test]
fn every_common_and_cascade_key_changes_the_light() {
    use shadowgraph::low_level::model::ParamKind;
    use shadowgraph::low_level::technique::params::{CASCADES, COMMON};
    let sun = "[[light]]\nkind = \"directional\"\nposition = [3.0, 6.0, 2.0]\n\
               target = [0.0, 0.0, 0.0]\nextent = 5.0\n\n[light.shadow]\ntechnique = \"pcf\"\n";
    let load = |extra: &str| {
        let text = scene(&format!("{sun}{extra}"));
        let s =
            Scene::parse(Path::new("keys.toml"), &text).unwrap_or_else(|e| panic!("{extra}: {e}"));
        format!("{:?}", s.lights[1])
    };
    let plain = load("");
    for spec in COMMON.iter().chain(CASCADES) {
        let value = match spec.kind {
            ParamKind::Int { lo, hi } => format!("{}", (lo + hi) / 2),
            ParamKind::Float { lo, hi } => format!("{:?}", 0.5 * (lo + hi) + 0.0123),
            ParamKind::Choice(options) => format!("{:?}", options[options.len() - 1]),
        };
        let set = format!("{} = {value}\n", spec.key);
        assert_ne!(
            load(&set),
            plain,
            "`{}` left the light as it was",
            spec.key.trim()
        );
    }
}

/// A light's `update` of the wrong kind shows its value on one short line: numbers as the
/// other errors print them (`1e300`, not 301 digits), long arrays cut, a table as `{…}`.
#[test]
fn a_bad_update_rate_prints_its_value_briefly() {
    let spot = "[[light]]\nkind = \"spot\"\nposition = [3.0, 6.0, 2.0]\n\
                target = [0.0, 0.0, 0.0]\nfov_degrees = 40.0\n";
    for (value, shown) in [
        ("[1e300, \"x\"]", "[1e300, \"x\"]"),
        ("[1, 2, 3, 4, 5e-300]", "[1, 2, 3, 4, …]"),
        ("{ a = 1e300 }", "{…}"),
        ("2.5", "2.5"),
    ] {
        let text = scene(&format!("{spot}update = {value}\n"));
        let at = format!("update = {value}");
        expect(&text, &at, 0, &[&format!("`light[1].update` = {shown}:")]);
    }
}
