//! The GPU context: instance, adapter, device, the exponential table and the
//! exact-mode pipelines.
//!
//! Adapter choice: `Backends::all().with_env()` (so `WGPU_BACKEND=vulkan|gl`
//! narrows it) unless [`GpuOptions::backend`] names one; `cpu_adapter` sets
//! `force_fallback_adapter`. No adapter is [`GpuError::NoAdapter`], whose
//! message names the apt packages. The device asks for the adapter's own
//! limits (large scenes need more than the defaults) and for
//! `FLOAT32_BLENDABLE` when the adapter has it.
//!
//! wgpu reports validation errors and device loss through callbacks; the
//! default uncaptured-error handler panics. Here both callbacks record the
//! message, and [`Context::check`] turns it into a [`GpuError`] at the next
//! synchronisation point, so no GPU failure panics.

use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use super::exptable::{ExpTable, TABLE_N};
use super::frame::{DrawKind, PIECE_DEPTH_FORMAT};
use super::vertex::ExactVertex;
use super::{AccumFormat, GpuError, GpuOptions};

/// How long one wait for the GPU may take before it is reported as a timeout
/// (one batch is bounded in size, so this is very generous).
const WAIT_LIMIT: Duration = Duration::from_secs(300);

/// What was opened, for reports and `--stats`.
#[derive(Clone, Debug, PartialEq)]
pub struct ContextInfo {
    pub adapter: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    /// The format `AccumFormat::Auto` resolves to on this device.
    pub auto_format: AccumFormat,
}

impl std::fmt::Display for ContextInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ({}, {}, {}), accumulation {}",
            self.adapter, self.backend, self.device_type, self.driver, self.auto_format
        )
    }
}

/// An open GPU device with the exact-mode resources.
pub struct Context {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: ContextInfo,
    limits: wgpu::Limits,
    f32_blendable: bool,
    pub(crate) table_view: wgpu::TextureView,
    pub(crate) bind_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    shader: wgpu::ShaderModule,
    /// Pipelines by accumulation format (f16, f32) and [`DrawKind`].
    pipelines: [[OnceLock<wgpu::RenderPipeline>; 3]; 2],
    errors: Arc<Mutex<Vec<String>>>,
    lost: Arc<Mutex<Option<String>>>,
}

/// A [`Context`] being opened on another thread ([`Context::spawn`]):
/// opening a device (and compiling the pipeline, which on a software
/// adapter is LLVM work) takes a few tenths of a second that a caller can
/// overlap with reading and sorting a mesh.
#[derive(Debug)]
pub struct PendingContext {
    opts: GpuOptions,
    handle: std::thread::JoinHandle<Result<Context, GpuError>>,
}

impl PendingContext {
    /// The options it was opened with.
    pub fn options(&self) -> &GpuOptions {
        &self.opts
    }

    /// Waits for the context.
    pub fn wait(self) -> Result<Context, GpuError> {
        self.handle
            .join()
            .unwrap_or_else(|_| Err(GpuError::Wgpu("opening the device panicked".into())))
    }
}

impl Context {
    /// Starts opening a context on a new thread.
    pub fn spawn(opts: &GpuOptions) -> PendingContext {
        let o = *opts;
        PendingContext {
            opts: o,
            handle: std::thread::spawn(move || Context::new(&o)),
        }
    }

    /// Opens a headless device (see the module docs).
    pub fn new(opts: &GpuOptions) -> Result<Context, GpuError> {
        pollster::block_on(Self::new_async(opts))
    }

    async fn new_async(opts: &GpuOptions) -> Result<Context, GpuError> {
        let backends = match opts.backend {
            Some(b) => b.backends(),
            None => wgpu::Backends::all().with_env(),
        };
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle().with_env();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: opts.cpu_adapter,
                compatible_surface: None,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|_| GpuError::NoAdapter {
                backends: format!("{backends:?}"),
                fallback: if opts.cpu_adapter {
                    ", software adapter only"
                } else {
                    ""
                },
            })?;
        let f32_blendable = adapter
            .features()
            .contains(wgpu::Features::FLOAT32_BLENDABLE);
        let required_features = if f32_blendable {
            wgpu::Features::FLOAT32_BLENDABLE
        } else {
            wgpu::Features::empty()
        };
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("zoovr"),
                required_features,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::RequestDevice(e.to_string()))?;

        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let sink = lost.clone();
        device.set_device_lost_callback(move |reason, msg| {
            if let Ok(mut v) = sink.lock() {
                *v = Some(format!("{reason:?}: {msg}"));
            }
        });

        let ai = adapter.get_info();
        let rt_ok = adapter
            .get_texture_format_features(wgpu::TextureFormat::Rgba32Float)
            .allowed_usages
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT);
        let f32_blendable = f32_blendable && rt_ok;
        let info = ContextInfo {
            adapter: ai.name.clone(),
            backend: format!("{:?}", ai.backend),
            device_type: format!("{:?}", ai.device_type),
            driver: format!("{} {}", ai.driver, ai.driver_info)
                .trim()
                .to_string(),
            auto_format: if f32_blendable {
                AccumFormat::F32
            } else {
                AccumFormat::F16
            },
        };

        let table_view = upload_table(&device, &queue, &ExpTable::new(TABLE_N));
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("exact bind group"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("exact"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("exact.wgsl"),
            source: wgpu::ShaderSource::Wgsl(super::EXACT_WGSL.into()),
        });
        let ctx = Context {
            device,
            queue,
            info,
            limits,
            f32_blendable,
            table_view,
            bind_layout,
            pipeline_layout,
            shader,
            pipelines: Default::default(),
            errors,
            lost,
        };
        ctx.check()?;
        Ok(ctx)
    }

    /// Adapter, backend and the automatic accumulation format.
    pub fn info(&self) -> &ContextInfo {
        &self.info
    }

    /// The device limits in force (the adapter's).
    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
    }

    /// Resolves `Auto` and checks that a forced format works here.
    pub fn resolve_format(&self, format: AccumFormat) -> Result<AccumFormat, GpuError> {
        match format {
            AccumFormat::Auto => Ok(self.info.auto_format),
            AccumFormat::F16 => Ok(AccumFormat::F16),
            AccumFormat::F32 if self.f32_blendable => Ok(AccumFormat::F32),
            AccumFormat::F32 => Err(GpuError::FormatUnsupported {
                format,
                reason: "Rgba32Float is not blendable (no FLOAT32_BLENDABLE) or not renderable",
            }),
        }
    }

    /// The exact pipeline for a resolved format and draw kind (built on
    /// first use).
    pub(crate) fn pipeline(&self, format: AccumFormat, kind: DrawKind) -> &wgpu::RenderPipeline {
        let (row, tf) = match format {
            AccumFormat::F32 => (1, wgpu::TextureFormat::Rgba32Float),
            _ => (0, wgpu::TextureFormat::Rgba16Float),
        };
        self.pipelines[row][kind as usize].get_or_init(|| self.build_pipeline(tf, kind))
    }

    fn build_pipeline(&self, format: wgpu::TextureFormat, kind: DrawKind) -> wgpu::RenderPipeline {
        // Premultiplied "over", back to front: dst = src + (1 - src.a) dst;
        // counting adds.
        let (blend, entry) = match kind {
            DrawKind::Composite => (wgpu::BlendComponent::OVER, "fs_main"),
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
        self.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("exact"),
                layout: Some(&self.pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &self.shader,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(ExactVertex::LAYOUT)],
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
                    module: &self.shader,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
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

    /// Returns the first error recorded by wgpu's callbacks, if any.
    pub fn check(&self) -> Result<(), GpuError> {
        if let Some(msg) = self.lost.lock().ok().and_then(|v| v.clone()) {
            return Err(GpuError::DeviceLost(msg));
        }
        if let Some(msg) = self.errors.lock().ok().and_then(|v| v.first().cloned()) {
            return Err(GpuError::Wgpu(msg));
        }
        Ok(())
    }

    /// Waits until `index` (or all work) is done; loops over `Timeout`, which
    /// the GL backend returns for long submissions.
    pub(crate) fn wait(&self, index: Option<wgpu::SubmissionIndex>) -> Result<(), GpuError> {
        let start = Instant::now();
        loop {
            self.check()?;
            let r = self.device.poll(wgpu::PollType::Wait {
                submission_index: index.clone(),
                timeout: Some(Duration::from_secs(1)),
            });
            match r {
                Ok(_) => return self.check(),
                Err(wgpu::PollError::Timeout) if start.elapsed() < WAIT_LIMIT => continue,
                Err(wgpu::PollError::Timeout) => {
                    return Err(GpuError::Timeout(WAIT_LIMIT.as_secs()));
                }
                Err(e) => return Err(GpuError::Wgpu(e.to_string())),
            }
        }
    }
}

fn upload_table(device: &wgpu::Device, queue: &wgpu::Queue, table: &ExpTable) -> wgpu::TextureView {
    let n = table.n();
    let size = wgpu::Extent3d {
        width: n,
        height: n,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("exp table"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytemuck::cast_slice(table.data()),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * n),
            rows_per_image: Some(n),
        },
        size,
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn destroyed_device_gives_errors_not_panics() {
        let ctx = match Context::new(&GpuOptions::default()) {
            Ok(c) => c,
            Err(e @ GpuError::NoAdapter { .. }) => {
                eprintln!("skipping: {e}");
                return;
            }
            Err(e) => panic!("{e}"),
        };
        let mut frame = ctx.begin_frame(8, 8, AccumFormat::Auto).unwrap();
        let v = ExactVertex::new([0.0, 0.0, 0.5, 1.0], 1.0, 1.0, [1.0; 3]);
        let v2 = ExactVertex::new([1.0, 0.0, 0.5, 1.0], 1.0, 1.0, [1.0; 3]);
        let v3 = ExactVertex::new([0.0, 1.0, 0.5, 1.0], 1.0, 1.0, [1.0; 3]);
        frame.push_triangles(&[v, v2, v3], &[0, 1, 2]).unwrap();
        ctx.device.destroy();
        let r = frame.finish();
        assert!(
            matches!(r, Err(GpuError::DeviceLost(_) | GpuError::Wgpu(_))),
            "{:?}",
            r.map(|_| ())
        );
        assert!(ctx.check().is_err());
        assert!(ctx.begin_frame(8, 8, AccumFormat::Auto).is_err());
    }
}
