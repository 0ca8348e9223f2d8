//! The plan of each light holds exactly what it needs.

use super::*;

#[test]
fn plans_hold_exactly_what_each_light_needs() {
    use shadowgraph::{Light, LightKind, PcfKernel, Shadow, Storage, StorageFilter, Technique};
    let light = |technique| Light {
        kind: LightKind::Directional { extent: 5.0 },
        position: glam::Vec3::new(0.0, 10.0, 0.1),
        target: glam::Vec3::ZERO,
        near: 1.0,
        far: 20.0,
        size: 0.0,
        radiance: glam::Vec3::ONE,
        shadow_map: 64,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 1.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    };
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let pcf = Technique::Pcf {
        radius: 1,
        kernel: PcfKernel::Tent,
    };
    let vsm = Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: blur,
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    let msm = Technique::Msm {
        prefilter: StorageFilter {
            storage: Storage::F16,
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 0,
            },
        },
        hausdorff: false,
        moment_bias: 5e-4,
        bleed: 0.0,
    };
    let csm = Technique::Csm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: blur,
        },
        terms: 3,
        attenuation: 1.0,
        offset: 0.1,
        scale: 2.0,
    };
    let lights = [light(pcf), light(vsm), light(msm), light(csm), light(pcf)];
    let sp = shadowgraph::low_level::render::plan_lights(&lights).expect("plan");
    let kernels = |i: usize| -> Vec<&str> {
        sp.plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect()
    };
    // PCF reads the linear map: no encoding, no filter; a second PCF light adds only its own.
    // The encodings read the depth themselves: no `linearize` for them.
    assert_eq!(kernels(0), ["linearize"]);
    assert_eq!(kernels(4), ["linearize"]);
    assert_eq!(kernels(1), ["vsm_blur"]);
    assert_eq!(kernels(2), ["msm", "mips"]);
    // CSM with 3 terms: two basis maps, written by one dispatch and each blurred.
    let mut csm_kernels = kernels(3);
    csm_kernels.sort();
    assert_eq!(csm_kernels, ["blur", "blur", "blur", "blur", "csm"]);
    assert_eq!(sp.shade_inputs[3].maps.len(), 2);
    assert_eq!(sp.plan.steps.len(), 1 + 1 + 2 + 5 + 1);
}
