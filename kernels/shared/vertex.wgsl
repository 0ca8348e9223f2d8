// The scene vertex as uploaded (import-only module).

// Keep in sync with `Vertex` in src/wgsl_mirrors.rs.
struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) material: u32,
}
