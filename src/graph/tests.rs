//! Planner tests: no GPU needed.

use super::*;

const F: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

fn node(name: &str, ins: &[&str], outs: &[&str]) -> Node {
    Node {
        name: name.into(),
        kernel: crate::kernels::KernelId::Copy,
        inputs: ins
            .iter()
            .map(|r| ("src".to_string(), r.to_string()))
            .collect(),
        outputs: outs
            .iter()
            .map(|r| ("dst".to_string(), r.to_string()))
            .collect(),
        params: vec![],
        dispatch: Dispatch::Groups([1, 1, 1]),
        light: Some(0),
    }
}

fn fixed(w: u32) -> SizeRule {
    SizeRule::Fixed {
        width: w,
        height: w,
    }
}

/// depth → a → b → c, plus a side branch a → x that no output needs.
fn chain() -> Graph {
    let mut g = Graph::default();
    g.import("depth", wgpu::TextureFormat::Depth32Float, 64, 64, Some(0));
    for r in ["a", "b", "c", "x"] {
        g.resource(r, F, fixed(64), Some(0));
    }
    g.node(node("make_x", &["a"], &["x"]));
    g.node(node("make_c", &["b"], &["c"]));
    g.node(node("make_b", &["a"], &["b"]));
    g.node(node("make_a", &["depth"], &["a"]));
    g
}

fn names(p: &Plan) -> Vec<&str> {
    p.steps.iter().map(|s| s.node.name.as_str()).collect()
}

#[test]
fn prunes_what_no_output_needs() {
    let p = plan(&chain(), &["c"]).unwrap();
    assert_eq!(names(&p), ["make_a", "make_b", "make_c"]);
    assert!(p.resource("x").is_none());
    let p = plan(&chain(), &["a"]).unwrap();
    assert_eq!(names(&p), ["make_a"]);
}

#[test]
fn imported_output_needs_no_node() {
    let p = plan(&chain(), &["depth"]).unwrap();
    assert!(p.steps.is_empty());
    assert!(p.slots.is_empty());
}

#[test]
fn order_is_dependency_first_then_declaration_order() {
    // Both branches are needed; make_x is declared first, so after make_a it runs before make_b.
    let p = plan(&chain(), &["c", "x"]).unwrap();
    assert_eq!(names(&p), ["make_a", "make_x", "make_b", "make_c"]);
    // Same result whatever order the outputs are asked in.
    let q = plan(&chain(), &["x", "c"]).unwrap();
    assert_eq!(names(&p), names(&q));
}

#[test]
fn missing_producer_is_named() {
    let mut g = chain();
    g.resource("orphan", F, fixed(8), None);
    g.node(node("use_orphan", &["orphan"], &["y"]));
    g.resource("y", F, fixed(8), None);
    let e = plan(&g, &["y"]).unwrap_err();
    assert_eq!(
        e,
        GraphError::MissingProducer {
            resource: "orphan".into(),
            needed_by: "use_orphan".into()
        }
    );
}

#[test]
fn cycle_is_reported_with_its_nodes() {
    let mut g = Graph::default();
    g.resource("p", F, fixed(8), None);
    g.resource("q", F, fixed(8), None);
    g.node(node("n1", &["q"], &["p"]));
    g.node(node("n2", &["p"], &["q"]));
    match plan(&g, &["p"]).unwrap_err() {
        GraphError::Cycle(c) => {
            assert!(
                c.contains(&"n1".to_string()) && c.contains(&"n2".to_string()),
                "{c:?}"
            )
        }
        e => panic!("expected a cycle, got {e}"),
    }
}

#[test]
fn wiring_mistakes_are_typed_errors() {
    let mut g = chain();
    g.node(node("bad", &["nope"], &["c2"]));
    assert!(matches!(
        plan(&g, &["c"]),
        Err(GraphError::UnknownResource { .. })
    ));

    let mut g = chain();
    g.node(node("again", &["a"], &["b"]));
    assert!(matches!(
        plan(&g, &["c"]),
        Err(GraphError::DuplicateProducer { .. })
    ));

    let mut g = chain();
    g.node(node("clobber", &["a"], &["depth"]));
    assert!(matches!(
        plan(&g, &["c"]),
        Err(GraphError::WritesImport { .. })
    ));

    assert!(matches!(
        plan(&chain(), &["zzz"]),
        Err(GraphError::UnknownOutput(_))
    ));
}

#[test]
fn textures_are_reused_after_last_use() {
    // a → b → c: a dies after make_b, so c (same shape) reuses a's slot.
    let p = plan(&chain(), &["c"]).unwrap();
    let slot = |r: &str| p.resource(r).unwrap().slot.unwrap();
    assert_ne!(
        slot("a"),
        slot("b"),
        "a step never reads and writes one texture"
    );
    assert_eq!(slot("a"), slot("c"));
    assert_eq!(p.slots.len(), 2);
    assert_eq!(p.slot_bytes(), 2 * 64 * 64 * 4);
    assert_eq!(p.peak_live_bytes(), 2 * 64 * 64 * 4);
    // Outputs live to the end.
    assert_eq!(p.resource("c").unwrap().last_use, p.steps.len());
}

#[test]
fn different_shapes_are_not_aliased() {
    let mut g = Graph::default();
    g.import("depth", wgpu::TextureFormat::Depth32Float, 64, 64, None);
    g.resource("a", F, fixed(64), None);
    g.resource("b", F, fixed(64), None);
    g.resource(
        "c",
        F,
        SizeRule::Reduced {
            of: "a".into(),
            shift: 1,
        },
        None,
    );
    g.node(node("make_a", &["depth"], &["a"]));
    g.node(node("make_b", &["a"], &["b"]));
    g.node(node("make_c", &["b"], &["c"]));
    let p = plan(&g, &["c"]).unwrap();
    let c = p.resource("c").unwrap();
    assert_eq!((c.width, c.height), (32, 32));
    assert_eq!(p.slots.len(), 3);
}

#[test]
fn reduced_sizes_round_up_and_reject_bad_rules() {
    let mut g = Graph::default();
    g.import("depth", wgpu::TextureFormat::Depth32Float, 1000, 37, None);
    g.resource(
        "half",
        F,
        SizeRule::Reduced {
            of: "depth".into(),
            shift: 1,
        },
        None,
    );
    g.resource(
        "tiny",
        F,
        SizeRule::Reduced {
            of: "depth".into(),
            shift: 9,
        },
        None,
    );
    g.resource(
        "bad",
        F,
        SizeRule::Reduced {
            of: "ghost".into(),
            shift: 1,
        },
        None,
    );
    g.node(node("h", &["depth"], &["half"]));
    g.node(node("t", &["depth"], &["tiny"]));
    g.node(node("b", &["depth"], &["bad"]));
    let p = plan(&g, &["half", "tiny"]).unwrap();
    let r = |n: &str| {
        let r = p.resource(n).unwrap();
        (r.width, r.height)
    };
    assert_eq!(r("half"), (500, 19));
    assert_eq!(r("tiny"), (2, 1));
    assert!(matches!(
        plan(&g, &["bad"]),
        Err(GraphError::BadSize { .. })
    ));
}

#[test]
fn block_sizes_round_up_per_axis() {
    let mut g = Graph::default();
    g.import("map", F, 1000, 37, None);
    for (name, x, y) in [
        ("rows", 256, 1),
        ("cols", 1, 256),
        ("both", 7, 5),
        ("zero", 0, 0),
    ] {
        g.resource(
            name,
            F,
            SizeRule::Blocks {
                of: "map".into(),
                x,
                y,
            },
            None,
        );
        g.node(node(name, &["map"], &[name]));
    }
    g.resource(
        "ghost_blocks",
        F,
        SizeRule::Blocks {
            of: "ghost".into(),
            x: 2,
            y: 2,
        },
        None,
    );
    g.node(node("g", &["map"], &["ghost_blocks"]));
    let p = plan(&g, &["rows", "cols", "both", "zero"]).unwrap();
    let r = |n: &str| {
        let r = p.resource(n).unwrap();
        (r.width, r.height)
    };
    assert_eq!(r("rows"), (4, 37));
    assert_eq!(r("cols"), (1000, 1));
    assert_eq!(r("both"), (143, 8));
    assert_eq!(r("zero"), (1, 1));
    assert_eq!(
        (block_count(1, 256), block_count(0, 4), block_count(9, 0)),
        (1, 1, 1)
    );
    assert!(matches!(
        plan(&g, &["ghost_blocks"]),
        Err(GraphError::BadSize { .. })
    ));
}

#[test]
fn text_and_dot_name_every_step() {
    let p = plan(&chain(), &["c"]).unwrap();
    let t = p.to_text(&["test light".into()], &[]);
    for n in ["make_a", "make_b", "make_c", "R32Float", "peak live"] {
        assert!(t.contains(n), "{n} missing from\n{t}");
    }
    let d = p.to_dot();
    assert!(
        d.starts_with("digraph") && d.contains("\"make_b\" -> \"b\""),
        "{d}"
    );
}

#[test]
fn unaliased_plan_gives_every_resource_its_own_texture() {
    let p = plan(&chain(), &["c"]).unwrap().unaliased();
    let slots: Vec<usize> = p.resources.iter().filter_map(|r| r.slot).collect();
    assert_eq!(slots, [0, 1, 2]);
    assert_eq!(p.slots.len(), 3);
}

/// A `Tiles` dispatch counts `y`-tall blocks in the GPU's layout and `cpu_y`-tall ones in a CPU
/// driver's; every other dispatch the same in both.
#[test]
fn tiles_are_taller_in_a_cpu_drivers_layout() {
    let size = |r: &str| (r == "map").then_some((100, 90));
    let tiles = Dispatch::Tiles {
        of: "map".into(),
        x: 24,
        y: 24,
        cpu_y: 40,
    };
    assert_eq!(tiles.groups(size, [8, 1, 1]), Some([5, 4, 1]));
    assert_eq!(
        tiles.groups_in_layout(size, [8, 1, 1], true),
        Some([5, 4, 1])
    );
    assert_eq!(
        tiles.groups_in_layout(size, [8, 1, 1], false),
        Some([5, 3, 1])
    );
    let blocks = Dispatch::Blocks {
        of: "map".into(),
        x: 24,
        y: 24,
    };
    assert_eq!(
        blocks.groups_in_layout(size, [8, 1, 1], false),
        Some([5, 4, 1])
    );
    let other = Dispatch::Tiles {
        of: "other".into(),
        x: 24,
        y: 24,
        cpu_y: 40,
    };
    assert_eq!(other.groups_in_layout(size, [8, 1, 1], false), None);
    let layered = Dispatch::Layers {
        base: Box::new(tiles),
        layers: 3,
    };
    assert_eq!(
        layered.groups_in_layout(size, [8, 1, 1], false),
        Some([5, 3, 3])
    );
    assert_eq!(layered.groups(size, [8, 1, 1]), Some([5, 4, 3]));
}
