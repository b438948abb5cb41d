//! The GPU device: instance, adapter, device and queue, error capture, and
//! the caches that live as long as the device (compiled stages, tables).
//! It knows no rendering mode: modes bring their stages ([`super::stage`])
//! and tables ([`super::table`]).
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

use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::stage::StageCache;
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

impl ContextInfo {
    /// Whether the adapter rasterises on the CPU (llvmpipe, lavapipe,
    /// WARP: `DeviceType::Cpu`), where triangle setup costs far more than
    /// fragments and stages pick their cheaper-per-triangle paths.
    pub fn is_software(&self) -> bool {
        self.device_type == format!("{:?}", wgpu::DeviceType::Cpu)
    }
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

/// An open GPU device with its caches.
pub struct Context {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: ContextInfo,
    limits: wgpu::Limits,
    f32_blendable: bool,
    /// Compiled stages (shader module, layouts, pipelines) by name
    /// ([`super::stage`]).
    pub(crate) stages: Mutex<HashMap<&'static str, Arc<StageCache>>>,
    /// Resources made once per device and shared by frames (tables), by
    /// key ([`Context::resource`]).
    resources: Mutex<HashMap<&'static str, Arc<dyn Any + Send + Sync>>>,
    errors: Arc<Mutex<Vec<String>>>,
    lost: Arc<Mutex<Option<String>>>,
}

/// A [`Context`] being opened on another thread ([`Context::spawn`]):
/// opening a device takes a few tenths of a second that a caller can
/// overlap with reading and sorting a mesh.
///
/// Dropping one that was never waited for still joins its thread: a process
/// that exits (an error found while the device opens) while Mesa's drivers
/// are being loaded on the other thread can abort inside LLVM's option
/// registry ("Option ... registered more than once"), since `exit` tears
/// down the registry the loading thread is filling.
#[derive(Debug)]
pub struct PendingContext {
    opts: GpuOptions,
    handle: Option<std::thread::JoinHandle<Result<Context, GpuError>>>,
}

impl PendingContext {
    /// The options it was opened with.
    pub fn options(&self) -> &GpuOptions {
        &self.opts
    }

    /// Waits for the context.
    pub fn wait(mut self) -> Result<Context, GpuError> {
        Self::join(self.handle.take())
    }

    fn join(
        handle: Option<std::thread::JoinHandle<Result<Context, GpuError>>>,
    ) -> Result<Context, GpuError> {
        match handle {
            Some(h) => h
                .join()
                .unwrap_or_else(|_| Err(GpuError::Wgpu("opening the device panicked".into()))),
            None => Err(GpuError::Wgpu("the device was already taken".into())),
        }
    }
}

impl Drop for PendingContext {
    fn drop(&mut self) {
        if let Some(h) = self.handle.take() {
            // The context (or its error) is not wanted; only the thread's end.
            drop(Self::join(Some(h)));
        }
    }
}

impl Context {
    /// Starts opening a context on a new thread.
    pub fn spawn(opts: &GpuOptions) -> PendingContext {
        let o = *opts;
        PendingContext {
            opts: o,
            handle: Some(std::thread::spawn(move || Context::new(&o))),
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

        let ctx = Context {
            device,
            queue,
            info,
            limits,
            f32_blendable,
            stages: Default::default(),
            resources: Default::default(),
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

    /// The resource stored under `key`, made by `make` on first use and
    /// kept for the device's life (e.g. a mode's lookup table); an error of
    /// `make` is returned and nothing is kept. A value of another type
    /// under the same key is replaced.
    pub fn resource<T: Any + Send + Sync, E>(
        &self,
        key: &'static str,
        make: impl FnOnce(&Context) -> Result<T, E>,
    ) -> Result<Arc<T>, E> {
        if let Some(r) = self.resources.lock().ok().and_then(|m| m.get(key).cloned()) {
            if let Ok(t) = r.downcast::<T>() {
                return Ok(t);
            }
        }
        let made = Arc::new(make(self)?);
        if let Ok(mut m) = self.resources.lock() {
            m.insert(key, made.clone());
        }
        Ok(made)
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

    /// Waits until every submitted command has finished (benchmarks,
    /// tests); returns the first error recorded.
    pub fn finish(&self) -> Result<(), GpuError> {
        self.wait(None)
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

#[cfg(test)]
mod tests {
    use super::super::layer::{LayerVertex, LAYER_STAGE};
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
        let stage = ctx.bind_stage(&LAYER_STAGE, &[]).unwrap();
        let v = |x: f32, y: f32| LayerVertex {
            pos: [x, y, 0.5, 1.0],
            rgba: [1.0; 4],
            piece: 0,
        };
        frame
            .push_triangles(&stage, &[v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)], &[0, 1, 2])
            .unwrap();
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
