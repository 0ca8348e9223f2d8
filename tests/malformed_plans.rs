//! `Plan`'s fields are public, so a host may build or edit one by hand: `Executor::record` must
//! answer a malformed plan with a typed error, never a panic (it used to index hash maps, slices
//! and `layouts[0]` unchecked).

mod common;

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use rand::Rng;
use shadowgraph::low_level::exec::Executor;
use shadowgraph::low_level::graph::{Dispatch, Plan};
use shadowgraph::low_level::kernels::KernelId;
use shadowgraph::low_level::render::plan_lights;
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique;
use shadowgraph::{Error, GraphError};

/// A plan with a blur, a mip chain and a summed-area table: every dispatch kind.
fn valid() -> (Plan, Scene) {
    let mut text = "[output]\nwidth = 8\nheight = 8\n[camera]\nposition = [0.0, 1.0, 3.0]\n\
                    target = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n"
        .to_string();
    for t in [
        "technique = \"vsm\"\nfilter = \"mips\"\nfilter_width = 2.0",
        "technique = \"msm\"\nfilter = \"sat\"",
        "technique = \"vsm\"",
    ] {
        text += &format!(
            "[[light]]\nkind = \"directional\"\nposition = [0.0, 5.0, 1.0]\n\
             target = [0.0, 0.0, 0.0]\nextent = 2.0\nshadow_map = 32\n[light.shadow]\n{t}\n"
        );
    }
    text += "[[object]]\nshape = \"box\"\nsize = 1.0\n";
    let s = Scene::parse(Path::new("plans.toml"), &text).unwrap();
    let sp = plan_lights(&s.lights).unwrap();
    (sp.plan, s)
}

fn depth_imports(device: &wgpu::Device, s: &Scene) -> HashMap<String, wgpu::Texture> {
    s.lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let t = device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: l.shadow_map,
                    height: l.shadow_map,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Depth32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            });
            (technique::depth_name(i), t)
        })
        .collect()
}

/// Records `plan`; a panic is reported as `Err("panic: …")`.
fn record(
    g: &shadowgraph::low_level::gpu::Gpu,
    ex: &mut Executor,
    plan: &Plan,
    imports: &HashMap<String, wgpu::Texture>,
) -> Result<shadowgraph::Result<()>, String> {
    catch_unwind(AssertUnwindSafe(|| {
        let mut enc = g.device.create_command_encoder(&Default::default());
        ex.record(&g.device, &mut enc, plan, imports, None)
            .map(|_| ())
    }))
    .map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// Named malformations, each a typed error.
#[test]
fn malformed_plans_are_typed_errors() {
    let g = common::gpu();
    let (plan, s) = valid();
    let imports = depth_imports(&g.device, &s);
    let mut ex = Executor::new();
    record(&g, &mut ex, &plan, &imports)
        .unwrap()
        .expect("the valid plan records");
    let mip = plan
        .steps
        .iter()
        .position(|st| matches!(st.node.dispatch, Dispatch::Several(_)))
        .unwrap();
    let blocks = plan
        .steps
        .iter()
        .position(|st| {
            matches!(
                st.node.dispatch,
                Dispatch::Blocks { .. } | Dispatch::Tiles { .. } | Dispatch::Redesigned { .. }
            )
        })
        .unwrap();
    type Edit = Box<dyn Fn(&mut Plan)>;
    let edits: Vec<(&str, Edit)> = vec![
        (
            "slot out of range",
            Box::new(|p| {
                p.resources
                    .iter_mut()
                    .find(|r| r.slot.is_some())
                    .unwrap()
                    .slot = Some(999)
            }),
        ),
        ("no slots", Box::new(|p| p.slots.clear())),
        ("zero-sized slot", Box::new(|p| p.slots[0].width = 0)),
        ("zero mip levels", Box::new(|p| p.slots[0].mips = 0)),
        (
            "depth format slot",
            Box::new(|p| p.slots[0].format = wgpu::TextureFormat::Depth32Float),
        ),
        ("slot of another size", Box::new(|p| p.slots[0].height += 1)),
        (
            "unknown input",
            Box::new(|p| p.steps[0].node.inputs[0].1 = "nothing".into()),
        ),
        (
            "unknown output",
            Box::new(|p| p.steps[1].node.outputs[0].1 = "nothing".into()),
        ),
        (
            "resource removed",
            Box::new(|p| {
                p.resources.pop();
            }),
        ),
        (
            "duplicate resource",
            Box::new(|p| {
                let r = p.resources[1].clone();
                p.resources.push(r);
            }),
        ),
        (
            "unknown output name",
            Box::new(|p| p.outputs.push("nothing".into())),
        ),
        (
            "mip chain without params",
            Box::new(move |p| p.steps[mip].node.params.clear()),
        ),
        (
            "mip chain without src",
            Box::new(move |p| p.steps[mip].node.inputs.clear()),
        ),
        (
            "blocks over nothing",
            Box::new(move |p| {
                p.steps[blocks].node.dispatch = Dispatch::Blocks {
                    of: "nothing".into(),
                    x: 1,
                    y: 1,
                }
            }),
        ),
        (
            "tiles over nothing",
            Box::new(move |p| {
                p.steps[blocks].node.dispatch = Dispatch::Tiles {
                    of: "nothing".into(),
                    x: 16,
                    y: 16,
                    cpu_y: 32,
                }
            }),
        ),
        (
            "tiles 0 tall on a CPU driver",
            Box::new(move |p| {
                let of = p.resources[0].resource.name.clone();
                p.steps[blocks].node.dispatch = Dispatch::Tiles {
                    of,
                    x: 16,
                    y: 16,
                    cpu_y: 0,
                }
            }),
        ),
        (
            "lines with 0 per workgroup",
            Box::new(|p| {
                p.steps[0].node.dispatch = Dispatch::Lines {
                    of: p.resources[0].resource.name.clone(),
                    per_group: 0,
                }
            }),
        ),
        (
            "kernel with other bindings",
            Box::new(|p| p.steps[0].node.kernel = KernelId::SatCarries),
        ),
    ];
    for (what, edit) in edits {
        let mut p = plan.clone();
        edit(&mut p);
        match record(&g, &mut ex, &p, &imports) {
            Err(panic) => panic!("{what}: record panicked: {panic}"),
            Ok(Ok(())) => panic!("{what}: a malformed plan recorded"),
            Ok(Err(e)) => {
                let shown = e.to_string();
                assert!(!shown.contains('\n'), "{what}: {shown}");
                if what != "kernel with other bindings" {
                    assert!(
                        matches!(e, Error::Graph(GraphError::BadPlan(_))),
                        "{what}: {e:?}"
                    );
                }
            }
        }
    }
    // A missing import is named too.
    let shown = record(&g, &mut ex, &plan, &HashMap::new())
        .unwrap()
        .expect_err("no imports")
        .to_string();
    assert!(shown.contains("light0.depth"), "{shown}");
}

/// Random edits of the valid plan (slots, sizes, names, dispatches, parameters): `record` never
/// panics, and whatever it records submits without panicking either.
#[test]
fn randomly_edited_plans_never_panic() {
    let g = common::gpu();
    let (plan, s) = valid();
    let imports = depth_imports(&g.device, &s);
    let mut ex = Executor::new();
    let mut rng = common::rng(12);
    let names: Vec<String> = plan
        .resources
        .iter()
        .map(|r| r.resource.name.clone())
        .collect();
    let mut recorded = 0;
    for case in 0..300 {
        let mut p = plan.clone();
        for _ in 0..rng.random_range(1..4) {
            let st = rng.random_range(0..p.steps.len());
            let name = names[rng.random_range(0..names.len())].clone();
            let (slots, steps) = (p.slots.len(), p.steps.len());
            match rng.random_range(0..9) {
                0 => p.slots.swap(0, rng.random_range(0..slots)),
                1 => {
                    let r = rng.random_range(0..p.resources.len());
                    p.resources[r].slot = Some(rng.random_range(0..p.slots.len() + 2));
                }
                2 => p.slots[rng.random_range(0..slots)].mips = rng.random_range(0..20),
                3 => p.steps[st].node.inputs.push(("src".into(), name)),
                4 => p.steps[st].node.dispatch = Dispatch::Texels(name),
                5 => p.steps[st].node.params.truncate(rng.random_range(0..8)),
                6 => p.steps.swap(st, rng.random_range(0..steps)),
                7 => {
                    let r = rng.random_range(0..p.resources.len());
                    p.resources[r].width = rng.random_range(0..70);
                }
                _ => {
                    p.steps[st].node.dispatch =
                        Dispatch::Groups([rng.random_range(0..70_000), 1, 1])
                }
            }
        }
        match record(&g, &mut ex, &p, &imports) {
            Err(panic) => panic!("case {case}: record panicked: {panic}"),
            Ok(Ok(())) => recorded += 1,
            Ok(Err(e)) => assert!(!e.to_string().contains('\n'), "case {case}: {e}"),
        }
        // Whatever was recorded and not submitted is dropped; errors from it are the device's.
        let _ = shadowgraph::low_level::gpu::take_uncaptured(&g.device);
    }
    assert!(recorded < 300, "no edit was refused");
}
