//! The registry of CPU twins: for every file under `shaders/`, the Rust
//! functions that mirror its functions, by name (as vello's CPU shaders
//! do).
//!
//! The scheme:
//! - the twin of `shaders/NAME.wgsl` is the Rust module `NAME`
//!   (`render::modes::NAME`; `gpu::common` and `gpu::layer` for the
//!   mode-independent files);
//! - every WGSL function has a Rust function of the same name, a free
//!   function or a method of one of the module's types: the entry points
//!   (`fs_main`, `build_main`) in module `NAME` itself, helpers there or in
//!   a module it draws on (`exact::exptable`, `integrate::cylinder`);
//! - a fragment entry's twin takes the stage's bindings on the CPU (a
//!   struct such as [`super::exact::ExactTwin`], which implements
//!   [`crate::gpu::cpu::CpuStage`] by calling it) and the triangle and
//!   barycentric weights the CPU rasteriser hands it, its `VertexOut`;
//! - a file of untwinned functions only (`segment_vertex.wgsl`,
//!   `iso_vertex.wgsl`: vertex stages) has no twins at all;
//! - `vs_main` and `fs_count` have no twin of their own: the CPU frame
//!   ([`crate::gpu::cpu::CpuFrame`]) plays the vertex stage (clip positions
//!   pass through; each twin interpolates and scales its attributes) and
//!   counts with [`crate::gpu::common::count_of`].
//!
//! [`stage_twins`] lists them, each by its path
//! ([`std::any::type_name_of_val`], so a renamed or moved twin changes its
//! entry), and [`missing_twins`] checks the list against the WGSL sources
//! of [`super::SHADERS`]: the registry test fails when a shader function
//! has no twin of its name.

use std::any::type_name_of_val as path;

use super::exact::exptable::{self, ExpTable};
use super::integral::{self, TfBuffer};
use super::{
    exact, exact_frag, iso, iso_split, iso_walk, piece_quad, preint, preint2d, preint2d_cyl,
    preint3d, segment, segment_view, table_build,
};
use crate::gpu::{common, layer};
use crate::integrate::cylinder;

/// Shader functions no twin mirrors by name, with the reason.
pub const NOT_TWINNED: &[(&str, &str)] = &[
    (
        "vs_main",
        "clip positions pass through; gpu::cpu::CpuFrame is the vertex stage",
    ),
    (
        "fs_count",
        "counting draws: gpu::cpu::CpuFrame adds gpu::common::count_of",
    ),
];

/// The twins of one shader file.
#[derive(Debug)]
pub struct StageTwins {
    /// The file under `shaders/`.
    pub file: &'static str,
    /// The paths of its twins (`zoovr::MODULE::...::NAME`).
    pub twins: Vec<&'static str>,
}

macro_rules! twins {
    ($file:literal) => {
        StageTwins { file: $file, twins: Vec::new() }
    };
    ($file:literal: $($f:expr),* $(,)?) => {
        StageTwins { file: $file, twins: vec![$(path(&$f)),*] }
    };
}

/// Every shader file's twins.
pub fn stage_twins() -> Vec<StageTwins> {
    vec![
        twins!("common.wgsl": common::piece_depth, common::finite, common::count_of),
        twins!("exact.wgsl": exact::fs_main),
        twins!("exptable.wgsl":
            exptable::log1p_, exptable::coord, ExpTable::texel, ExpTable::alpha_of),
        twins!("exact_frag.wgsl": exact_frag::fs_main),
        twins!("integral.wgsl":
            TfBuffer::node_s, TfBuffer::node, TfBuffer::piece_index, TfBuffer::eval_piece,
            TfBuffer::segment_spans, TfBuffer::span_end,
            integral::neg_expm1, integral::taylor_sf, integral::asym,
            integral::ends_sf,
            integral::sanitize_thickness, integral::gauss_node, integral::gauss,
            integral::weights,
            TfBuffer::add_piece, TfBuffer::integrate_segment),
        twins!("iso.wgsl":
            iso::count_at_most, iso::iso_window, iso::iso_light,
            iso::iso_surface, iso::iso_over, iso::iso_crosses, iso::fs_iso),
        twins!("iso_split.wgsl": iso_split::iso_segment),
        twins!("iso_walk.wgsl": iso_walk::iso_segment),
        twins!("iso_vertex.wgsl"),
        twins!("layer.wgsl": layer::fs_main),
        twins!("preint.wgsl":
            preint::one_minus_exp_over, preint::homogeneous, preint::over, preint::axis,
            preint::lerp4, preint::extension, preint::preint_segment,
            preint::fs_main),
        twins!("preint2d.wgsl": preint2d::texel2d, preint2d::table_rgba),
        twins!("preint2d_cyl.wgsl": preint2d_cyl::plane_texel, preint2d_cyl::table_rgba),
        twins!("preint3d.wgsl": preint3d::texel3d, preint3d::table_rgba),
        twins!("segment.wgsl": segment::segment_at),
        twins!("segment_vertex.wgsl"),
        twins!("segment_view.wgsl": segment_view::segment_of),
        twins!("piece_quad.wgsl": piece_quad::segment_at, piece_quad::corners, piece_quad::edge,
            piece_quad::point, piece_quad::depth, piece_quad::shear, piece_quad::find),
        twins!("table_build.wgsl":
            cylinder::cyl_to_table, table_build::optical_depth, table_build::subspans,
            table_build::column_step, table_build::exp_small,
            table_build::next_powers,
            table_build::column_subspan, table_build::store_texel, table_build::build_column,
            table_build::column_main,
            table_build::build_main),
    ]
}

/// The functions a WGSL source defines, each with whether it is an entry
/// point (`@vertex`, `@fragment` or `@compute` on the lines before it).
pub fn wgsl_functions(src: &str) -> Vec<(&str, bool)> {
    let mut out = Vec::new();
    let mut entry = false;
    for line in src.lines().map(str::trim_start) {
        if line.starts_with("@vertex")
            || line.starts_with("@fragment")
            || line.starts_with("@compute")
        {
            entry = true;
        }
        if let Some(rest) = line.strip_prefix("fn ") {
            let name = rest.split(['(', ' ', '<']).next().unwrap_or("");
            out.push((name, entry));
            entry = false;
        } else if !line.starts_with('@') && !line.is_empty() && !line.starts_with("//") {
            entry = false;
        }
    }
    out
}

/// What is wrong with the twins `twins` of shader file `file` (source
/// `src`): a function without a twin of its name, an entry point twinned
/// outside module `NAME`, a file with no twin in module `NAME`, a twin of no
/// function.
pub fn check_twins(file: &str, src: &str, twins: &[&str]) -> Vec<String> {
    let module = file.trim_end_matches(".wgsl");
    let in_module = |p: &str| p.split("::").any(|s| s == module);
    let mut errors = Vec::new();
    let fns = wgsl_functions(src);
    for &(f, entry) in &fns {
        if NOT_TWINNED.iter().any(|(n, _)| *n == f) {
            continue;
        }
        match twins.iter().find(|p| p.rsplit("::").next() == Some(f)) {
            None => errors.push(format!("{file}: `{f}` has no twin of its name")),
            Some(p) if entry && !in_module(p) => errors.push(format!(
                "{file}: entry `{f}` twinned outside module {module}: {p}"
            )),
            Some(_) => {}
        }
    }
    // A file of untwinned functions only (a vertex stage) needs no module.
    let needs_module = fns
        .iter()
        .any(|(f, _)| !NOT_TWINNED.iter().any(|(n, _)| n == f));
    if needs_module && !twins.iter().any(|p| in_module(p)) {
        errors.push(format!("{file}: no twin in a module named {module}"));
    }
    for p in twins {
        if !fns
            .iter()
            .any(|&(f, _)| f == p.rsplit("::").next().unwrap_or(p))
        {
            errors.push(format!("{file}: twin {p} mirrors no function of it"));
        }
    }
    errors
}

/// Every shader file of [`super::SHADERS`] checked against
/// [`stage_twins`] (empty when every function has its twin).
pub fn missing_twins() -> Vec<String> {
    let all = stage_twins();
    let mut errors = Vec::new();
    for (file, src) in super::SHADERS {
        match all.iter().find(|t| t.file == *file) {
            Some(t) => errors.extend(check_twins(file, src, &t.twins)),
            None => errors.push(format!("{file}: no twins registered")),
        }
    }
    for t in &all {
        if !super::SHADERS.iter().any(|(f, _)| *f == t.file) {
            errors.push(format!("{}: twins of a file not in SHADERS", t.file));
        }
    }
    errors
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "// a stage\nfn helper(x: f32) -> f32 {\n    return x;\n}\n\n@fragment\nfn fs_main(f: VertexOut) -> FragOut {\n}\n@fragment\nfn fs_count(f: VertexOut) -> FragOut {\n}\n";

    #[test]
    fn finds_functions_and_entry_points() {
        assert_eq!(
            wgsl_functions(SRC),
            vec![("helper", false), ("fs_main", true), ("fs_count", true)]
        );
    }

    #[test]
    fn a_function_without_its_twin_is_reported() {
        let ok = ["zoovr::x::stage::helper", "zoovr::x::stage::fs_main"];
        assert!(check_twins("stage.wgsl", SRC, &ok).is_empty());
        let missing = check_twins("stage.wgsl", SRC, &ok[1..]);
        assert_eq!(
            missing,
            vec!["stage.wgsl: `helper` has no twin of its name"]
        );
        let elsewhere = ["zoovr::x::stage::helper", "zoovr::x::other::fs_main"];
        assert_eq!(check_twins("stage.wgsl", SRC, &elsewhere).len(), 1);
        let renamed = ["zoovr::x::stage::helper", "zoovr::x::stage::fs_main2"];
        assert_eq!(check_twins("stage.wgsl", SRC, &renamed).len(), 2);
    }

    #[test]
    fn every_shader_function_has_its_twin() {
        assert_eq!(missing_twins(), Vec::<String>::new());
    }
}
