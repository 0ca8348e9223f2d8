// Camera G-buffer: world position (w = 1 where covered) and normal (w = material index).
// The shading kernel reads these, so visibility can also be evaluated at arbitrary points.

struct Camera {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> camera: Camera;

// #import shared/vertex

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(v: VsIn) -> VsOut {
    var o: VsOut;
    o.clip = camera.view_proj * vec4<f32>(v.position, 1.0);
    o.world = v.position;
    o.normal = v.normal;
    o.material = v.material;
    return o;
}

struct FsOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
}

@fragment
fn fs_main(v: VsOut, @builtin(front_facing) front: bool) -> FsOut {
    // Two-sided surfaces: the normal faces the camera.
    let n = normalize(v.normal) * select(-1.0, 1.0, front);
    var o: FsOut;
    o.position = vec4<f32>(v.world, 1.0);
    o.normal = vec4<f32>(n, f32(v.material));
    return o;
}
