//! Stages: the shader programs a frame draws with, described by the modes
//! and compiled here without knowing what they compute.
//!
//! A [`StageDesc`] names a WGSL file (put behind `shaders/common.wgsl`, the
//! functions every stage shares: the piece key and the finiteness test), the
//! layout of its vertex (the Rust mirror is a [`super::GpuVertex`]), and the
//! bindings of its group 0, in binding order. Every stage has the entry
//! points `vs_main`, `fs_main` (composite: premultiplied colour, "over"
//! blending) and `fs_count` (coverage counting, additive), and writes its
//! piece's key as depth ([`super::piece_depth`]); the pipeline for an
//! accumulation format and a [`DrawKind`] follows from that alone:
//! - `Composite`: `fs_main`, blend `src + (1 - src.a) dst`, depth test less
//!   with write (each piece colours a pixel at most once);
//! - `CountPieces`: `fs_count`, additive, the same depth test;
//! - `CountTriangles`: `fs_count`, additive, no depth test.
//!
//! The device compiles a stage once ([`StageCache`], kept by the
//! [`Context`]) and its pipelines on first use. [`Context::bind_stage`]
//! binds a stage to one frame's resources (uniform bytes, tables, storage
//! bytes), giving the [`Stage`] that [`super::Frame::push_triangles`]
//! draws with.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

use wgpu::util::DeviceExt;

use super::device::Context;
use super::frame::DrawKind;
use super::table::Table;
use super::{AccumFormat, GpuError};

/// WGSL functions shared by every stage (`shaders/common.wgsl`).
pub const COMMON_WGSL: &str = include_str!("../../shaders/common.wgsl");

/// The full source of a stage: the common functions, then its own file.
pub fn stage_source(wgsl: &str) -> String {
    format!("{COMMON_WGSL}\n{wgsl}")
}

/// The depth format holding the piece keys.
pub(crate) const PIECE_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What one binding of a stage's group 0 is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    /// A uniform buffer (vertex and fragment stages).
    Uniform,
    /// A lookup table ([`Table`]): a read-only storage buffer of `f32` or
    /// `vec4<f32>` texels (fragment stage).
    Table,
    /// A read-only storage buffer (fragment stage).
    Storage,
}

/// A shader program as a mode describes it; see the module docs.
#[derive(Debug)]
pub struct StageDesc {
    /// File name under `shaders/` (the cache key and the label).
    pub name: &'static str,
    /// The fragment entry point that composites (`fs_main` unless the stage
    /// gathers files that define one of their own, as the isosurface stages
    /// do).
    pub fragment: &'static str,
    /// The file's WGSL (without `shaders/common.wgsl`).
    pub wgsl: &'static str,
    /// Layout of the vertex buffer (`VertexIn`).
    pub vertex: wgpu::VertexBufferLayout<'static>,
    /// Bindings of group 0, binding `k` at index `k`.
    pub bindings: &'static [Binding],
    /// Values of the WGSL's pipeline-overridable constants (`override`
    /// declarations) by name, for this stage's pipelines; those not named
    /// keep their defaults. One WGSL can so make several stages (each with
    /// its own `name`, the cache key), the compiler dropping the code a
    /// constant switches off.
    pub constants: &'static [(&'static str, f64)],
}

/// One resource bound to a stage for a frame, in [`StageDesc::bindings`]
/// order.
#[derive(Clone, Copy, Debug)]
pub enum Resource<'a> {
    /// Bytes of a uniform struct (`#[repr(C)]`, WGSL layout).
    Uniform(&'a [u8]),
    /// A lookup table.
    Table(&'a Table),
    /// Bytes of a read-only storage buffer.
    Storage(&'a [u8]),
}

/// A stage compiled on one device: module, layouts, and its pipelines by
/// accumulation format (f16, f32) and [`DrawKind`].
pub(crate) struct StageCache {
    desc: &'static StageDesc,
    module: wgpu::ShaderModule,
    bind_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: [[OnceLock<wgpu::RenderPipeline>; 3]; 2],
}

/// A stage bound to one frame's resources (cheap to clone).
#[derive(Clone)]
pub struct Stage {
    /// Unique per binding: a frame flushes its batch when the stage changes.
    pub(crate) id: u64,
    pub(crate) cache: Arc<StageCache>,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl std::fmt::Debug for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Stage({}, #{})", self.cache.desc.name, self.id)
    }
}

impl Stage {
    /// The description it was made from.
    pub fn desc(&self) -> &'static StageDesc {
        self.cache.desc
    }

    /// The pipeline for a resolved accumulation format and draw kind.
    pub(crate) fn pipeline(
        &self,
        ctx: &Context,
        format: AccumFormat,
        kind: DrawKind,
    ) -> &wgpu::RenderPipeline {
        self.cache.pipeline(ctx, format, kind)
    }
}

static NEXT_STAGE_ID: AtomicU64 = AtomicU64::new(1);

impl Context {
    /// Compiles `desc` (once per device) and binds it to `resources`.
    pub fn bind_stage(
        &self,
        desc: &'static StageDesc,
        resources: &[Resource],
    ) -> Result<Stage, GpuError> {
        if resources.len() != desc.bindings.len() {
            return Err(GpuError::BadOption(
                "a stage's resources must match its bindings",
            ));
        }
        let cache = self.stage_cache(desc);
        let mut buffers = Vec::new();
        for (k, (b, r)) in desc.bindings.iter().zip(resources).enumerate() {
            let usage = match (b, r) {
                (Binding::Uniform, Resource::Uniform(_)) => wgpu::BufferUsages::UNIFORM,
                (Binding::Storage, Resource::Storage(_)) => wgpu::BufferUsages::STORAGE,
                (Binding::Table, Resource::Table(_)) => continue,
                _ => {
                    return Err(GpuError::BadOption(
                        "a stage's resource does not match its binding",
                    ))
                }
            };
            let bytes = match r {
                Resource::Uniform(b) | Resource::Storage(b) => *b,
                Resource::Table(_) => &[],
            };
            buffers.push((k, self.buffer_with(desc.name, bytes, usage)));
        }
        let entries: Vec<wgpu::BindGroupEntry> = resources
            .iter()
            .enumerate()
            .map(|(k, r)| wgpu::BindGroupEntry {
                binding: k as u32,
                resource: match r {
                    Resource::Table(t) => t.buffer().raw().as_entire_binding(),
                    _ => buffers
                        .iter()
                        .find(|(i, _)| *i == k)
                        .map(|(_, b)| b.as_entire_binding())
                        .unwrap_or_else(|| unreachable!("made above")),
                },
            })
            .collect();
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(desc.name),
            layout: &cache.bind_layout,
            entries: &entries,
        });
        self.check()?;
        Ok(Stage {
            id: NEXT_STAGE_ID.fetch_add(1, Ordering::Relaxed),
            cache,
            bind_group,
        })
    }

    /// The compiled stage of `desc` (compiled on first use).
    fn stage_cache(&self, desc: &'static StageDesc) -> Arc<StageCache> {
        if let Some(c) = self
            .stages
            .lock()
            .ok()
            .and_then(|m| m.get(desc.name).cloned())
        {
            return c;
        }
        let entries: Vec<wgpu::BindGroupLayoutEntry> = desc
            .bindings
            .iter()
            .enumerate()
            .map(|(k, b)| wgpu::BindGroupLayoutEntry {
                binding: k as u32,
                visibility: match b {
                    Binding::Uniform => wgpu::ShaderStages::VERTEX_FRAGMENT,
                    _ => wgpu::ShaderStages::FRAGMENT,
                },
                ty: match b {
                    Binding::Uniform => wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    Binding::Storage | Binding::Table => wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                },
                count: None,
            })
            .collect();
        let (bind_layout, pipeline_layout, module) = self.program(desc.name, &entries, desc.wgsl);
        let cache = Arc::new(StageCache {
            desc,
            module,
            bind_layout,
            pipeline_layout,
            pipelines: Default::default(),
        });
        if let Ok(mut m) = self.stages.lock() {
            m.insert(desc.name, cache.clone());
        }
        cache
    }
}

impl Context {
    /// A buffer of `usage` initialised with `bytes`, padded with zeros to
    /// at least 16 bytes and a multiple of 4 (wgpu refuses empty buffers;
    /// a storage array may be empty).
    pub(super) fn buffer_with(
        &self,
        label: &str,
        bytes: &[u8],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let mut v = bytes.to_vec();
        v.resize(v.len().max(16).next_multiple_of(4), 0);
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &v,
                usage,
            })
    }

    /// What a stage or a kernel compiles once: the layout of its one bind
    /// group of `entries`, the pipeline layout of that group, and its shader
    /// module (`wgsl` behind `shaders/common.wgsl`).
    pub(super) fn program(
        &self,
        label: &str,
        entries: &[wgpu::BindGroupLayoutEntry],
        wgsl: &str,
    ) -> (
        wgpu::BindGroupLayout,
        wgpu::PipelineLayout,
        wgpu::ShaderModule,
    ) {
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(stage_source(wgsl).into()),
            });
        (layout, pipeline_layout, module)
    }
}

impl StageCache {
    fn pipeline(
        &self,
        ctx: &Context,
        format: AccumFormat,
        kind: DrawKind,
    ) -> &wgpu::RenderPipeline {
        let (row, tf) = match format {
            AccumFormat::F32 => (1, wgpu::TextureFormat::Rgba32Float),
            _ => (0, wgpu::TextureFormat::Rgba16Float),
        };
        self.pipelines[row][kind as usize].get_or_init(|| self.build(ctx, tf, kind))
    }

    fn build(
        &self,
        ctx: &Context,
        format: wgpu::TextureFormat,
        kind: DrawKind,
    ) -> wgpu::RenderPipeline {
        // Premultiplied "over", back to front: dst = src + (1 - src.a) dst;
        // counting adds.
        let (blend, entry) = match kind {
            DrawKind::Composite => (wgpu::BlendComponent::OVER, self.desc.fragment),
            DrawKind::CountPieces | DrawKind::CountTriangles => (
                wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
                "fs_count",
            ),
        };
        // One colouring per piece and pixel: the fragment's depth is its
        // piece's key, decreasing in drawing order (`piece_depth`).
        let once_per_piece = kind != DrawKind::CountTriangles;
        ctx.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(self.desc.name),
                layout: Some(&self.pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &self.module,
                    entry_point: Some("vs_main"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: self.desc.constants,
                        ..Default::default()
                    },
                    buffers: &[Some(self.desc.vertex.clone())],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: PIECE_DEPTH_FORMAT,
                    depth_write_enabled: Some(once_per_piece),
                    depth_compare: Some(if once_per_piece {
                        wgpu::CompareFunction::Less
                    } else {
                        wgpu::CompareFunction::Always
                    }),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &self.module,
                    entry_point: Some(entry),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: self.desc.constants,
                        ..Default::default()
                    },
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: Some(wgpu::BlendState {
                            color: blend,
                            alpha: blend,
                        }),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
    }
}
