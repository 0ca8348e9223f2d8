//! The host's side of the plug-in tests: a depth pass of its own, into a texture it owns.

use shadowgraph::LightParams;
use shadowgraph::low_level::gpu::{Gpu, submit_and_wait};
use shadowgraph::low_level::wgsl_mirrors::Vertex;
use wgpu::util::DeviceExt;

/// The host's own depth pass: its own shader and pipeline, the light's matrices and slope
/// bias, into a texture the host owns.
const HOST_DEPTH: &str = "
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
@vertex
fn vs_main(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view_proj * vec4<f32>(p, 1.0);
}
";

pub fn host_depth(
    g: &Gpu,
    vertices: &[Vertex],
    light: &LightParams,
    slope_bias: f32,
    size: u32,
) -> wgpu::Texture {
    let vp = light.projection * light.view;
    host_depth_views(
        g,
        vertices,
        &[(vp, [0, 0, size, size])],
        slope_bias,
        (size, size),
    )
}

/// [`host_depth`] drawing once per view, each with its own matrix, viewport and scissor (a
/// point light's faces, `Prefilter::point_views`), into a `width × height` texture.
pub fn host_depth_views(
    g: &Gpu,
    vertices: &[Vertex],
    views: &[(glam::Mat4, [u32; 4])],
    slope_bias: f32,
    (width, height): (u32, u32),
) -> wgpu::Texture {
    let d = &g.device;
    let depth = d.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.depth"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host.depth"),
        source: wgpu::ShaderSource::Wgsl(HOST_DEPTH.into()),
    });
    let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host.depth"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: wgpu::DepthBiasState {
                constant: 0,
                slope_scale: slope_bias,
                clamp: 0.0,
            },
        }),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    });
    let groups: Vec<(wgpu::BindGroup, [u32; 4])> = views
        .iter()
        .map(|(vp, viewport)| {
            let ubuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("host.view_proj"),
                contents: bytemuck::cast_slice(&vp.to_cols_array()),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("host.depth"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: ubuf.as_entire_binding(),
                }],
            });
            (bg, *viewport)
        })
        .collect();
    let vbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host.vertices"),
        contents: bytemuck::cast_slice(vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let view = depth.create_view(&Default::default());
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host.depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_vertex_buffer(0, vbuf.slice(..));
        for (bg, [x, y, w, h]) in &groups {
            pass.set_viewport(*x as f32, *y as f32, *w as f32, *h as f32, 0.0, 1.0);
            pass.set_scissor_rect(*x, *y, *w, *h);
            pass.set_bind_group(0, bg, &[]);
            pass.draw(0..vertices.len() as u32, 0..1);
        }
    }
    submit_and_wait(d, &g.queue, enc, "host depth").expect("host depth pass");
    depth
}
