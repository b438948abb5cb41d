//! Helpers shared by the render tests: whether a GPU adapter is there, and
//! the options of one render by mode, split and field model.
#![allow(dead_code)]

use zoovr::gpu::{Context, GpuOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{Mode, ProjectedOptions, ReferenceOptions, RenderOptions};

/// Whether a GPU adapter opens with the default options; when none does,
/// says so on stderr (the caller then skips its GPU part).
pub fn gpu_available() -> bool {
    match Context::new(&GpuOptions::default()) {
        Ok(_) => true,
        Err(e) => {
            eprintln!("skipping the GPU part: no adapter ({e})");
            false
        }
    }
}

/// Options of one render in `mode`: every cell drawn as its consistent tets
/// when `split_all` (projected-cell modes), the ray caster's field `model`;
/// the default camera, GPU and accumulation.
pub fn options(mode: Mode, split_all: bool, model: FieldModel) -> RenderOptions {
    RenderOptions {
        mode,
        projected: ProjectedOptions {
            split_all,
            ..Default::default()
        },
        reference: ReferenceOptions {
            model,
            ..Default::default()
        },
        ..Default::default()
    }
}
