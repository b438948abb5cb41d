//! The GPU layer: a device, a render target, a batch stream over any vertex
//! type, stages and tables. It knows no rendering mode: a mode brings its
//! stage (a `.wgsl` file under `shaders/`, its vertex type and resources)
//! and its CPU twin, and draws through the same [`Frame`].
//!
//! How a frame works, stage by stage:
//! 1. [`Context::new`] opens a headless wgpu instance (Vulkan, GL, ... as
//!    `Backends::all().with_env()`, or the one backend asked for), picks an
//!    adapter (`force_fallback_adapter` for `--cpu-adapter`) and a device
//!    with the adapter's limits and `FLOAT32_BLENDABLE` where it exists
//!    ([`device`]). Stages and tables are compiled and uploaded once per
//!    device and cached there ([`stage`], [`table`], [`Context::resource`]).
//! 2. [`Context::begin_frame`] creates the target ([`target`]): the
//!    accumulation texture (Rgba32Float where the adapter can blend it,
//!    else Rgba16Float; see [`AccumFormat`]) and the piece-key depth
//!    texture.
//! 3. [`Frame::push_triangles`] appends triangles of a bound [`Stage`] (any
//!    [`GpuVertex`], already in back-to-front order) to a CPU batch of
//!    bounded size; a full batch, or a change of stage, uploads the batch
//!    into reused vertex/index buffers and draws it with one command
//!    encoder; batches are submitted in order and at most two are in
//!    flight, so memory stays bounded whatever the scene size ([`frame`]).
//! 4. The stage's fragment shader outputs a premultiplied colour and its
//!    piece's key as depth; the blend unit does premultiplied "over" back to
//!    front, `dst = src + (1 - src.a) dst` on all four channels, in
//!    submission order, and the depth test lets each piece colour a pixel
//!    at most once. [`cpu::CpuFrame`] is the CPU twin of this stage, with
//!    each stage's twin ([`cpu::CpuStage`]) in place of its shader.
//! 5. [`Frame::finish`] copies the target into a staging buffer (rows padded
//!    to 256 bytes, in chunks no larger than the adapter allows), maps it,
//!    waits with a poll loop that tolerates GL's `Timeout`, and converts
//!    f16 -> f32 ([`readback`]).
//!
//! Conventions (docs/conventions.md): pixel `(i, j)` samples its centre
//! `(i + 0.5, j + 0.5)`, row 0 at the top; [`ClipMapper`] turns continuous
//! pixel coordinates into clip space on the rasteriser's sub-pixel grid so
//! that the rasteriser samples exactly those points ([`raster`]). Ties (a
//! pixel centre exactly on a shared edge) follow the rasteriser's top-left
//! fill rule: a centre on an edge belongs to the triangle for which that
//! edge is a top edge (horizontal, other vertex below) or a left edge; so
//! two triangles sharing an edge never both cover a centre on it, and one
//! of them always does. Varyings use perspective-correct interpolation
//! (never `@interpolate(linear)`: Mesa produces NaN with it on triangles
//! crossing the viewport edge with different clip w).
//!
//! Errors never panic: wgpu's uncaptured-error and device-lost callbacks are
//! captured and turned into [`GpuError`] at the next check.

pub mod common;
pub mod compute;
pub mod cpu;
mod device;
mod frame;
pub mod layer;
pub mod raster;
mod readback;
pub mod stage;
pub mod table;
mod target;

pub use common::{piece_depth, MAX_PIECES};
pub use device::{Context, ContextInfo, PendingContext};
pub use frame::{DrawKind, Frame, FrameOptions, FrameStats};
pub use raster::{ClipMapper, GpuVertex, SUBPIXEL};
pub use stage::{Binding, Resource, Stage, StageDesc};
pub use table::{Table, TableDim};

use thiserror::Error;

/// The graphics API to run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Vulkan (lavapipe on machines without a GPU).
    Vulkan,
    /// OpenGL / GLES via EGL (llvmpipe on machines without a GPU).
    Gl,
}

impl Backend {
    fn backends(self) -> wgpu::Backends {
        match self {
            Backend::Vulkan => wgpu::Backends::VULKAN,
            Backend::Gl => wgpu::Backends::GL,
        }
    }
}

impl std::str::FromStr for Backend {
    type Err = GpuError;
    fn from_str(s: &str) -> Result<Backend, GpuError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "vulkan" | "vk" => Ok(Backend::Vulkan),
            "gl" | "gles" | "opengl" => Ok(Backend::Gl),
            other => Err(GpuError::UnknownBackend(other.to_string())),
        }
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Backend::Vulkan => "vulkan",
            Backend::Gl => "gl",
        })
    }
}

/// How to open the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Only this backend; `None` means every backend, narrowed by the
    /// standard `WGPU_BACKEND` variable when it is set.
    pub backend: Option<Backend>,
    /// Insist on the software ("fallback") adapter even where a real GPU exists.
    pub cpu_adapter: bool,
}

/// Accumulation (render target) format.
///
/// `Auto` is Rgba32Float where the device can blend it (Vulkan, including
/// lavapipe, with `FLOAT32_BLENDABLE`) and Rgba16Float elsewhere (GL). F16
/// accumulation rounds every blend to 11 significant bits: the tests measure
/// what that costs (1000 layers of alpha 1e-4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AccumFormat {
    #[default]
    Auto,
    /// Rgba16Float (blendable everywhere).
    F16,
    /// Rgba32Float (needs `FLOAT32_BLENDABLE`).
    F32,
}

impl AccumFormat {
    /// The wgpu texture format (`Auto` has none until resolved).
    pub fn texture_format(self) -> Option<wgpu::TextureFormat> {
        match self {
            AccumFormat::Auto => None,
            AccumFormat::F16 => Some(wgpu::TextureFormat::Rgba16Float),
            AccumFormat::F32 => Some(wgpu::TextureFormat::Rgba32Float),
        }
    }

    /// Bytes per pixel of a resolved format.
    pub fn bytes_per_pixel(self) -> u32 {
        match self {
            AccumFormat::F32 => 16,
            _ => 8,
        }
    }
}

impl std::fmt::Display for AccumFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            AccumFormat::Auto => "auto",
            AccumFormat::F16 => "rgba16float",
            AccumFormat::F32 => "rgba32float",
        })
    }
}

/// Errors of the GPU compositor.
#[derive(Debug, Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (backends: {backends}{fallback}). Install a software driver: \
         `apt-get install -y --no-install-recommends mesa-vulkan-drivers` (Vulkan, lavapipe) \
         or `apt-get install -y --no-install-recommends libegl1 libgl1-mesa-dri` (GL, llvmpipe)"
    )]
    NoAdapter {
        backends: String,
        /// ", software adapter only" when `cpu_adapter` was asked for.
        fallback: &'static str,
    },
    #[error("unknown backend '{0}' (expected vulkan or gl)")]
    UnknownBackend(String),
    #[error("cannot open the GPU device: {0}")]
    RequestDevice(String),
    #[error("accumulation format {format} is not usable on this adapter: {reason}")]
    FormatUnsupported {
        format: AccumFormat,
        reason: &'static str,
    },
    #[error("image size {width}x{height} is not supported (each side 1..={max})")]
    BadSize { width: u32, height: u32, max: u32 },
    #[error("table {what} {value} is not supported by a {dim}: each side needs a texel")]
    TableSize {
        dim: &'static str,
        what: &'static str,
        value: u32,
    },
    #[error(
        "a {dim} of {size:?} texels needs {mib:.1} MiB, more than one storage buffer of this \
         adapter holds ({max_mib:.1} MiB); choose a smaller --table"
    )]
    TableBytes {
        dim: &'static str,
        size: [u32; 3],
        mib: f64,
        max_mib: f64,
    },
    #[error("{0}")]
    TableTooLarge(String),
    #[error("index count {0} is not a multiple of 3")]
    NotTriangles(usize),
    #[error("index {index} out of range for {len} vertices")]
    IndexOutOfRange { index: u32, len: usize },
    #[error("vertex {0} has a non-finite value")]
    NonFiniteVertex(usize),
    #[error("invalid frame option: {0}")]
    BadOption(&'static str),
    #[error("GPU device lost: {0}")]
    DeviceLost(String),
    #[error("GPU error: {0}")]
    Wgpu(String),
    #[error("GPU did not finish within {0} s")]
    Timeout(u64),
    #[error("reading the image back failed: {0}")]
    Readback(String),
}
