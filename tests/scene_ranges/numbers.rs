//! Every number checked as the f32 it becomes, refused with its key and line or
//! accepted finite, and printed short in messages.

use super::*;

#[test]
fn full_scene_is_valid_and_finite() {
    let s = parse(FULL).expect("FULL parses");
    assert_eq!((s.lights.len(), s.objects.len()), (7, 4));
    assert_finite_scene(&s, "FULL");
    assert!(numeric_keys(FULL).len() > 60);
}

/// Each numeric key set to each extreme (and each component of a list): refused with an error
/// naming the file, the key and its line, or accepted with every f32 finite and no object
/// collapsed. Today's code casts checked f64 values to f32, so 1e39 becomes infinity and 1e-50
/// becomes 0.
#[test]
fn every_number_is_checked_as_f32() {
    let extremes = [
        "1e39", "-1e39", "1e300", "1e20", "-3e38", "1e-50", "-1e-50", "5e-324", "3.5e38", "nan",
        "inf", "-inf", "0", "-1",
    ];
    let lines: Vec<&str> = FULL.lines().collect();
    let mut refused = 0;
    let mut cases = 0;
    for (n, key, value) in numeric_keys(FULL) {
        let components = if value.starts_with('[') {
            value.matches(',').count() + 1
        } else {
            1
        };
        for x in extremes {
            for k in 0..components {
                let new_value = if value.starts_with('[') {
                    let mut parts: Vec<String> = value
                        .trim_matches(['[', ']'])
                        .split(',')
                        .map(|p| p.trim().to_string())
                        .collect();
                    parts[k] = x.to_string();
                    format!("[{}]", parts.join(", "))
                } else {
                    x.to_string()
                };
                let mut edited = lines.clone();
                let line = lines[n].replacen(&value, &new_value, 1);
                edited[n] = &line;
                let text = edited.join("\n");
                let what = format!("`{key}` = {new_value}");
                cases += 1;
                match parse(&text) {
                    Ok(s) => assert_finite_scene(&s, &what),
                    Err(e) => {
                        refused += 1;
                        let shown = e.to_string();
                        assert_short_line(&shown);
                        let Error::Scene { location, .. } = &e else {
                            panic!("{what}: expected a scene error, got {e:?}");
                        };
                        let line_no: Option<usize> =
                            location.split(':').nth(1).and_then(|l| l.parse().ok());
                        // `far` ≤ `near` may point at either; everything else at its own line.
                        let sibling = key.ends_with(".near") || key.ends_with(".far");
                        assert!(
                            line_no == Some(n + 1) || (sibling && line_no.is_some()),
                            "{what}: error at {location:?}, expected line {}: {shown}",
                            n + 1
                        );
                        let leaf = key.rsplit('.').next().unwrap_or(&key);
                        assert!(
                            shown.contains(&key) || (sibling && shown.contains(leaf)),
                            "{what}: the error does not name the key: {shown}"
                        );
                    }
                }
            }
        }
    }
    assert!(
        cases > 1000 && refused > cases / 2,
        "{refused} of {cases} refused"
    );
}

#[test]
fn the_issues_examples_are_refused_with_key_and_line() {
    let cases = [
        (
            "position = [0.5, 3.0, 6.0]",
            "position = [0, 3, 1e39]",
            "camera.position",
            "1e39",
        ),
        (
            "position = [-3.0, 6.0, 2.0]",
            "position = [-2, 1e30, -1.5]",
            "light[0].position",
            "1e30",
        ),
        (
            "color = [1.0, 0.9, 0.8]",
            "color = [1e38, 1e38, 1e38]",
            "light[0].color",
            "1e38",
        ),
        (
            "translate = [0.0, 0.5, 0.0]",
            "translate = [0, 1e39, 0]",
            "object[1].translate",
            "1e39",
        ),
        ("scale = 1.5", "scale = 1e39", "object[2].scale", "1e39"),
        ("scale = 1.5", "scale = 1e-50", "object[2].scale", "1e-50"),
        (
            "scale = [1.0, 2.0, 1.0]",
            "scale = [1, 1e-30, 1]",
            "object[1].scale",
            "1e-30",
        ),
        (
            "rotate_degrees = [0.0, 30.0, 0.0]",
            "rotate_degrees = [1e39, 0, 0]",
            "object[1].rotate_degrees",
            "1e39",
        ),
        (
            "background = [0.5, 0.6, 0.7]",
            "background = [1e39, 0, 0]",
            "output.background",
            "1e39",
        ),
        (
            "extent = 4.0",
            "extent = 5e-324",
            "light[0].extent",
            "5e-324",
        ),
    ];
    for (from, to, key, number) in cases {
        assert_eq!(FULL.matches(from).count(), 1, "{from}");
        let text = FULL.replacen(from, to, 1);
        let line = text[..text.find(to).unwrap()].matches('\n').count() + 1;
        let err = parse(&text)
            .err()
            .unwrap_or_else(|| panic!("`{to}` was accepted"));
        let shown = err.to_string();
        assert_short_line(&shown);
        assert!(
            shown.starts_with(&format!("{INLINE}:{line}:"))
                && shown.contains(key)
                && shown.contains(number),
            "`{to}`: {shown}"
        );
    }
}

#[test]
fn numbers_in_messages_print_short() {
    for (from, to, want) in [
        ("extent = 4.0", "extent = 5e-324", "5e-324"),
        ("intensity = 1.5", "intensity = 1e300", "1e300"),
        ("near = 1.0", "near = 1e-300", "1e-300"),
        ("bias = 0.003", "bias = -1e200", "-1e200"),
        // Integers past i64 (found by the fuzzer, which saw them printed in full).
        ("terms = 6", "terms = 10000000000000000000000", "1e22"),
        ("shape = \"box\"", "shape = -100000000000000000000", "-1e20"),
        // A mesh path with a line break stays one line.
        (
            "shape = \"cylinder\"\nradius = 0.3\nheight = 1.2",
            "shape = \"mesh\"\npath = \"x\\ny.obj\"",
            "x\\ny.obj` not found",
        ),
    ] {
        let shown = parse(&FULL.replacen(from, to, 1))
            .expect_err(to)
            .to_string();
        assert_short_line(&shown);
        assert!(shown.contains(want), "{shown}");
    }
}
