//! wgpu compositor for the exact (Max-Williams-Silva) mode.
//!
//! How it works, stage by stage:
//! 1. [`Context::new`] opens a headless wgpu instance (Vulkan, GL, ... as
//!    `Backends::all().with_env()`, or the one backend asked for), picks an
//!    adapter (`force_fallback_adapter` for `--cpu-adapter`) and a device with
//!    the adapter's limits and `FLOAT32_BLENDABLE` where it exists. It uploads
//!    the exponential table ([`exptable`]) once.
//! 2. [`Context::begin_frame`] creates the accumulation target (Rgba32Float
//!    where the adapter can blend it, else Rgba16Float; see [`AccumFormat`]).
//! 3. [`Frame::push_triangles`] appends [`ExactVertex`] triangles (already in
//!    back-to-front order) to a CPU batch of bounded size; a full batch is
//!    uploaded into reused vertex/index buffers and drawn by one command
//!    encoder, and batches are submitted in order. At most two batches are in
//!    flight, so memory stays bounded whatever the scene size.
//! 4. The fragment shader (`shaders/exact.wgsl`) computes
//!    `alpha = 1 - exp(-l tau)` from the 2D exponential table (manual bilinear
//!    filtering in f32) and outputs the premultiplied `(glow * alpha, alpha)`;
//!    the blend unit does premultiplied "over" back to front:
//!    `dst = src + (1 - src.a) dst` on all four channels, in submission
//!    order; the fragment's depth is its piece's key, so each piece colours
//!    a pixel at most once ([`frame`] docs). [`cpu::CpuFrame`] is the CPU
//!    twin of this stage.
//! 5. [`Frame::finish`] copies the target into a staging buffer (rows padded to
//!    256 bytes, in chunks no larger than the adapter allows), maps it, waits
//!    with a poll loop that tolerates GL's `Timeout`, and converts f16 -> f32.
//!
//! Conventions (docs/conventions.md): pixel `(i, j)` samples its centre
//! `(i + 0.5, j + 0.5)`, row 0 at the top; [`ClipMapper`] turns continuous
//! pixel coordinates into clip space so that the rasteriser samples exactly
//! those points. Ties (a pixel centre exactly on a shared edge) follow the
//! rasteriser's top-left fill rule: a centre on an edge belongs to the
//! triangle for which that edge is a top edge (horizontal, other vertex below)
//! or a left edge; so two triangles sharing an edge never both cover a centre
//! on it, and one of them always does. Varyings use perspective-correct
//! interpolation (never `@interpolate(linear)`: Mesa produces NaN with it on
//! triangles crossing the viewport edge with different clip w).
//!
//! Errors never panic: wgpu's uncaptured-error and device-lost callbacks are
//! captured and turned into [`GpuError`] at the next check.

mod context;
pub mod cpu;
pub mod exptable;
mod frame;
mod readback;
mod vertex;

pub use context::{Context, ContextInfo, PendingContext};
pub use frame::{DrawKind, Frame, FrameOptions, FrameStats};
pub use vertex::{piece_depth, ClipMapper, ExactVertex, MAX_PIECES, SUBPIXEL};

use thiserror::Error;

/// WGSL source of the exact-mode compositing stage.
pub const EXACT_WGSL: &str = include_str!("../../shaders/exact.wgsl");

/// Every shader, by file name (for validation tests and tools).
pub const SHADERS: &[(&str, &str)] = &[("exact.wgsl", EXACT_WGSL)];

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
