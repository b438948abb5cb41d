//! Compute passes: a small generic facility that runs one WGSL compute
//! entry point over a grid of workgroups, reading uniform and storage
//! buffers and writing one or more storage buffers ([`GpuBuffer`]). It
//! knows no mode: a caller brings its [`ComputeDesc`] (WGSL put behind
//! `shaders/common.wgsl`, like the stages), its resources in binding order,
//! and the workgroup counts.
//!
//! How it works:
//! 1. [`Context::dispatch`] compiles the kernel once per device (kept with
//!    [`Context::resource`] under the kernel's name), makes the buffers of
//!    the uniform and read-only storage resources, binds them with the
//!    caller's [`GpuBuffer`]s (read-write storage) as group 0, and submits
//!    one compute pass. It does not wait: later work on the queue (a copy,
//!    a draw) sees its results in submission order.
//! 2. A [`GpuBuffer`] outlives dispatches (a table build rewrites only the
//!    texels that changed), is a [`super::Table`]'s storage, which stages
//!    then read, and can be read back ([`GpuBuffer::read`], tests and
//!    twins).

use std::sync::{Arc, Mutex};

use super::device::Context;
use super::GpuError;

/// What one binding of a kernel's group 0 is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ComputeBinding {
    /// `var<uniform>`.
    Uniform,
    /// `var<storage, read>`.
    Storage,
    /// `var<storage, read_write>` ([`GpuBuffer`]).
    StorageRw,
}

/// A compute kernel as a caller describes it.
#[derive(Debug)]
pub struct ComputeDesc {
    /// Its name (the cache key and the label; unique per kernel).
    pub name: &'static str,
    /// Its WGSL (without `shaders/common.wgsl`).
    pub wgsl: &'static str,
    /// The entry point.
    pub entry: &'static str,
    /// Bindings of group 0, binding `k` at index `k`.
    pub bindings: &'static [ComputeBinding],
}

/// One resource of a dispatch, in [`ComputeDesc::bindings`] order.
#[derive(Clone, Copy, Debug)]
pub enum ComputeResource<'a> {
    Uniform(&'a [u8]),
    Storage(&'a [u8]),
    Buffer(&'a GpuBuffer),
}

/// A storage buffer a kernel writes, kept between dispatches.
#[derive(Debug)]
pub struct GpuBuffer {
    buffer: wgpu::Buffer,
    len: u64,
}

/// A kernel compiled on one device.
struct Kernel {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl GpuBuffer {
    /// A zeroed buffer of `len` bytes (a multiple of 4, at least 16).
    pub fn new(ctx: &Context, label: &str, len: u64) -> Result<GpuBuffer, GpuError> {
        let len = len.max(16).next_multiple_of(4);
        if len > ctx.limits().max_storage_buffer_binding_size || len > ctx.limits().max_buffer_size
        {
            return Err(GpuError::BadOption(
                "a compute buffer is larger than this adapter's storage buffers",
            ));
        }
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: len,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.check()?;
        Ok(GpuBuffer { buffer, len })
    }

    /// Writes `bytes` at the start of the buffer (through the queue: later
    /// work sees them in submission order).
    pub fn write(&self, ctx: &Context, bytes: &[u8]) {
        ctx.queue.write_buffer(&self.buffer, 0, bytes);
    }

    /// The wgpu buffer (to bind it read-only in a stage).
    pub(crate) fn raw(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Its size in bytes.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Whether it holds no bytes (never: buffers have at least 16).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Reads the whole buffer back (waits for the queue).
    pub fn read(&self, ctx: &Context) -> Result<Vec<u8>, GpuError> {
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("compute readback"),
            size: self.len,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &staging, 0, self.len);
        let index = ctx.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let status: Arc<Mutex<Option<Result<(), String>>>> = Arc::new(Mutex::new(None));
        let sink = status.clone();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            if let Ok(mut s) = sink.lock() {
                *s = Some(r.map_err(|e| e.to_string()));
            }
        });
        ctx.wait(Some(index))?;
        for _ in 0..100 {
            match status.lock().ok().and_then(|s| s.clone()) {
                Some(Ok(())) => {
                    let out = slice
                        .get_mapped_range()
                        .map_err(|e| GpuError::Readback(e.to_string()))?
                        .to_vec();
                    staging.unmap();
                    return Ok(out);
                }
                Some(Err(e)) => return Err(GpuError::Readback(e)),
                None => ctx.wait(None)?,
            }
        }
        Err(GpuError::Readback("buffer was never mapped".into()))
    }
}

impl Context {
    /// Runs `desc` over `groups` workgroups with `resources` bound (see the
    /// module docs); returns once submitted.
    pub fn dispatch(
        &self,
        desc: &'static ComputeDesc,
        resources: &[ComputeResource],
        groups: [u32; 3],
    ) -> Result<(), GpuError> {
        if resources.len() != desc.bindings.len() {
            return Err(GpuError::BadOption(
                "a kernel's resources must match its bindings",
            ));
        }
        let max = self.limits().max_compute_workgroups_per_dimension;
        if groups.iter().any(|&g| g > max) {
            return Err(GpuError::BadOption(
                "a dispatch has more workgroups than this adapter allows",
            ));
        }
        let kernel = self.resource(desc.name, |ctx| Ok::<_, GpuError>(Kernel::new(ctx, desc)))?;
        let mut owned = Vec::new();
        for (b, r) in desc.bindings.iter().zip(resources) {
            let (bytes, usage) = match (b, r) {
                (ComputeBinding::Uniform, ComputeResource::Uniform(x)) => {
                    (*x, wgpu::BufferUsages::UNIFORM)
                }
                (ComputeBinding::Storage, ComputeResource::Storage(x)) => {
                    (*x, wgpu::BufferUsages::STORAGE)
                }
                (ComputeBinding::StorageRw, ComputeResource::Buffer(_)) => continue,
                _ => {
                    return Err(GpuError::BadOption(
                        "a kernel's resource does not match its binding",
                    ))
                }
            };
            owned.push(self.buffer_with(desc.name, bytes, usage));
        }
        let mut next = owned.iter();
        let mut entries = Vec::new();
        for (k, r) in resources.iter().enumerate() {
            let buffer = match r {
                ComputeResource::Buffer(b) => &b.buffer,
                _ => next.next().unwrap_or_else(|| unreachable!("made above")),
            };
            entries.push(wgpu::BindGroupEntry {
                binding: k as u32,
                resource: buffer.as_entire_binding(),
            });
        }
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(desc.name),
            layout: &kernel.layout,
            entries: &entries,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(desc.name),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(desc.name),
                timestamp_writes: None,
            });
            pass.set_pipeline(&kernel.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
        }
        self.queue.submit([encoder.finish()]);
        self.check()
    }
}

impl Kernel {
    fn new(ctx: &Context, desc: &'static ComputeDesc) -> Kernel {
        let entries: Vec<wgpu::BindGroupLayoutEntry> = desc
            .bindings
            .iter()
            .enumerate()
            .map(|(k, b)| wgpu::BindGroupLayoutEntry {
                binding: k as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: match b {
                        ComputeBinding::Uniform => wgpu::BufferBindingType::Uniform,
                        ComputeBinding::Storage => {
                            wgpu::BufferBindingType::Storage { read_only: true }
                        }
                        ComputeBinding::StorageRw => {
                            wgpu::BufferBindingType::Storage { read_only: false }
                        }
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let (layout, pipeline_layout, module) = ctx.program(desc.name, &entries, desc.wgsl);
        let pipeline = ctx
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(desc.name),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(desc.entry),
                compilation_options: Default::default(),
                cache: None,
            });
        Kernel { layout, pipeline }
    }
}
